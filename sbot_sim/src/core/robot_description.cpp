#include "sbot_sim/core/robot_description.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include <Eigen/Cholesky>
#include <urdf_parser/urdf_parser.h>
#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/yaml_checks.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/world_config.h"

#ifndef SBOT_DESCRIPTION_SOURCE_DIR
#define SBOT_DESCRIPTION_SOURCE_DIR ""
#endif

namespace sbot {
namespace {

Pose toPose(const urdf::Pose& p) {
  double x, y, z, w;
  p.rotation.getQuaternion(x, y, z, w);
  return Pose(Vec3(p.position.x, p.position.y, p.position.z), Quat(w, x, y, z).normalized());
}

/// The XML of `<link name="NAME" ...>` up to its end, comments removed ("" if not found).
std::string linkXml(const std::string& xml, const std::string& name) {
  std::string text;  // without <!-- comments -->
  for (std::size_t i = 0; i < xml.size();) {
    const std::size_t c = xml.find("<!--", i);
    text += xml.substr(i, c == std::string::npos ? std::string::npos : c - i);
    if (c == std::string::npos) break;
    const std::size_t e = xml.find("-->", c + 4);
    i = e == std::string::npos ? xml.size() : e + 3;
  }
  for (const char q : {'"', '\''}) {
    const std::size_t start = text.find("<link name=" + std::string(1, q) + name + q);
    if (start == std::string::npos) continue;
    const std::size_t open_end = text.find('>', start);
    if (open_end == std::string::npos) return "";
    if (text[open_end - 1] == '/') return text.substr(start, open_end + 1 - start);  // <link .../>
    const std::size_t end = text.find("</link>", open_end);
    return text.substr(start, end == std::string::npos ? std::string::npos : end - start);
  }
  return "";
}

std::size_t countTags(const std::string& xml, const std::string& tag) {
  std::size_t n = 0;
  for (std::size_t i = xml.find("<" + tag); i != std::string::npos; i = xml.find("<" + tag, i + 1)) {
    const char next = i + 1 + tag.size() < xml.size() ? xml[i + 1 + tag.size()] : '>';
    n += (next == '>' || next == ' ' || next == '/' || next == '\n' || next == '\t' || next == '\r');
  }
  return n;
}

constexpr double kMaxTorqueWindow = 10;  ///< [s] treels.torque_window
// Bounds on a description's numbers: far beyond any s-bot (12 cm, 0.66 kg), yet finite values past
// them (1e300) overflow ODE's normalisations, which abort the process instead of reporting.
constexpr double kMaxLength = 100;     ///< [m] offsets and shape sizes
constexpr double kMaxMass = 1000;      ///< [kg] per link
constexpr double kMaxInertia = 1000;   ///< [kg m^2] per inertia entry

void requirePositive(double v, const std::string& file, const std::string& field) {
  if (!(std::isfinite(v) && v > 0)) throw ConfigError(file, field, "must be a finite number > 0");
}

/// A shape's edge, radius or length: degenerate geometry is refused here, not by an ODE assertion.
void requireGeomSize(double v, const std::string& file, const std::string& field) {
  if (const std::string problem = geomSizeProblem(v); !problem.empty()) throw ConfigError(file, field, problem);
}

void requireAtMost(double v, double limit, const std::string& file, const std::string& field, const char* unit) {
  if (!(std::abs(v) <= limit)) {
    std::ostringstream why;
    why << "must be at most " << limit << " " << unit << " in size, found " << v;
    throw ConfigError(file, field, why.str());
  }
}

void requireReasonableOrigin(const Pose& origin, const std::string& file, const std::string& field) {
  for (int k = 0; k < 3; ++k) requireAtMost(origin.position[k], kMaxLength, file, field + " xyz", "m");
}

LinkDescription convertLink(const urdf::Link& link, const std::string& xml, const std::string& file) {
  LinkDescription out;
  out.name = link.name;
  // urdfdom drops an <inertial> or <collision> it cannot parse (mass="nan", radius="x") with only
  // a message on stderr; the link would then load massless or without that shape.
  const std::string own = linkXml(xml, link.name);
  if (!own.empty()) {
    const std::size_t inertials = countTags(own, "inertial"), collisions = countTags(own, "collision");
    if (inertials != (link.inertial ? 1u : 0u) || collisions != link.collision_array.size())
      throw ConfigError(file, "link " + link.name,
                        "urdfdom could not parse all of it: it kept " + std::to_string(link.inertial ? 1 : 0) + " of " +
                            std::to_string(inertials) + " <inertial> and " + std::to_string(link.collision_array.size()) +
                            " of " + std::to_string(collisions) + " <collision> elements (its message is printed above)");
  }
  if (link.inertial) {
    const urdf::Inertial& in = *link.inertial;
    if (!(std::isfinite(in.mass) && in.mass >= 0))
      throw ConfigError(file, "link " + link.name + "/inertial/mass", "must be a finite number >= 0");
    requireAtMost(in.mass, kMaxMass, file, "link " + link.name + "/inertial/mass", "kg");
    out.mass = in.mass;
    out.inertial_origin = toPose(in.origin);
    requireReasonableOrigin(out.inertial_origin, file, "link " + link.name + "/inertial/origin");
    out.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const std::string field = "link " + link.name + "/inertial/inertia";
    if (!out.inertia.allFinite()) throw ConfigError(file, field, "must be finite");
    for (int k = 0; k < 9; ++k) requireAtMost(out.inertia(k / 3, k % 3), kMaxInertia, file, field, "kg m^2");
    if (in.mass > 0 && (in.ixx <= 0 || in.iyy <= 0 || in.izz <= 0)) {
      throw ConfigError(file, field, "diagonal inertia must be positive for a link with mass");
    }
    // ODE refuses (aborts on) an inertia tensor that is not positive definite: products of inertia
    // too large for the moments.
    if (in.mass > 0 && Eigen::LLT<Mat3>(out.inertia).info() != Eigen::Success) {
      throw ConfigError(file, field,
                        "must be positive definite (ixy, ixz, iyz too large for ixx, iyy, izz); a rigid body's is");
    }
  }
  for (const auto& col : link.collision_array) {
    if (!col || !col->geometry)
      throw ConfigError(file, "link " + link.name + "/collision", "has no geometry");
    const std::string field = "link " + link.name + "/collision/geometry";
    CollisionShape shape;
    shape.origin = toPose(col->origin);
    requireReasonableOrigin(shape.origin, file, "link " + link.name + "/collision/origin");
    switch (col->geometry->type) {
      case urdf::Geometry::SPHERE:
        shape.type = CollisionShape::Type::Sphere;
        shape.radius = static_cast<const urdf::Sphere&>(*col->geometry).radius;
        requireGeomSize(shape.radius, file, field + "/sphere radius");
        requireAtMost(shape.radius, kMaxLength, file, field + "/sphere radius", "m");
        break;
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(*col->geometry);
        shape.type = CollisionShape::Type::Cylinder;
        shape.radius = c.radius;
        shape.length = c.length;
        requireGeomSize(shape.radius, file, field + "/cylinder radius");
        requireGeomSize(shape.length, file, field + "/cylinder length");
        requireAtMost(std::max(shape.radius, shape.length), kMaxLength, file, field + "/cylinder", "m");
        break;
      }
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(*col->geometry);
        shape.type = CollisionShape::Type::Box;
        shape.size = Vec3(b.dim.x, b.dim.y, b.dim.z);
        for (int k = 0; k < 3; ++k) requireGeomSize(shape.size[k], file, field + "/box size");
        for (int k = 0; k < 3; ++k) requireAtMost(shape.size[k], kMaxLength, file, field + "/box size", "m");
        break;
      }
      default:
        throw ConfigError(file, "link " + link.name + "/collision/geometry",
                          "expected sphere, cylinder or box, found a mesh");
    }
    out.collisions.push_back(shape);
  }
  return out;
}

