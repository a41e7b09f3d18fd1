// One simulated s-bot: the ODE bodies, geoms and joints built from its RobotDescription, and the
// actuator side of the standard s-bot API (sbot.h, seed Appendix A) in the API's own units.
// Sensors live in their own modules and read the robot through linkPose()/world ray casts.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sbot_sim/core/detail/ode_handles.h"
#include "sbot_sim/core/effects.h"
#include "sbot_sim/core/geom_info.h"
#include "sbot_sim/core/link_ref.h"
#include "sbot_sim/core/random_streams.h"
#include "sbot_sim/core/rest.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/types.h"
#include "sbot_sim/core/world_config.h"

namespace sbot {

class World;


struct JointState {
  std::string name;
  double position = 0;  ///< [rad]
  double velocity = 0;  ///< [rad/s]
  double effort = 0;    ///< [N m] motor torque applied last step
};

class Robot {
 public:
  Robot(World& world, const RobotDescription& description, const std::string& name, int index,
        const Pose& base_pose);
  ~Robot();
  Robot(const Robot&) = delete;
  Robot& operator=(const Robot&) = delete;

  const std::string& name() const { return name_; }
  int index() const { return index_; }
  const RobotDescription& description() const { return *description_; }
  const std::string& level() const { return description_->level; }

  // ---- standard s-bot API, actuator side (units as sbot.h) -------------------------------------
  /// Track speeds in API units (1 unit = 2.8 mm/s). Clamped to [-127,127] as the API documents,
  /// then limited to +-speed_limit_units (70) as the seed's simulator does. Returns true if either
  /// value had to be changed.
  bool setSpeed(int left, int right);
  /// Measured track speeds (encoderSpeed), API units, in [-127,127].
  void getSpeed(int* left, int* right) const;
  /// Track motor torques, API units (2.4412 mN m), in [-127,127]: trackTorqueLeft/Right.
  void getTrackTorque(int* left, int* right) const;
  /// [m] lateral distance between the left and right outermost driven wheels (the treels' centre
  /// wheels, on which the robot turns), measured on the built model: 0.082 m at full size (Table
  /// 2.2), 0.041 m for Fast; the seed's 0.082 m if the wheels are not apart. cmd_vel's b.
  double trackWidth() const { return track_width_; }
  /// Passive treels (seed TreelsModule::setPassive): motors off, only the gear back-drive friction
  /// (treels.backdrive_force) resists rolling. Any setSpeed() makes them active again.
  void setTracksPassive(bool passive) {
    if (passive != passive_) wake();  // on a slope, released gears roll
    passive_ = passive;
  }
  bool tracksPassive() const { return passive_; }
  /// Turret position target in API units of 2 degrees, clamped to [-100,100]. Returns true if clamped.
  bool setTurretRotation(int pos);
  int getTurretRotation() const;
  int getTurretRotationTorque() const;

