// Configuration of a simulated world: integration, contacts, terrain. Filled from a scenario YAML
// (scenario.h) or directly by headless tools (benchmarks, validation, calibration).
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "sbot_sim/core/types.h"

namespace sbot {

/// [s] the integration steps a world accepts: below, a run of seconds takes millions of steps (a
/// step given in the wrong unit; per-robot buffers sized window / step run out of memory); above,
/// no level's contacts hold (the Fast level's 100 ms is the largest the seed uses).
constexpr double kMinStep = 1e-4, kMaxStep = 0.5;
/// [-] quickstep's over-relaxation converges only below 2; from 2 on ODE's solve diverges and aborts.
constexpr double kMaxSolverSor = 1.99;
/// [m/s^2] the largest gravity a world or a level accepts (100 g; no contact holds beyond).
constexpr double kMaxGravity = 1000;
/// [m] a rough terrain's side, and the finest cell of its height field (side / (samples - 1)): a
/// robot over finer cells meets tens of thousands of triangles a step, and ODE's height-field
/// collider stalls (0.08 mm cells: minutes per step) or, for a vanishing side, aborts.
constexpr double kMinTerrainSize = 0.1, kMaxTerrainSize = 1e4, kMinTerrainCell = 0.001;

/// Contact model. Materials are named by the sidecar (`materials`) and by obstacles (`surface`).
struct ContactConfig {
  /// Coulomb coefficient of any contact without a listed material: the s-bot's plastic turret and
  /// chassis against walls, obstacles and other robots (0.4, plastic on plastic/painted wood). The
  /// treels have their own entry below; with 1.0 here a robot pushing a wall climbs it with its
  /// turret and flips over backwards.
  double mu = 0.4;
  /// Per-material coefficients; they override `mu` (two listed materials: the smaller wins).
  ///  caster 0   a free ball in a socket transmits no tangential force.
  ///  track  1.0 rubber treels on the seed's polystyrene/wood: holds a 30 deg slope until the robot
  ///             topples (Table 4.1 needs mu >= tan 30 deg = 0.58). Note the motors (0.22 N m per
  ///             track = 10 N at the ground) are far stronger than this traction (6.5 N for the whole
  ///             robot): a robot pushing a wall slips its tracks rather than stalling its motors.
  std::map<std::string, double> material_mu{{"caster", 0.0}, {"track", 1.0}};
  double erp = 0.2;         ///< contact error reduction (ODE soft_erp)
  double cfm = 1e-5;        ///< contact softness (ODE soft_cfm) [m/N scaled by step]
  double bounce = 0.0;      ///< restitution
  int max_contacts = 4;     ///< per geom pair
  /// false: ODE's box friction where mu is a force limit [N] per contact, like the seed's Vortex
  /// "friction 12e4 dyne". true (default): Coulomb friction pyramid (dContactApprox1).
  bool coulomb = true;

