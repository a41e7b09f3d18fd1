// The simulated world: one ODE world and collision space, the terrain, the robots, and the fixed-step
// loop. No ROS here: the simulator node, benchmarks, validation and calibration all drive this class.
#pragma once

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "sbot_sim/core/actuators/connections.h"
#include "sbot_sim/core/detail/ode_handles.h"
#include "sbot_sim/core/effects.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/world_config.h"

namespace sbot {

struct RayHit {
  bool hit = false;
  double distance = 0;         ///< [m] along the ray
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  std::string surface;         ///< material / surface label of what was hit
  const Robot* robot = nullptr;///< the robot hit, if any
};

/// What is wrong with `name` as a robot name, or "" when it is valid. Robot names become ROS
/// namespaces and TF prefixes (`<name>/proximity`, `<name>/base_link`), so they follow the ROS graph
/// name rules for one segment: a letter, then letters, digits or '_'.
std::string robotNameProblem(const std::string& name);

/// The simulated space: every coordinate of a robot or a terrain box within +-kMaxCoordinate [m].
/// ODE's collision spaces cannot index geometry far beyond it (a robot spawned at x = 1e300 stopped
/// the simulator with an ODE assertion).
constexpr double kMaxCoordinate = 1e5;
/// What is wrong with `p` [m] as a position in the world ("" when it is finite and inside).
std::string positionProblem(const Vec3& p);

class World {
 public:
  explicit World(const WorldConfig& config);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Spawn a robot of `description` with base_link at `pose` (x, y, yaw), level, its lowest point
  /// 1 mm above the highest ground under its collision geoms' own outlines (a robot whose outline
  /// reaches over a wall is set on the wall's height, as a robot held there would be).
  Robot& addRobot(const RobotDescription& description, const Pose2D& pose, const std::string& name);
  /// Spawn at an explicit 3D pose of base_link. Both refuse (ConfigError) a duplicate or invalid name.
  Robot& addRobotAt(const RobotDescription& description, const Pose& pose, const std::string& name);
  void removeRobot(const std::string& name);
  /// Dynamic model switching (seed 2.1.3): rebuild robot `name` from `description` in place, keeping
  /// its state and connections (Robot::switchDescription). Throws UnknownName / ConfigError.
  Robot& switchLevel(const std::string& name, const RobotDescription& description);
  Robot& robot(const std::string& name);            ///< throws UnknownName
  Robot* findRobot(const std::string& name);        ///< nullptr if absent
  std::vector<Robot*> robots();
  std::size_t robotCount() const { return robots_.size(); }
  /// Quickstep iterations in use: the config's, raised to the robots' levels' needs.
  int solverIterations() const { return solver_iterations_; }

  /// Where a step's wall time goes (World::enableProfile). Sensors are read outside step() and are
  /// timed by whoever reads them. Plain counters: a profile is the sum since the last reset.
  struct StepProfile {
    double commands_s = 0;    ///< [s] effects' command hooks and the motors (Robot::applyCommands)
    double collision_s = 0;   ///< [s] broad and narrow phase, contact joints built (handlePair)
    double solver_s = 0;      ///< [s] dWorldQuickStep / dWorldStep
    double feedback_s = 0;    ///< [s] wheel loads, joint feedback, torque windows (readFeedback)
    std::uint64_t steps = 0;
    std::uint64_t contacts = 0;  ///< contact joints created (counted whether or not timing is on)
    double total_s() const { return commands_s + collision_s + solver_s + feedback_s; }
  };
  /// Time the phases of every step from now on (5 clock reads per step, ~1-2 % of a Fast step);
  /// resets the profile. Off by default.
  void enableProfile(bool on);
  const StepProfile& profile() const { return profile_; }

  /// Advance one fixed step: effects' command hooks, motors, collisions, integration, feedback.
  void step();
  void stepN(int n) { for (int i = 0; i < n; ++i) step(); }
  double time() const { return time_; }
  /// Gravity [m/s^2, world frame]; the config's is (0, 0, -gravity). A slope experiment tilts it;
  /// a new gravity wakes every sleeping robot at the next step.
  void setGravity(const Vec3& g);
  Vec3 gravity() const;
  std::uint64_t stepCount() const { return steps_; }
  const WorldConfig& config() const { return config_; }