JointDescription convertJoint(const urdf::Joint& j, const std::string& file) {
  JointDescription out;
  out.name = j.name;
  out.parent = j.parent_link_name;
  out.child = j.child_link_name;
  out.origin = toPose(j.parent_to_joint_origin_transform);
  requireReasonableOrigin(out.origin, file, "joint " + j.name + "/origin");
  out.axis = Vec3(j.axis.x, j.axis.y, j.axis.z);
  switch (j.type) {
    case urdf::Joint::FIXED: out.type = JointDescription::Type::Fixed; break;
    case urdf::Joint::REVOLUTE: out.type = JointDescription::Type::Revolute; break;
    case urdf::Joint::CONTINUOUS: out.type = JointDescription::Type::Continuous; break;
    default:
      throw ConfigError(file, "joint " + j.name + "/type",
                        "expected fixed, revolute or continuous (the s-bot has no other joints)");
  }
  if (out.type != JointDescription::Type::Fixed) {
    if (out.axis.norm() < 1e-9) throw ConfigError(file, "joint " + j.name + "/axis", "zero axis");
    out.axis.normalize();
  }
  if (j.limits) {
    out.lower = j.limits->lower;
    out.upper = j.limits->upper;
    out.effort = j.limits->effort;
    out.velocity = j.limits->velocity;
  }
  if (out.type == JointDescription::Type::Revolute && !(out.lower <= out.upper)) {
    throw ConfigError(file, "joint " + j.name + "/limit", "lower limit above upper limit");
  }
  return out;
}

