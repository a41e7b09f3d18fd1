// What the core needs to build one s-bot in ODE: the URDF (links, inertias, collision shapes, joints,
// limits; parsed with urdfdom) plus the level's sidecar `<level>.sbot.yaml` (simulation semantics URDF
// cannot express: which joints drive the tracks, unit conversions, contact materials, sensor models).
// Both files are generated from sbot_description/config/sbot_parameters.yaml; see that package.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/types.h"

namespace sbot {

struct CollisionShape {
  enum class Type { Sphere, Cylinder, Box };
  Type type = Type::Sphere;
  double radius = 0;       ///< sphere, cylinder [m]
  double length = 0;       ///< cylinder along its local z [m]
  Vec3 size = Vec3::Zero();///< box edge lengths [m]
  Pose origin;             ///< in the link frame
};

struct LinkDescription {
  std::string name;
  double mass = 0;                 ///< [kg]; 0 for massless frames (sensors, markers)
  Pose inertial_origin;            ///< centre of mass frame in the link frame
  Mat3 inertia = Mat3::Zero();     ///< [kg m^2] about the centre of mass, in the inertial frame
  std::vector<CollisionShape> collisions;
  std::string material = "body";   ///< contact material (sidecar `materials`), see ContactConfig
};

struct JointDescription {
  enum class Type { Fixed, Revolute, Continuous };
  std::string name, parent, child;
  Type type = Type::Fixed;
  Pose origin;                     ///< child frame in the parent frame
  Vec3 axis = Vec3::UnitZ();       ///< in the child frame
  double lower = 0, upper = 0;     ///< [rad], revolute only
  double effort = 0;               ///< [N m] URDF limit (the motor's maximum torque)
  double velocity = 0;             ///< [rad/s] URDF limit
};

/// Track drive ("treels"): API speed units to wheel angular velocity, torque limits. Table 2.2.
struct TreelsSemantics {
  std::vector<std::string> left_joints, right_joints;  ///< driven wheel hinges, +rotation = forward
  double wheel_radius = 0.022;       ///< [m] used for the unit conversion of every driven wheel
  std::map<std::string, double> wheel_radii;  ///< per-joint override [m] (mixed wheel sizes)
  double max_torque = 0.21971;       ///< [N m] per track at the axle (90 units)
  double torque_unit = 0.0024412;    ///< [N m] per API torque unit
  double speed_unit = 0.0028;        ///< [m/s] per API speed unit
  int speed_limit_units = 70;        ///< simulator limit (seed 2.2.1); API range is [-127,127]
  double gear_ratio = 150;           ///< motor to axle
  double rotor_inertia = 0;          ///< [kg m^2] of one track motor's rotor (reflected: x gear^2)
  double backdrive_force = 1.2;      ///< [N] to pull the whole robot with its motors off (passive)
  double torque_window = 0.1;        ///< [s] getTrackTorque reports the mean motor torque over this window
  /// Track creep: a driven track slips back over the terrain at the slip ratio (F/N) / this of its
  /// own speed, F/N its traction ratio (World applies it to the driven wheels' terrain contacts).
  /// Dimensionless; 0 = no creep. Wheel drives only.
  double creep_stiffness = 0;
  /// Friction of this level's treels abstraction relative to the track material: a driven wheel's
  /// contacts (and Fast's body drive) use mu("track", surface) times this. Dimensionless, > 0.
  double friction_scale = 1.0;
  /// How this level's contacts with the terrain limit friction (sidecar friction_law).
  /// Coulomb ("coulomb"): mu times the normal force (ODE's friction pyramid, dContactApprox1), mu
  /// from the surface materials times friction_scale. ForceLimit ("force_limit"): the seed's own law
  /// (Table 2.2 note 4, Vortex's "isotropic friction"): every contact holds up to
  /// friction_force_limit, whatever its normal force. An enum: World reads it on every contact.
  enum class FrictionLaw { Coulomb, ForceLimit };
  FrictionLaw friction_law = FrictionLaw::Coulomb;
  double friction_force_limit = 1.2;  ///< [N] per contact, friction_law force_limit only
  /// "wheels": a velocity motor on every driven hinge (wheel-ground contacts carry the robot);
  /// "body": the tracks drive the chassis directly as an ideal differential drive (Robot, Fast).
  std::string drive = "wheels";
};

/// Turret servo. Table 2.3.
struct TurretSemantics {
  std::string joint;                 ///< empty when the level has no turret joint
  double speed = 0.5;                ///< [rad/s]
  double unit = 0.034906585;         ///< [rad] per API unit (2 degrees)
  int range_units = 100;             ///< API range [-range, range]
  double max_torque = 1.0;           ///< [N m]
  double torque_unit = 0.0117176;    ///< [N m] per API torque unit
};

struct RobotDescription {
  std::string level;                 ///< fast, simple, basic, medium, detailed
  std::string urdf_path, sidecar_path, urdf_xml;
  std::string root_link;
  std::vector<LinkDescription> links;      ///< root first, then parents before children
  std::vector<JointDescription> joints;    ///< in the same order as the child links
  TreelsSemantics treels;
  TurretSemantics turret;
  double recommended_step = 0.01;          ///< [s]
  double gravity = 9.81;                   ///< [m/s^2] the level's world gravity (Fast: reduced)
  /// Quickstep iterations this level needs to behave as validated (sidecar extra solver_iterations;
  /// 0 = no requirement). A World raises its iterations to the largest need of its robots.
  int solver_iterations = 0;
  std::map<std::string, std::string> extra;///< sidecar `extra` scalars (sensor models, ...), as text
  YAML::Node sidecar;                      ///< the whole sidecar, for modules with structured entries