  /// Height of the terrain (ground plane, boxes, height field) under (x, y) [m].
  double terrainHeight(double x, double y) const;
  /// Cast a ray; `ignore` (optional) is not hit (a sensor's own robot).
  RayHit castRay(const Vec3& origin, const Vec3& direction, double length, const Robot* ignore) const;
  /// A bundle of rays from one origin (a sensor's cone): the same hits as castRay per direction,
  /// but the spaces are searched once, for the box that bounds the whole bundle.
  std::vector<RayHit> castRays(const Vec3& origin, const std::vector<Vec3>& directions, double length,
                               const Robot* ignore) const;
  /// Several bundles of n rays each (a sensor ring; n = directions.size() / origins.size()): bundle k
  /// is directions[k n .. k n + n - 1] from origins[k], and hits come in the same order. One search of
  /// the spaces, for the box around all of them: the same hits as castRays per bundle.
  std::vector<RayHit> castRayBundles(const std::vector<Vec3>& origins, const std::vector<Vec3>& directions,
                                     double length, const Robot* ignore) const;
  /// Rays from one origin, each with its own length (a camera's lines of sight to the LEDs it may
  /// see): the same hits as castRay per (direction, length). One search of the spaces for the box
  /// around all of them; then a ray is tested against a robot's geoms only if its segment crosses
  /// that robot's bounding box, so that a long line of sight across a swarm does not test every
  /// robot its axis-aligned box covers (as ODE's ray against a space does).
  std::vector<RayHit> castRaysOfLengths(const Vec3& origin, const std::vector<Vec3>& directions,
                                        const std::vector<double>& lengths, const Robot* ignore) const;

  /// The deepest overlap of `robot`'s geoms with the terrain or another robot as it stands now.
  struct Overlap {
    double depth = 0;  ///< [m] ODE's penetration depth; 0 when nothing overlaps
    std::string with;  ///< "the ground", "box 'step'" or "robot 'sbot_3'"
  };
  /// `robots_only`: other robots alone, not the terrain.
  Overlap deepestOverlap(const Robot& robot, bool robots_only = false) const;
  /// Why the robots as they stand overlap each other by more than kPlacementTolerance, naming the
  /// first such pair and the depth ("" if none): spawned so, the contacts throw them apart.
  std::string robotsOverlapProblem() const;
  /// Teleport `robot` (Robot::setBasePose: base_link at `pose`, at rest) unless it would then sit
  /// deeper than kPlacementTolerance inside the terrain or another robot, which the contacts would
  /// resolve by throwing it out (a robot set 5 m under the floor rose through it at 0.5 m/s). Returns
  /// "" when placed; otherwise why not, and the robot is left exactly as it was.
  static constexpr double kPlacementTolerance = 0.01;  ///< [m] a robot set down slightly low settles
  std::string placeRobot(Robot& robot, const Pose& pose);

  /// Effects change what robots feel: sleeping robots (Robot::asleep) are woken.
  void addEffect(EffectPtr effect) {
    effects_.push_back(std::move(effect));
    wakeAll();
  }
  const std::vector<EffectPtr>& effects() const { return effects_; }
  void clearEffects() {
    effects_.clear();
    wakeAll();
  }
  /// Every sleeping robot back into the solve (world changes: gravity, effects, a robot removed
  /// or switched).
  void wakeAll();

  /// Gripper / side-arm connections between robots (actuators/connections.h).
  ConnectionManager& connections() { return *connections_; }
  const ConnectionManager& connections() const { return *connections_; }

  dWorldID odeWorld() const { return world_; }
  dSpaceID space() const { return space_; }
  /// The terrain's static geoms. Not inside space(): each step collides every robot's space with it
  /// (collideWithTerrain), so static geoms are never tested against each other (a course of
  /// hundreds of boxes costs the broadphase almost nothing). Built once by the constructor, whose
  /// index of its geoms' boxes would miss a geom added later.
  dSpaceID staticSpace() const { return static_space_; }
  dJointGroupID contactGroup() const { return contacts_; }

  /// Internal (public for the query callbacks): a geom with its bounding box [min x, max x, min y,
  /// max y, min z, max z] (ODE's layout). castRays tests a ray only against the geoms whose boxes
  /// meet its segment's; collideWithTerrain a robot only against the static geoms that meet its own.
  struct BoxedGeom {
    dGeomID geom;
    double aabb[6];  ///< ODE's dReal (double: ode_handles.cpp checks)
  };
  // internal: collision callback trampoline
  void handlePair(dGeomID a, dGeomID b);