/// The sidecar's `extra` entries: what each may hold. The modules read most of them (sensor
/// constants, models, solver iterations); the counts of the seed's tables (ir_count, mic_count,
/// led_groups, camera size, reading maxima) document the hardware and are checked all the same, so
/// that an edited value is refused rather than silently meaning nothing.
struct ExtraRule {
  const char* key;
  enum Kind { Choice, Flag, Number, Count } kind;
  double lo = 0, hi = 0;           // Number: lo < v <= hi (lo_inclusive: lo <= v); Count: lo <= v <= hi
  const char* choices = "";        // Choice: '|'-separated
  bool lo_inclusive = false;
};
const std::vector<ExtraRule>& extraRules() {
  using R = ExtraRule;
  constexpr double kPi = 3.14159265358979323846;
  static const std::vector<ExtraRule> rules{
      {"ir_model", R::Choice, 0, 0, "lut|raytrace"},
      {"camera", R::Choice, 0, 0, "fake|raw"},
      {"sound_model", R::Choice, 0, 0, "simple|complex"},
      {"light_ring", R::Choice, 0, 0, "leds|full"},
      {"gripper", R::Choice, 0, 0, "none|sticky|jaws"},
      {"treels_model", R::Choice, 0, 0, "two_wheels_casters|six_spheres|six_teethed_cylinders"},
      {"ground_sensors", R::Flag},
      {"side_arm", R::Flag},
      {"dynamical_bodies", R::Count, 1, 100},
      {"solver_iterations", R::Count, 0, 100000},  // 0: the world's
      {"ir_count", R::Count, 1, 15},
      {"ir_rays", R::Count, 1, 1000},
      {"ground_rays", R::Count, 1, 1000},
      {"mic_count", R::Count, 1, 3},
      {"led_groups", R::Count, 1, 8},
      {"led_max_units", R::Count, 1, 255},
      {"camera_width", R::Count, 16, 4096},
      {"camera_height", R::Count, 16, 4096},
      {"ir_max_reading_units", R::Count, 1, 65535},
      {"ground_max_reading_units", R::Count, 1, 65535},
      {"ir_range_min_m", R::Number, 0, 1},
      {"ir_range_max_m", R::Number, 0, 10},
      {"ground_range_min_m", R::Number, 0, 1},
      {"ground_range_max_m", R::Number, 0, 10},
      {"ir_cone_angle_rad", R::Number, 0, kPi},
      {"ground_cone_angle_rad", R::Number, 0, kPi},
      {"ir_sensitivity_angle_rad", R::Number, 0, kPi},
      {"fake_camera_vertical_angle_rad", R::Number, 0, kPi},
      {"fake_camera_range_m", R::Number, 0, 1000},
      {"ir_noise", R::Number, 0, 10, "", true},  // relative (0.1 = 10 %)
      {"ground_noise", R::Number, 0, 10, "", true},
      {"sound_noise", R::Number, 0, 10, "", true},
      {"ir_fit_a", R::Number, -1e6, 1e6},  // eq. 2.5's log-log fit
      {"ir_fit_b", R::Number, -1e6, 1e6},
      {"ground_fit_a", R::Number, -1e6, 1e6},
      {"ground_fit_b", R::Number, -1e6, 1e6},
      {"led_unit_mcd", R::Number, 0, 1e6},
      {"light_sensor_unit_mcd_cm2", R::Number, 0, 1e6},
      {"light_sensor_max_units", R::Number, 0, 1e6},
      {"blink_max_hz", R::Number, 0, 1e3},
      {"friction_force_N", R::Number, 0, 1e3, "", true},
      {"inertia_floor_kgm2", R::Number, 0, 1, "", true},
  };
  return rules;
}

void checkExtra(const YAML::Node& e, const std::string& file) {
  if (!e.IsMap()) throw ConfigError(file, "extra", "expected a mapping of names to values");
  const auto& rules = extraRules();
  for (const auto& kv : e) {
    const std::string key = kv.first.as<std::string>(), field = "extra." + key;
    const auto rule = std::find_if(rules.begin(), rules.end(), [&](const ExtraRule& r) { return key == r.key; });
    if (rule == rules.end()) {
      std::set<std::string> known;
      for (const auto& r : rules) known.insert(r.key);
      throw ConfigError(file, field, unknownFieldMessage(known));
    }
    if (!kv.second.IsScalar()) throw ConfigError(file, field, "expected a single value");
    const std::string text = kv.second.Scalar();
    if (rule->kind == ExtraRule::Choice) {
      const std::string choices = std::string("|") + rule->choices + "|";
      if (choices.find("|" + text + "|") == std::string::npos)
        throw ConfigError(file, field, "expected one of " + std::string(rule->choices) + ", found '" + text + "'");
      continue;
    }
    if (rule->kind == ExtraRule::Flag) {
      if (text != "true" && text != "false") throw ConfigError(file, field, "expected true or false, found '" + text + "'");
      continue;
    }
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    const bool number = !text.empty() && end && *end == '\0' && std::isfinite(v);
    std::ostringstream range;
    if (rule->kind == ExtraRule::Count) {
      range << "a whole number in [" << rule->lo << ", " << rule->hi << "]";
      if (!number || v != std::floor(v) || v < rule->lo || v > rule->hi)
        throw ConfigError(file, field, "expected " + range.str() + ", found '" + text + "'");
    } else {
      range << "a finite number in " << (rule->lo_inclusive ? "[" : "(") << rule->lo << ", " << rule->hi << "]";
      if (!number || v > rule->hi || v < rule->lo || (!rule->lo_inclusive && v == rule->lo))
        throw ConfigError(file, field, "expected " + range.str() + ", found '" + text + "'");
    }
  }
  for (const char* sensor : {"ir", "ground"}) {
    const std::string lo = std::string(sensor) + "_range_min_m", hi = std::string(sensor) + "_range_max_m";
    if (e[lo] && e[hi] && !(e[lo].as<double>() < e[hi].as<double>()))
      throw ConfigError(file, "extra." + lo, "must be below extra." + hi);
  }
}