  // ---- continuous access (SI) ------------------------------------------------------------------
  /// Requested track surface speeds [m/s] (the same limit applies). Used by cmd_vel.
  void setTrackSpeeds(double left_mps, double right_mps);
  double requestedLeft() const { return req_left_; }
  double requestedRight() const { return req_right_; }
  /// Track surface speeds [m/s] from wheel rotation (the physics; no sensor effects).
  double trackSpeedLeft() const;
  double trackSpeedRight() const;
  /// The wheel encoder's reading [m/s] of track `side` (0 left, 1 right): the wheel rotation passed
  /// through the world's sensor-path effects (kTrackSpeedChannel), e.g. speed_scale's encoders read
  /// the command while the ground moves faster. What getSpeed, the node and the calibration replay read.
  double encoderSpeed(int side) const;
  /// Track motor torque [N m], the mean over the last treels.torque_window seconds: a motor's
  /// current reading averages, while one step's constraint torque carries the contact solver's
  /// step-to-step jitter (Medium, quickstep, 40 units: sd 4.8 API units per step, 0.6 over 0.1 s).
  double trackTorqueLeft() const;
  double trackTorqueRight() const;
  /// Normal force the surroundings (ground, obstacles, other robots) exerted on the driven
  /// treels wheels in the last step [N]: the load the tracks can grip with. About the robot's
  /// weight on flat ground; near 0 when it is airborne or hung up on its chassis or casters (the
  /// validation's Table 4.6 tells "stuck" from "slipping" by it). Fast's body drive counts its
  /// chassis and casters too (they stand for its tracks).
  double driveWheelLoad() const { return drive_wheel_load_; }
  /// The same contacts' total force on the robot [N, world frame]. Fast's body drive takes its
  /// traction from the part along the chassis' up axis: what presses the tracks onto their
  /// support, not a wall or robot pushing from the side.
  const Vec3& driveContactForce() const { return drive_contact_force_; }
  /// Fast's body drive: the traction it was given in the last step [N] (0 for wheel drives).
  double bodyDriveTraction() const { return drive_traction_; }
  /// Turret angle [rad] relative to the treels.
  double turretAngle() const;
  /// The turret is welded to the treels (WorldConfig::lock_idle_turret: quickstep, turrets whose
  /// centre of mass is off their axis, i.e. Basic, Medium, Detailed): it has
  /// stayed within half an API unit (1 deg) of its target for 0.2 s. A target more than that away
  /// frees it again at the next step (both are in-place rebuilds, see switchDescription). While welded,
  /// bodies() has one body fewer and getTurretRotationTorque() reads 0: the servo's holding torque
  /// is not measured (the weld holds any load; the real servo gives way above 1.49 N m).
  bool turretLocked() const { return turret_locked_; }
  /// Whether robots of level `d` weld their idle turret in a world configured as `c`.
  static bool weldsIdleTurret(const WorldConfig& c, const RobotDescription& d);

  /// World pose of the base_link frame.
  Pose basePose() const;
  /// World pose of any URDF link, including massless sensor frames merged into a body.
  Pose linkPose(const std::string& link) const;
  /// linkPose through a LinkRef: the same pose, the name looked up once per build of the robot.
  Pose linkPose(const LinkRef& link) const;
  bool hasLink(const std::string& link) const { return link_index_.count(link) != 0; }
  /// hasLink through a LinkRef: its absence, like its frame, is looked up once per build.
  bool hasLink(const LinkRef& link) const { return resolve(link); }
  Vec3 linearVelocity() const;   ///< of the base_link origin, world frame [m/s]
  Vec3 angularVelocity() const;  ///< world frame [rad/s]
  std::vector<JointState> jointStates() const;
  /// The whole robot's centre of mass [m, world frame]; its mass [kg] into `mass_out` if given.
  Vec3 centreOfMass(double* mass_out = nullptr) const;
  /// Rigid bodies the model is built of (links joined by fixed joints are one body).
  std::size_t bodyCount() const { return bodies_.size(); }
  /// Push the robot: `force` [N, world frame] at its base body's centre of mass, for the next step.
  void addBaseForce(const Vec3& force);

  /// Move the robot so base_link sits at `pose` with zero velocity (teleport).
  void setBasePose(const Pose& pose);
  /// Every body's pose and velocities, to put the robot back exactly (World::placeRobot).
  struct BodyState {
    Pose pose;
    Vec3 linear, angular;  ///< [m/s], [rad/s] world frame
  };
  std::vector<BodyState> bodyStates() const;
  void setBodyStates(const std::vector<BodyState>& states);

  // ---- joint access for actuator modules (core/actuators: gripper, side arm) --------------------
  /// ODE hinge of a moving URDF joint, nullptr if the level has no such joint. Hinges other than the
  /// treels and the turret are passive (FMax 0) until a module drives them through this handle.
  dJointID hingeJoint(const std::string& joint) const;
  /// Unwrapped angle [rad], rate [rad/s] and last-step torque about the axis [N m] of a hinge; 0 if
  /// the level has no such joint.
  double jointAngle(const std::string& joint) const;
  double jointRate(const std::string& joint) const;
  double jointEffort(const std::string& joint) const;
  /// Hold hinge `joint` where it is, as a powered servo does: its motor's target rate 0, with at
  /// most `max_torque` [N m]. False (and nothing done) if the level has no such joint.
  bool holdJoint(const std::string& joint, double max_torque);
  /// ODE body carrying a URDF link (massless links are merged into a body); nullptr if absent.
  dBodyID linkBody(const std::string& link) const;