  const LinkDescription* findLink(const std::string& name) const;
  const JointDescription* findJoint(const std::string& name) const;
  double totalMass() const;
  /// Radius converting API speed units to this driven joint's rad/s.
  double wheelRadius(const std::string& joint) const;
  std::string extraOr(const std::string& key, const std::string& fallback) const;
};

/// The number at sidecar[entry][key] of `d` (e.g. "gripper", "jaw_speed"), or `fallback` when the
/// entry or the key is absent. One reader for the optional parameters of the actuator modules (front
/// gripper, side arm). Throws ConfigError naming the sidecar and "entry.key" for a value that is not
/// a finite number.
double sidecarNumber(const RobotDescription& d, const char* entry, const char* key, double fallback);

/// Parse one URDF and its sidecar. Throws ConfigError naming the file and field on bad input.
RobotDescription loadRobotDescription(const std::string& urdf_path, const std::string& sidecar_path);

/// Directory holding `urdf/<level>.urdf` and `urdf/<level>.sbot.yaml`: $SBOT_DESCRIPTION_DIR if
/// set, otherwise the sbot_description source directory this library was built against.
std::string descriptionDirectory();

/// The contact materials a robot's links can be made of (sidecar `materials`;
/// sbot_description/README.md): a scenario's contact.materials may name these and the terrain's surfaces.
const std::set<std::string>& robotMaterials();

/// The five model levels, cheapest first.
const std::vector<std::string>& modelLevels();

/// Load a level by name from descriptionDirectory(); cached, so spawning many robots parses once.
const RobotDescription& loadLevel(const std::string& level);

/// True for a level made for a reduced gravity (Fast: half size, 1/20 mass, motors scaled for 1/50 g).
bool scaledForItsGravity(const RobotDescription& d);

/// Why a robot of `d` cannot live in a world of `world_gravity` [m/s^2], or "" when it can. Only a
/// level made for a reduced gravity (Fast: half size, 1/20 mass, motors scaled for 1/50 g, seed 3.1)
/// is bound to it; the full-size levels carry real masses and torques and work under any gravity.
std::string gravityProblem(const RobotDescription& d, double world_gravity);

}  // namespace sbot