template <typename T>
T get(const YAML::Node& node, const std::string& key, const T& fallback, const std::string& file,
      const std::string& prefix) {
  if (!node || !node[key]) return fallback;
  try {
    return node[key].as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError(file, prefix + key, "has the wrong type");
  }
}

/// The side arm's section (Detailed): the names it gives must be the URDF's, and the loop joints'
/// anchors and axes finite 3-vectors (a NaN anchor or a zero axis aborts inside ODE).
static void checkSideArm(const YAML::Node& arm, const RobotDescription& d, const std::string& file) {
  const auto text = [&](const YAML::Node& n, const std::string& field) {
    if (!n.IsScalar()) throw ConfigError(file, field, "expected a name");
    return n.Scalar();
  };
  const auto link = [&](const YAML::Node& n, const std::string& field) {
    const std::string name = text(n, field);
    if (!d.findLink(name)) throw ConfigError(file, field, "no link '" + name + "' in " + d.urdf_path);
  };
  const auto joint = [&](const YAML::Node& n, const std::string& field) {
    const std::string name = text(n, field);
    if (!d.findJoint(name)) throw ConfigError(file, field, "no joint '" + name + "' in " + d.urdf_path);
  };
  for (const char* key : {"base_link", "tip_link"})
    if (arm[key]) link(arm[key], std::string("side_arm.") + key);
  if (const YAML::Node servos = arm["servos"]) {
    if (!servos.IsMap()) throw ConfigError(file, "side_arm.servos", "expected a mapping of servo names to joints");
    for (const auto& kv : servos) joint(kv.second, "side_arm.servos." + kv.first.Scalar());
  }
  if (const YAML::Node passive = arm["passive_joints"]) {
    if (!passive.IsSequence()) throw ConfigError(file, "side_arm.passive_joints", "expected a list of joints");
    for (std::size_t i = 0; i < passive.size(); ++i) joint(passive[i], "side_arm.passive_joints[" + std::to_string(i) + "]");
  }
  if (const YAML::Node loops = arm["loop_joints"]) {
    if (!loops.IsSequence()) throw ConfigError(file, "side_arm.loop_joints", "expected a list of {name, parent, child, ...}");
    for (std::size_t i = 0; i < loops.size(); ++i) {
      const std::string at = "side_arm.loop_joints[" + std::to_string(i) + "]";
      const YAML::Node lj = loops[i];
      if (!lj.IsMap()) throw ConfigError(file, at, "expected a mapping {name, parent, child, anchor_in_parent, axis}");
      for (const char* key : {"parent", "child"}) {
        if (!lj[key]) throw ConfigError(file, at + "." + key, "missing");
        link(lj[key], at + "." + key);
      }
      for (const char* key : {"anchor_in_parent", "anchor_in_child", "axis"}) {
        if (!lj[key]) continue;
        const std::string field = at + "." + key;
        const YAML::Node v = lj[key];
        Vec3 x;
        try {
          if (!v.IsSequence() || v.size() != 3) throw YAML::Exception(YAML::Mark::null_mark(), "");
          x = Vec3(v[0].as<double>(), v[1].as<double>(), v[2].as<double>());
        } catch (const YAML::Exception&) {
          throw ConfigError(file, field, "expected [x, y, z], three numbers");
        }
        if (!x.allFinite()) throw ConfigError(file, field, "must be finite");
        for (int k = 0; k < 3; ++k) requireAtMost(x[k], kMaxLength, file, field, "m");
        if (std::string(key) == "axis" && x.norm() < 1e-9) throw ConfigError(file, field, "zero axis");
      }
    }
  }
}