  // ---- dynamic model switching (seed 2.1.3; implemented in core/swarm/model_switch.cpp) ---------
  /// Rebuild this robot's bodies, geoms and joints from `description` within the same step, in
  /// place: this Robot object (name, index, random streams, every pointer to it) stays valid. Kept:
  /// base pose, base linear and angular velocity, the angle and rate of every joint both levels
  /// have (turret, gripper elevation, ...), the track speeds (wheel spin), the requested track
  /// speeds, passive mode and the turret target. Joints other robots or modules attached to this
  /// robot (World::connections(): gripper / side-arm connections) are re-attached, with the same
  /// dJointID, to the new body carrying the same link (holder: gripper_tip / side-arm tip; held:
  /// turret). Throws ConfigError if the levels differ in scale (Fast vs full size).
  void switchDescription(const RobotDescription& description);
  /// Turret position target [rad].
  double turretTarget() const { return turret_target_; }

  RandomStreams& random() { return random_; }

  // ---- used by World -----------------------------------------------------------------------------
  void applyCommands(double dt, const std::vector<EffectPtr>& effects);
  void readFeedback(double dt);
  void clearDriveContacts() {
    drive_contacts_ = 0;
    driven_wheel_contacts_ = 0;
    drive_wheel_load_ = 0;
    drive_contact_force_ = Vec3::Zero();
  }
  /// One contact on a drive geom: its push along the contact normal [N], its force vector [N], and
  /// whether the geom is a driven wheel (the body drive's chassis and casters are drive geoms too).
  void addDriveContact(double push, const Vec3& force, bool on_wheel) {
    drive_wheel_load_ += push;
    drive_contact_force_ += force;
    ++drive_contacts_;
    if (on_wheel) ++driven_wheel_contacts_;
  }
  /// Track creep (treels.creep_stiffness) as ODE's force-dependent slip for one terrain contact of
  /// a driven wheel of `track` (0 left, 1 right) [m/s per N]; 0 when the level has no creep, uses
  /// the body drive, the track stands or nothing carried the wheels in the last step.
  double trackCreepSlip(int track) const { return creep_slip_[track]; }
  dBodyID baseBody() const;
  dSpaceID space() const { return space_; }

  // ---- sleeping at rest (RestConfig; World drives these once per step) -------------------------
  /// True while the robot is out of the solve: it was commanded to stand (both tracks at zero
  /// after the command-path effects) and stood still for RestConfig::window_s.
  bool asleep() const { return asleep_; }
  /// Before the step: wake a sleeping robot that something disturbed, i.e. whose bodies were
  /// enabled (setBasePose, a rebuild) or carry a force or torque (an external push).
  void wakeIfDisturbed();
  /// After the step: a sleeping robot that ODE woke (a contact or joint with an awake body) is
  /// awake again; an awake one commanded to stand that stood still for the window is restReady().
  void updateRest(const RestConfig& config);
  /// Awake, commanded to stand, and still for the whole window. World puts it to sleep together
  /// with the robots joined to it (connections, static links), once they are all ready.
  bool restReady() const { return rest_ready_; }
  /// Out of the solve now, keeping the window's mean drive-contact loads (World calls it).
  void sleepAtRest();
  /// Before collision: awake, tracks commanded to stand, no servo moving or commanded in the last
  /// kServoSettle_s, no body faster than kStandingSpeed, and none moved beyond the rest limits
  /// (RestConfig) in the last kMovedRecently_s. A sleeper it touches stays asleep and stands as a
  /// static body for it (World::handlePair): settling neighbours do not wake each other.
  bool standing() const { return standing_; }
  void updateStanding();
  static constexpr double kStandingSpeed = 0.08;  ///< [m/s] above quickstep's jitter at rest (<= 0.05)
  static constexpr double kServoSettle_s = 2.0;   ///< [s] a servo command moves the robot this long
  /// [s] a robot that moved past the rest limits (3 mm) this recently is being pushed or dragged
  /// (at >= ~1.2 cm/s), not rocking: quickstep's creep at rest takes ~1.5 s for 3 mm.
  static constexpr double kMovedRecently_s = 0.25;
  /// Back into the solve, the rest window restarted. Every command that changes a target calls it
  /// (a track speed through applyCommands, the turret, the gripper, the side arm).
  void wake();
  /// Woken by a contact or joint with an awake body (World): as wake(), but it commands nothing.
  void wakeByTouch();
  const std::vector<dBodyID>& bodies() const { return bodies_; }
  std::size_t geomCount() const { return geoms_.size(); }