  double muFor(const std::string& a, const std::string& b) const;
};

/// A static box: walls, steps, plateaus, gap edges, ramps (pitch tilts it about its local y axis).
struct BoxObstacle {
  std::string name;
  Vec3 center = Vec3::Zero();  ///< [m]
  Vec3 size = Vec3::Ones();    ///< full edge lengths [m]
  double yaw = 0;              ///< [rad]
  double pitch = 0;            ///< [rad]
  std::string surface = "ground";  ///< contact material / optical surface label
};

/// The surface labels the library knows (materials of obstacles and floors, and the s-bot's own
/// parts as rays and contacts see them): what a per-surface effect (ir_reflectance) may name besides
/// a world's own labels (surfaceLabels). A dataset declares others under `surfaces:`.
const std::set<std::string>& knownSurfaces();

struct TerrainConfig {
  enum class Type { Plane, Composite, Rough };
  Type type = Type::Plane;
  bool ground_plane = true;             ///< infinite plane at z = 0 (Plane and Composite)
  std::vector<BoxObstacle> boxes;       ///< composite planes and obstacles (any terrain type)
  // Rough terrain (seed 2.4.1): a grey-scale image is a height map.
  std::string heightmap_image;          ///< path; empty = generated fractal noise from `seed`
  int resolution = 128;                 ///< samples per side when generated
  double size_x = 5.0, size_y = 5.0;    ///< [m]
  double height_range = 0.0;            ///< peak-to-peak height [m] (HR of Fig. 4.4 in cm / 100)
  std::uint64_t heightmap_seed = 1;
};

/// Every surface label `terrain` uses: its boxes' and, with the ground plane, "ground".
std::set<std::string> surfaceLabels(const TerrainConfig& terrain);

/// Sleeping at rest (rest.h says why): a robot commanded to stand that stood still is taken out
/// of the solve until something disturbs it.
struct RestConfig {
  /// Put robots to sleep at rest (scenario `world.sleep_at_rest`). Off: every robot is solved
  /// every step, creep included (to study the solver itself).
  bool enabled = true;
  /// [s] how long a robot must have stood still, commanded to stand, before it sleeps.
  double window_s = 0.5;
  /// [m] no body of the robot moved further than this during the window (6 mm/s at 0.5 s: a
  /// standing Simple creeps ~2 mm/s and rocks ~1 mm; at 2 mm one Simple in 20 took 7 s to settle).
  /// A robot sliding or tipping for real accelerates past it within the window.
  double max_shift_m = 0.003;
  /// [rad] no heavy body (see heavy_fraction) turned further than this during the window (a
  /// standing Simple rocks +-1.3 deg). Light bodies (wheels, the Basic gripper element) are left
  /// out: a wheel held at zero speed jitters a few degrees about its axle under quickstep.
  double max_turn_rad = 0.052;
  /// Bodies of at least this fraction of the robot's mass are "heavy" (chassis, turret).
  double heavy_fraction = 0.1;
};

struct WorldConfig {
  double step = 0.01;          ///< fixed integration step [s], in [kMinStep, kMaxStep]
  double gravity = 9.81;       ///< [m/s^2], pointing -z
  /// ODE stepper. "quickstep" (default): iterative, the validated configuration. "exact":
  /// dWorldStep's direct LCP solve per island: no yaw drift for Simple/Basic/Medium and faster for
  /// them, but ODE reports LCP failures on Detailed and the validation tables fall apart with it
  /// (docs/model.md, "Yaw drift under quickstep"; docs/validation.md, "Solver").
  std::string solver = "quickstep";
  int solver_iterations = 20;  ///< ODE quickstep iterations (ODE default; docs/model.md, "Solver")
  /// Raise the iterations to what the robots' levels need (RobotDescription::solver_iterations,
  /// Medium: 25, Detailed: 40) while such a robot is in the world. Off only to study the solver itself.
  bool level_iterations = true;
  double solver_sor = 1.3;     ///< ODE quickstep over-relaxation
  /// Opt-in: a turret that has reached its target is welded to the treels (one rigid body) until
  /// it is commanded elsewhere (Robot::turretLocked; quickstep only, and only turrets whose centre
  /// of mass is off their axis: Robot::weldsIdleTurret). Quickstep does not converge on the
  /// turret's 4 cm off-axis centre of mass hinged to the treels: a standing Medium turns -11 deg in
  /// 10 s on the hinge, +1.5 welded. Off by default: welded robots with the turret turned round
  /// and the gripper raised tilt 11 deg in an abrupt spin (hinge 4, exact solver 0.3) and toppled
  /// in the obstacle-avoidance scenario (docs/model.md, "Yaw drift under quickstep").
  bool lock_idle_turret = false;
  RestConfig rest;
  std::uint64_t seed = 1;      ///< root of every random stream
  ContactConfig contact;
  TerrainConfig terrain;
};

}  // namespace sbot