void parseSidecar(RobotDescription& d) {
  const std::string& file = d.sidecar_path;
  YAML::Node root;
  try {
    root = YAML::Load(readInputFile(file, "sidecar file"));
  } catch (const YAML::Exception& e) {
    throw ConfigError(file, "", std::string("not valid YAML: ") + e.what());
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty()) throw ConfigError(file, "", problem);
  if (!root.IsMap()) throw ConfigError(file, "", "expected a mapping at the top level");
  const std::set<std::string> sections{"level",     "recommended_step", "gravity", "treels", "turret",
                                       "materials", "extra",            "gripper", "side_arm"};
  if (const YAML::Node key = unknownKey(root, sections)) throw ConfigError(file, key.Scalar(), unknownFieldMessage(sections));
  for (const char* section : {"treels", "turret", "materials", "extra", "gripper", "side_arm"})
    if (root[section] && !root[section].IsMap()) throw ConfigError(file, section, "expected a mapping");
  // The fields of each section (sbot_description/README.md; generate_urdf.py writes them): a
  // misspelt field would otherwise leave its default in force unseen. The second set: numbers that
  // no later check reads here (the modules read them when they are built), checked finite now.
  const std::map<std::string, std::pair<std::set<std::string>, std::set<std::string>>> fields{
      {"treels",
       {{"left_joints", "right_joints", "wheel_radii", "friction_law", "drive", "wheel_radius", "max_torque",
         "torque_unit", "speed_unit", "speed_limit_units", "gear_ratio", "rotor_inertia", "backdrive_force",
         "torque_window", "creep_stiffness", "friction_scale", "friction_force_limit"},
        {"max_speed", "wheel_effort"}}},
      {"turret", {{"joint", "speed", "unit", "range_units", "max_torque", "torque_unit"}, {}}},
      {"gripper",
       {{"type", "link", "tip_frame", "elevation_joint", "jaw_joints"},
        {"grip_point", "aperture_max", "elevation_lower", "elevation_upper", "elevation_speed", "elevation_torque",
         "jaw_force", "jaw_length", "jaw_speed", "jaw_torque", "zero_set_point"}}},
      {"side_arm",
       {{"base_link", "tip_link", "servos", "passive_joints", "loop_joints", "kinematics"},
        {"rest_azimuth", "link_length", "rhombi", "rest_half_angle", "half_angle_min", "half_angle_max",
         "rotation_range", "depth_rest", "unit", "elevation_torque", "horizontal_torque", "servo_speed", "jaw_force",
         "jaw_speed", "jaw_torque", "aperture_max"}}}};
  for (const auto& [section, kinds] : fields) {
    const YAML::Node n = root[section];
    if (!n) continue;
    std::set<std::string> known = kinds.first;
    known.insert(kinds.second.begin(), kinds.second.end());
    if (const YAML::Node key = unknownKey(n, known))
      throw ConfigError(file, section + "." + key.Scalar(), unknownFieldMessage(known));
    for (const std::string& key : kinds.second) {
      if (!n[key]) continue;
      double v = 0;
      try {
        v = n[key].as<double>();
      } catch (const YAML::Exception&) {
        throw ConfigError(file, section + "." + key, "expected a number");
      }
      if (!std::isfinite(v)) throw ConfigError(file, section + "." + key, "must be finite");
    }
  }
  // Speeds, torques, forces and sizes of the grippers: a zero made a jaw that never closes (its
  // delay is aperture / speed) and an arm without limits. And their ranges must be ranges.
  const auto number = [&](const char* section, const char* key) { return root[section][key].as<double>(); };
  const std::pair<const char*, std::vector<const char*>> positives[] = {
      {"gripper", {"aperture_max", "elevation_speed", "elevation_torque", "jaw_force", "jaw_length", "jaw_speed", "jaw_torque"}},
      {"side_arm", {"link_length", "rhombi", "rotation_range", "unit", "elevation_torque", "horizontal_torque",
                    "servo_speed", "jaw_force", "jaw_speed", "jaw_torque", "aperture_max"}}};
  for (const auto& [section, keys] : positives)
    for (const char* key : keys)
      if (root[section] && root[section][key] && !(number(section, key) > 0))
        throw ConfigError(file, std::string(section) + "." + key, "must be > 0");
  const std::array<const char*, 4> ordered[] = {{"gripper", "elevation_lower", "elevation_upper", ""},
                                                {"side_arm", "half_angle_min", "rest_half_angle", "half_angle_max"}};
  for (const auto& o : ordered) {
    const char* section = o[0];
    if (!root[section]) continue;
    std::vector<const char*> given;
    for (int k = 1; k < 4; ++k)
      if (*o[k] && root[section][o[k]]) given.push_back(o[k]);
    for (std::size_t k = 1; k < given.size(); ++k)
      if (!(number(section, given[k - 1]) < number(section, given[k])))
        throw ConfigError(file, std::string(section) + "." + given[k - 1],
                          std::string("must be below ") + section + "." + given[k]);
  }
  d.level = get<std::string>(root, "level", "", file, "");
  if (d.level.empty()) throw ConfigError(file, "level", "missing");
  d.recommended_step = get<double>(root, "recommended_step", 0.01, file, "");
  d.gravity = get<double>(root, "gravity", 9.81, file, "");

  const YAML::Node t = root["treels"];
  if (!t) throw ConfigError(file, "treels", "missing");
  auto& tr = d.treels;
  tr.left_joints = get<std::vector<std::string>>(t, "left_joints", {}, file, "treels.");
  tr.right_joints = get<std::vector<std::string>>(t, "right_joints", {}, file, "treels.");
  tr.wheel_radius = get<double>(t, "wheel_radius", tr.wheel_radius, file, "treels.");
  tr.wheel_radii = get<std::map<std::string, double>>(t, "wheel_radii", {}, file, "treels.");
  tr.max_torque = get<double>(t, "max_torque", tr.max_torque, file, "treels.");
  tr.torque_unit = get<double>(t, "torque_unit", tr.torque_unit, file, "treels.");
  tr.speed_unit = get<double>(t, "speed_unit", tr.speed_unit, file, "treels.");
  tr.speed_limit_units = get<int>(t, "speed_limit_units", tr.speed_limit_units, file, "treels.");
  tr.gear_ratio = get<double>(t, "gear_ratio", tr.gear_ratio, file, "treels.");
  tr.rotor_inertia = get<double>(t, "rotor_inertia", tr.rotor_inertia, file, "treels.");
  tr.backdrive_force = get<double>(t, "backdrive_force", tr.backdrive_force, file, "treels.");
  tr.torque_window = get<double>(t, "torque_window", tr.torque_window, file, "treels.");
  tr.creep_stiffness = get<double>(t, "creep_stiffness", tr.creep_stiffness, file, "treels.");
  tr.friction_scale = get<double>(t, "friction_scale", tr.friction_scale, file, "treels.");
  // Every number below divides, scales or limits a motor: NaN, 0 or a sign error would silently
  // give a robot that cannot drive or one that explodes.
  const auto nonNegative = [&](double v, const std::string& field) {
    if (!(std::isfinite(v) && v >= 0)) throw ConfigError(file, field, "must be a finite number >= 0");
  };
  if (!(d.recommended_step >= kMinStep && d.recommended_step <= kMaxStep)) {
    std::ostringstream why;
    why << "expected a step in [" << kMinStep << ", " << kMaxStep << "] s (as a scenario's world.step), found "
        << d.recommended_step;
    throw ConfigError(file, "recommended_step", why.str());
  }
  nonNegative(d.gravity, "gravity");
  requireAtMost(d.gravity, kMaxGravity, file, "gravity", "m/s^2");
  requirePositive(tr.max_torque, file, "treels.max_torque");
  requirePositive(tr.torque_unit, file, "treels.torque_unit");
  requirePositive(tr.speed_unit, file, "treels.speed_unit");
  requirePositive(tr.speed_limit_units, file, "treels.speed_limit_units");
  requirePositive(tr.gear_ratio, file, "treels.gear_ratio");
  for (const auto& r : tr.wheel_radii) requirePositive(r.second, file, "treels.wheel_radii." + r.first);
  nonNegative(tr.rotor_inertia, "treels.rotor_inertia");
  nonNegative(tr.backdrive_force, "treels.backdrive_force");
  nonNegative(tr.torque_window, "treels.torque_window");
  // A buffer of torque_window / step samples per robot: 1e7 s took a node past 24 GB.
  if (tr.torque_window > kMaxTorqueWindow)
    throw ConfigError(file, "treels.torque_window", "must be <= " + std::to_string(static_cast<int>(kMaxTorqueWindow)) +
                                                        " s (getTrackTorque's averaging window)");
  nonNegative(tr.creep_stiffness, "treels.creep_stiffness");
  requirePositive(tr.friction_scale, file, "treels.friction_scale");
  const std::string law = get<std::string>(t, "friction_law", "coulomb", file, "treels.");
  if (law != "coulomb" && law != "force_limit")
    throw ConfigError(file, "treels.friction_law", "expected 'coulomb' or 'force_limit', found '" + law + "'");
  tr.friction_law = law == "force_limit" ? TreelsSemantics::FrictionLaw::ForceLimit : TreelsSemantics::FrictionLaw::Coulomb;
  tr.friction_force_limit = get<double>(t, "friction_force_limit", tr.friction_force_limit, file, "treels.");
  requirePositive(tr.friction_force_limit, file, "treels.friction_force_limit");
  tr.drive = get<std::string>(t, "drive", tr.drive, file, "treels.");
  if (tr.drive != "wheels" && tr.drive != "body")
    throw ConfigError(file, "treels.drive", "expected 'wheels' or 'body', found '" + tr.drive + "'");
  if (tr.left_joints.empty() || tr.right_joints.empty())
    throw ConfigError(file, "treels.left_joints/right_joints", "each track needs at least one driven joint");
  requirePositive(tr.wheel_radius, file, "treels.wheel_radius");
  std::set<std::string> driven;  // one joint, one track, once
  for (const auto& side : {tr.left_joints, tr.right_joints}) {
    for (const auto& name : side) {
      const JointDescription* j = d.findJoint(name);
      if (!j) throw ConfigError(file, "treels", "driven joint '" + name + "' is not in " + d.urdf_path);
      if (j->type != JointDescription::Type::Continuous && j->type != JointDescription::Type::Revolute)
        throw ConfigError(file, "treels", "driven joint '" + name + "' must be continuous, found fixed");
      if (!driven.insert(name).second)
        throw ConfigError(file, "treels.left_joints/right_joints",
                          "driven joint '" + name + "' is listed twice (each joint drives one track, once)");
    }
  }
  for (const auto& r : tr.wheel_radii)
    if (!driven.count(r.first))
      throw ConfigError(file, "treels.wheel_radii." + r.first,
                        "not a driven joint (driven joints: " + nameList(driven) + ")");

  if (const YAML::Node tu = root["turret"]) {
    auto& tt = d.turret;
    tt.joint = get<std::string>(tu, "joint", "", file, "turret.");
    tt.speed = get<double>(tu, "speed", tt.speed, file, "turret.");
    tt.unit = get<double>(tu, "unit", tt.unit, file, "turret.");
    tt.range_units = get<int>(tu, "range_units", tt.range_units, file, "turret.");
    tt.max_torque = get<double>(tu, "max_torque", tt.max_torque, file, "turret.");
    tt.torque_unit = get<double>(tu, "torque_unit", tt.torque_unit, file, "turret.");
    const JointDescription* tj = tt.joint.empty() ? nullptr : d.findJoint(tt.joint);
    if (!tt.joint.empty() && !tj)
      throw ConfigError(file, "turret.joint", "joint '" + tt.joint + "' is not in " + d.urdf_path);
    if (tj && tj->type == JointDescription::Type::Fixed)
      throw ConfigError(file, "turret.joint", "joint '" + tt.joint + "' must be revolute or continuous, found fixed in " +
                                                  d.urdf_path);
    for (const auto& side : {tr.left_joints, tr.right_joints})
      for (const auto& name : side)
        if (name == tt.joint) throw ConfigError(file, "turret.joint", "'" + name + "' is a driven treels joint");
    if (!tt.joint.empty()) {
      requirePositive(tt.speed, file, "turret.speed");
      requirePositive(tt.unit, file, "turret.unit");
      requirePositive(tt.range_units, file, "turret.range_units");
      requirePositive(tt.max_torque, file, "turret.max_torque");
      requirePositive(tt.torque_unit, file, "turret.torque_unit");
    }
  }

  if (const YAML::Node m = root["materials"]) {
    for (const auto& kv : m) {
      const auto link = kv.first.as<std::string>();
      const std::string material = kv.second.IsScalar() ? kv.second.Scalar() : "";
      if (!robotMaterials().count(material)) {
        throw ConfigError(file, "materials." + link,
                          "unknown material '" + material + "' (materials: " + nameList(robotMaterials()) + ")");
      }
      bool found = false;
      for (auto& l : d.links) {
        if (l.name == link) {
          l.material = kv.second.as<std::string>();
          found = true;
        }
      }
      if (!found) throw ConfigError(file, "materials." + link, "no such link in " + d.urdf_path);
    }
  }
  if (const YAML::Node g = root["gripper"]) {
    if (!g.IsMap()) throw ConfigError(file, "gripper", "expected a mapping");
    const std::string type = get<std::string>(g, "type", "none", file, "gripper.");
    if (type != "none" && type != "sticky" && type != "jaws")
      throw ConfigError(file, "gripper.type", "expected none, sticky or jaws, found '" + type + "'");
    for (const char* key : {"link", "tip_frame"})
      if (g[key] && !d.findLink(get<std::string>(g, key, "", file, "gripper.")))
        throw ConfigError(file, std::string("gripper.") + key, "no such link in " + d.urdf_path);
    if (g["elevation_joint"] && !d.findJoint(get<std::string>(g, "elevation_joint", "", file, "gripper.")))
      throw ConfigError(file, "gripper.elevation_joint", "no such joint in " + d.urdf_path);
    for (const auto& j : get<std::vector<std::string>>(g, "jaw_joints", {}, file, "gripper."))
      if (!d.findJoint(j)) throw ConfigError(file, "gripper.jaw_joints", "no joint '" + j + "' in " + d.urdf_path);
  }
  if (const YAML::Node arm = root["side_arm"]) checkSideArm(arm, d, file);
  // Everything else that is a scalar is kept as text for the modules that need it.
  if (const YAML::Node e = root["extra"]) {
    checkExtra(e, file);
    for (const auto& kv : e) {
      if (kv.second.IsScalar()) d.extra[kv.first.as<std::string>()] = kv.second.as<std::string>();
    }
    d.solver_iterations = get<int>(e, "solver_iterations", 0, file, "extra.");
  }
  d.sidecar = root;
}

}  // namespace