 private:
  struct LinkFrame {
    int body = -1;          ///< index into bodies_
    Pose body_T_link;       ///< link frame in the body (centre of mass) frame
  };
  struct Hinge {
    std::string name;
    dJointID id = nullptr;
    detail::JointFeedbackPtr feedback;  ///< ODE writes the hinge's forces here each step
    Vec3 axis_in_child = Vec3::UnitZ();
    int child_body = -1;
    double effort = 0;      ///< torque about the axis, last step [N m]
    double angle = 0;       ///< unwrapped angle [rad]: ODE reports [-pi, pi], the turret turns +-200 deg
    double raw_angle = 0;   ///< ODE's wrapped angle at the last update
  };

  /// Builds from model_ (the level's description, or its copy with the turret welded): the stages
  /// below, in robot_build.cpp.
  void build(const Pose& base_pose);
  struct LinkGroups;  ///< links grouped into rigid bodies (a fixed joint merges a child into its parent)
  static LinkGroups groupLinks(const RobotDescription& d, const Pose& base_pose);
  /// The body of group `gi` (its mass about its centre of mass) with its links' collision geoms.
  void addGroupBody(const LinkGroups& groups, std::size_t gi, double inertia_floor);
  void addHinges(const LinkGroups& groups);  ///< one ODE hinge per moving joint
  void markDriveWheels();                    ///< the tracks' hinges and their wheels' geoms
  /// switchDescription's work: rebuild from `model` in place, carrying the state over
  /// (core/swarm/model_switch.cpp). description_ is already the level to be.
  void rebuild(const RobotDescription& model);
  /// Weld a settled turret, free one that has a new target (start of applyCommands).
  void updateTurretLock(double dt);
  void setTurretLocked(bool locked);
  /// `d` with its turret joint fixed at `angle` [rad] (the turret merged into the treels' body).
  static std::unique_ptr<RobotDescription> withTurretWelded(const RobotDescription& d, double angle);
  /// Destroys every ODE object this robot owns (bodies, geoms, its space, hinges, loop joints, the
  /// body drive) and empties the bookkeeping: ~Robot and switchDescription.
  void destroyModel();
  void measureTrackWidth();
  void buildBodyDrive();
  void applyBodyDrive(const TrackCommand& cmd);
  void applyDriveReaction(const Quat& chassis_orientation);
  void applyRollingResistance(const TrackCommand& cmd);  ///< TrackCommand::resist_torque_*
  /// trackCreepSlip for this step, from the motor targets in `cmd` and the last step's wheel loads.
  void updateCreepSlip(const TrackCommand& cmd);
  /// Track surface speed [m/s] the body drive sees: forward speed -/+ yaw rate * width / 2.
  double bodyDriveTrackSpeed(int side) const;
  void addReflectedRotorInertia(const std::vector<int>& track);
  void addLoopJoints(const std::map<std::string, Pose>& world_T_link,
                     const std::map<std::string, std::pair<int, Pose>>& link_group);
  const Hinge* hinge(const std::string& joint) const;
  double hingeRate(const Hinge& h) const;
  double hingeAngle(const Hinge& h) const;