 private:
  void buildTerrain();
  std::vector<BoxedGeom> terrain_index_;        ///< static_space_'s geoms, in its order (never move)
  std::vector<BoxedGeom> robot_geoms_;          ///< collideWithTerrain's robot geoms (reused)
  void indexTerrain();  ///< fills terrain_index_ (after buildTerrain)
  /// Contacts between a robot and the terrain (see world_contacts.cpp for why not dSpaceCollide2).
  void collideWithTerrain(Robot& r);
  /// Before the terrain is collided: wake every sleeping robot that a joint (a contact made this
  /// step, a connection, a static link) ties to an awake body, as ODE's island walk would mid-step.
  void wakeSleepersJointedToAwakeBodies();
  bool jointedToAnEnabledBody(const Robot& robot) const;
  void collideRobots(const Robot& a, const Robot& b);
  /// A contact between a sleeper and a standing robot, made against the sleeper as a static body.
  struct HeldBackContact {
    dJointID joint;
    dBodyID body_a, body_b;  ///< the contact's two bodies, as dCollide gave them
    const Robot* sleeper;
    const Robot* standing;
  };
  std::vector<HeldBackContact> held_back_;   ///< this step's (handlePair)
  std::vector<std::pair<const Robot*, const Robot*>> awake_touches_;  ///< this step's awake robot pairs in contact
  /// After robot-robot collision: a held-back contact whose standing robot is pushed (in contact,
  /// directly or through other awake robots, with one that is not standing) joins its sleeper.
  void releaseHeldBackContacts();
  void joinHeldBackContactsOf(const Robot& sleeper);
  /// After the step: robots joined by connections or static links fall asleep together, once
  /// every awake one of them is restReady(); a robot joined to none sleeps on its own.
  void sleepRestingGroups();

  WorldConfig config_;
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dSpaceID static_space_ = nullptr;
  /// One ray geom (in no space) reused by castRay/terrainHeight: creating and destroying a geom per
  /// ray cost ~10 % of a sensor-reading Medium step. Makes a World unsafe to query from two threads.
  mutable dGeomID query_ray_ = nullptr;
  mutable dGeomID query_box_ = nullptr;  ///< castRays' bounding box, also in no space
  mutable std::vector<BoxedGeom> ray_candidates_;  ///< castRays' geoms within that box (reused)
  /// castRaysOfLengths' runs of ray_candidates_ with one robot's geoms (a static geom alone), with
  /// the box around each run (reused).
  struct CandidateGroup {
    std::size_t begin, end;
    double aabb[6];
  };
  mutable std::vector<CandidateGroup> candidate_groups_;
  int solver_iterations_ = 0;
  Vec3 stepped_gravity_ = Vec3::Zero();  ///< [m/s^2] ODE's gravity at the last step (see step)
  bool exact_solver_ = false;     ///< config_.solver == "exact"
  void updateSolverIterations();  ///< after a robot came, went or changed level
  dGeomID queryRay(double length) const;  ///< query_ray_ with this length
  /// Fills ray_candidates_ with the geoms (not `ignore`'s) whose bounding boxes meet [lo, hi].
  void findRayCandidates(const Vec3& lo, const Vec3& hi, const Robot* ignore) const;
  mutable std::vector<Vec3> ray_units_;  ///< unitDirections' result (reused)
  /// `directions` normalised into ray_units_ (once per ray for the bounds and the casts).
  const Vec3* unitDirections(const std::vector<Vec3>& directions) const;
  /// Casts the n rays of unit `directions` from `origin` against ray_candidates_ only; the hit of
  /// directions[i] into hits[i] (each a miss at `length` unless something nearer is hit).
  void castAgainstCandidates(const Vec3& origin, const Vec3* directions, std::size_t n, double length,
                             const Robot* ignore, RayHit* hits) const;
  dJointGroupID contacts_ = nullptr;
  /// This step's contacts on driven treels wheels, with ODE's force feedback (Robot::driveWheelLoad;
  /// defined in world_internal.h). A deque: ODE keeps pointers to the feedback records while the
  /// step runs.
  struct WheelContact;
  std::unique_ptr<std::deque<WheelContact>> wheel_contacts_;
  void updateDriveWheelLoads();       ///< after the step: sum the normal forces per robot
  std::vector<dGeomID> static_geoms_;
  std::map<dGeomID, std::string> static_material_;
  std::vector<std::unique_ptr<Robot>> robots_;
  std::unique_ptr<ConnectionManager> connections_;  ///< destroyed before the robots
  std::vector<EffectPtr> effects_;
  double time_ = 0;
  std::uint64_t steps_ = 0;
  bool profiling_ = false;
  StepProfile profile_;
  int next_index_ = 0;
  std::vector<double> heightfield_;   ///< row-major heights for Rough terrain [m]
  dHeightfieldDataID heightfield_data_ = nullptr;
};

}  // namespace sbot