const std::set<std::string>& robotMaterials() {
  static const std::set<std::string> m{"chassis", "track", "caster", "stickable", "sticky", "body"};
  return m;
}

const LinkDescription* RobotDescription::findLink(const std::string& name) const {
  for (const auto& l : links)
    if (l.name == name) return &l;
  return nullptr;
}

const JointDescription* RobotDescription::findJoint(const std::string& name) const {
  for (const auto& j : joints)
    if (j.name == name) return &j;
  return nullptr;
}

double RobotDescription::totalMass() const {
  double m = 0;
  for (const auto& l : links) m += l.mass;
  return m;
}

double RobotDescription::wheelRadius(const std::string& joint) const {
  auto it = treels.wheel_radii.find(joint);
  return it == treels.wheel_radii.end() ? treels.wheel_radius : it->second;
}

std::string RobotDescription::extraOr(const std::string& key, const std::string& fallback) const {
  auto it = extra.find(key);
  return it == extra.end() ? fallback : it->second;
}

double sidecarNumber(const RobotDescription& d, const char* entry, const char* key, double fallback) {
  const YAML::Node e = d.sidecar[entry];
  if (!e || !e.IsMap() || !e[key]) return fallback;
  double v;
  try {
    v = e[key].as<double>();
  } catch (const YAML::Exception&) {
    throw ConfigError(d.sidecar_path, std::string(entry) + "." + key, "expected a number");
  }
  if (!std::isfinite(v)) throw ConfigError(d.sidecar_path, std::string(entry) + "." + key, "must be finite");
  return v;
}