  World& world_;
  const RobotDescription* description_;  ///< the level (what description() returns)
  const RobotDescription* model_;        ///< what the bodies are built from: description_ or welded_model_
  std::unique_ptr<RobotDescription> welded_model_;
  std::string turret_joint_;             ///< the level's turret joint ("" if it has none)
  bool welds_turret_ = false;            ///< weldsIdleTurret(world config, level), per level
  bool turret_locked_ = false;
  double locked_angle_ = 0;              ///< [rad] unwrapped turret angle while welded
  double turret_settled_for_ = 0;        ///< [s] the free turret has been at its target
  std::string name_;
  int index_;
  RandomStreams random_;

  std::vector<dBodyID> bodies_;
  std::vector<dGeomID> geoms_;
  std::vector<std::unique_ptr<GeomInfo>> geom_infos_;
  dSpaceID space_ = nullptr;             ///< this robot's geoms; never collided with itself
  std::vector<Hinge> hinges_;
  std::vector<dJointID> loop_joints_;    ///< side-arm loop closures (sidecar side_arm.loop_joints)
  std::map<std::string, dJointID> loop_index_;  ///< loop joint name -> joint (hingeJoint() finds them)
  std::map<std::string, int> hinge_index_;
  std::map<std::string, LinkFrame> link_index_;
  /// Unique over the process and every build() of every robot: a LinkRef resolved in another
  /// build (of this robot, or of another) is looked up again.
  std::uint64_t build_id_ = 0;
  /// Resolve `link` in this build if it was resolved in another; whether this robot has it.
  bool resolve(const LinkRef& link) const;
  std::vector<int> left_hinges_, right_hinges_;
  int turret_hinge_ = -1;
  Pose base_body_T_base_;                ///< base_link in its body's (centre of mass) frame
  double track_width_ = 0.082;           ///< [m] see trackWidth()
  bool wheels_apart_ = false;            ///< the model's driven wheels give the track width

  int drive_contacts_ = 0;               ///< contacts behind drive_wheel_load_ (last step)
  int driven_wheel_contacts_ = 0;        ///< of those, on the driven wheels themselves (see applyDriveReaction)
  double creep_slip_[2] = {0, 0};        ///< see trackCreepSlip(); set by updateCreepSlip each step
  double drive_wheel_load_ = 0;          ///< [N] see driveWheelLoad()
  Vec3 drive_contact_force_ = Vec3::Zero();  ///< [N] see driveContactForce()
  double req_left_ = 0, req_right_ = 0;  ///< requested track speeds [m/s]
  double turret_target_ = 0;             ///< [rad]
  bool passive_ = false;
  bool asleep_ = false;                  ///< see asleep()
  bool rest_ready_ = false;              ///< see restReady()
  bool standing_ = false;                ///< see standing()
  double last_command_wake_s_ = -1e9;    ///< [s] world time of the last wake() (commands, disturbances)
  bool commanded_still_ = false;         ///< both tracks commanded 0 in the last applyCommands
  RestWatch rest_watch_;
  void sleep();

  // Body drive (sidecar treels.drive: body; the Fast level). In 1/50 g a 1/20-mass robot's wheel
  // contacts carry ~10 mN, too little for ODE's wheel contacts at 100 ms steps (the robot hops and
  // spins its wheels in place), so the tracks act on the chassis directly: a linear motor holds the
  // forward speed (and no side slip) and an angular motor the yaw rate of an ideal differential
  // drive, each force-limited by the motors and by traction (mu times the load that pressed the
  // chassis, casters and wheels onto their support in the last step: none while airborne).
  dJointID drive_linear_ = nullptr;   ///< LMotor, axes chassis x and y
  dJointID drive_angular_ = nullptr;  ///< AMotor, axis chassis z
  /// The motors' forces (kept across rebuilds: the first step after one reads the last step's).
  detail::JointFeedbackPtr drive_linear_fb_, drive_angular_fb_;
  double drive_torque_[2] = {0, 0};   ///< [N m] per track (left, right), last step
  double drive_traction_ = 0;         ///< [N] see bodyDriveTraction()
  // Per-step track torques of the last treels.torque_window (ring buffer) and their running sum.
  std::vector<std::array<double, 2>> torque_history_;
  std::size_t torque_next_ = 0;
  std::array<double, 2> torque_sum_{0, 0};
};

}  // namespace sbot