RobotDescription loadRobotDescription(const std::string& urdf_path, const std::string& sidecar_path) {
  RobotDescription d;
  d.urdf_path = urdf_path;
  d.sidecar_path = sidecar_path;
  d.urdf_xml = readInputFile(urdf_path);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(d.urdf_xml);
  if (!model) throw ConfigError(urdf_path, "", "not a valid URDF (urdfdom's message is printed above)");
  if (!model->getRoot()) throw ConfigError(urdf_path, "", "URDF has no root link");
  d.root_link = model->getRoot()->name;
  if (d.root_link != "base_link")
    throw ConfigError(urdf_path, "root link", "expected 'base_link', found '" + d.root_link + "'");

  // Breadth-first: parents before children, so bodies can be built in one pass.
  std::vector<urdf::LinkConstSharedPtr> queue{model->getRoot()};
  for (std::size_t i = 0; i < queue.size(); ++i) {
    const auto& link = queue[i];
    d.links.push_back(convertLink(*link, d.urdf_xml, urdf_path));
    if (i > 0) d.joints.push_back(convertJoint(*link->parent_joint, urdf_path));
    for (const auto& child : link->child_links) queue.push_back(child);
  }
  parseSidecar(d);
  return d;
}

std::string descriptionDirectory() {
  if (const char* env = std::getenv("SBOT_DESCRIPTION_DIR")) {
    if (*env) return env;
  }
  return SBOT_DESCRIPTION_SOURCE_DIR;
}

const std::vector<std::string>& modelLevels() {
  static const std::vector<std::string> levels{"fast", "simple", "basic", "medium", "detailed"};
  return levels;
}

namespace {
constexpr double kGravityTolerance = 0.01;  // relative
}

bool scaledForItsGravity(const RobotDescription& d) {
  constexpr double kEarth = 9.81;  // [m/s^2]
  return std::abs(d.gravity - kEarth) > kGravityTolerance * kEarth;
}

std::string gravityProblem(const RobotDescription& d, double world_gravity) {
  if (!scaledForItsGravity(d) || std::abs(world_gravity - d.gravity) <= kGravityTolerance * d.gravity) return "";
  std::ostringstream msg;
  msg << "level " << d.level << " is scaled for a gravity of " << d.gravity << " m/s^2 (" << d.sidecar_path
      << "), this world has " << world_gravity << " m/s^2: set the world's gravity to " << d.gravity
      << " (and its step to " << d.recommended_step << " s) and give it no full-size robots";
  return msg.str();
}

const RobotDescription& loadLevel(const std::string& level) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<RobotDescription>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(level);
  if (it != cache.end()) return *it->second;
  bool known = false;
  for (const auto& l : modelLevels()) known |= (l == level);
  if (!known) {
    throw UnknownName("unknown model level '" + level + "' (levels: fast, simple, basic, medium, detailed)");
  }
  const std::string dir = descriptionDirectory() + "/urdf/";
  auto d = std::make_unique<RobotDescription>(
      loadRobotDescription(dir + level + ".urdf", dir + level + ".sbot.yaml"));
  // The level names the robot in messages, topics and model switches: a copied sidecar that kept
  // another level's name made a Simple robot report itself as Medium.
  if (d->level != level)
    throw ConfigError(d->sidecar_path, "level", "says '" + d->level + "' in the sidecar of level '" + level + "'");
  return *cache.emplace(level, std::move(d)).first->second;
}

}  // namespace sbot
