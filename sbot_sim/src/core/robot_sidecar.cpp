// The robot description's sidecar (<level>.yaml beside the URDF: sbot_description/README.md),
// read section by section: level, treels, turret, materials, gripper, side arm and extra, each
// checked as it is read, with a ConfigError naming the file and the field.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world_config.h"
#include "sbot_sim/core/yaml_checks.h"
#include "description_checks.h"

namespace sbot {
namespace {

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


/// The sidecar's YAML, a mapping (refused: a file that is missing, not YAML, or too deeply nested).
YAML::Node loadSidecar(const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(readInputFile(file, "sidecar file"));
  } catch (const YAML::Exception& e) {
    throw ConfigError(file, "", std::string("not valid YAML: ") + e.what());
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty()) throw ConfigError(file, "", problem);
  if (!root.IsMap()) throw ConfigError(file, "", "expected a mapping at the top level");
  return root;
}

/// The sections and their fields: unknown names are refused, and the numbers no later check reads
/// here are checked finite.
void checkSectionFields(const YAML::Node& root, const std::string& file) {
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
}

/// The grippers' and the side arm's numbers: positive where they must be, and ranges ordered.
void checkGripperNumbers(const YAML::Node& root, const std::string& file) {
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
}

/// level, recommended_step and gravity.
void parseLevel(const YAML::Node& root, RobotDescription& d, const std::string& file) {
  d.level = get<std::string>(root, "level", "", file, "");
  if (d.level.empty()) throw ConfigError(file, "level", "missing");
  d.recommended_step = get<double>(root, "recommended_step", 0.01, file, "");
  d.gravity = get<double>(root, "gravity", 9.81, file, "");
}

/// treels: the fields as written (checked by checkTreels).
void readTreels(const YAML::Node& t, RobotDescription& d, const std::string& file) {
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
}

// Every number below divides, scales or limits a motor: NaN, 0 or a sign error would silently
// give a robot that cannot drive or one that explodes.
void requireNonNegative(double v, const std::string& file, const std::string& field) {
  if (!(std::isfinite(v) && v >= 0)) throw ConfigError(file, field, "must be a finite number >= 0");
}

/// recommended_step and gravity in their ranges.
void checkLevel(const RobotDescription& d, const std::string& file) {
  if (!(d.recommended_step >= kMinStep && d.recommended_step <= kMaxStep)) {
    std::ostringstream why;
    why << "expected a step in [" << kMinStep << ", " << kMaxStep << "] s (as a scenario's world.step), found "
        << d.recommended_step;
    throw ConfigError(file, "recommended_step", why.str());
  }
  requireNonNegative(d.gravity, file, "gravity");
  requireAtMost(d.gravity, kMaxGravity, file, "gravity", "m/s^2");
}

/// treels: motors' numbers, the friction law, the drive and the driven joints.
void checkTreels(const YAML::Node& t, RobotDescription& d, const std::string& file) {
  auto& tr = d.treels;
  requirePositive(tr.max_torque, file, "treels.max_torque");
  requirePositive(tr.torque_unit, file, "treels.torque_unit");
  requirePositive(tr.speed_unit, file, "treels.speed_unit");
  requirePositive(tr.speed_limit_units, file, "treels.speed_limit_units");
  requirePositive(tr.gear_ratio, file, "treels.gear_ratio");
  for (const auto& r : tr.wheel_radii) requirePositive(r.second, file, "treels.wheel_radii." + r.first);
  requireNonNegative(tr.rotor_inertia, file, "treels.rotor_inertia");
  requireNonNegative(tr.backdrive_force, file, "treels.backdrive_force");
  requireNonNegative(tr.torque_window, file, "treels.torque_window");
  // A buffer of torque_window / step samples per robot: 1e7 s took a node past 24 GB.
  if (tr.torque_window > kMaxTorqueWindow)
    throw ConfigError(file, "treels.torque_window", "must be <= " + std::to_string(static_cast<int>(kMaxTorqueWindow)) +
                                                        " s (getTrackTorque's averaging window)");
  requireNonNegative(tr.creep_stiffness, file, "treels.creep_stiffness");
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
}

/// turret: its joint (one of the URDF's, moving, not a track's) and the servo's numbers.
void parseTurret(const YAML::Node& root, RobotDescription& d, const std::string& file) {
  const auto& tr = d.treels;
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
}

/// materials: link -> one of robotMaterials().
void parseMaterials(const YAML::Node& root, RobotDescription& d, const std::string& file) {
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
}

/// gripper: its type, and links and joints that are the URDF's.
void checkGripper(const YAML::Node& root, const RobotDescription& d, const std::string& file) {
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
}

/// extra: checked (checkExtra); its scalars kept as text for the modules.
void parseExtra(const YAML::Node& root, RobotDescription& d, const std::string& file) {
  // Everything else that is a scalar is kept as text for the modules that need it.
  if (const YAML::Node e = root["extra"]) {
    checkExtra(e, file);
    for (const auto& kv : e) {
      if (kv.second.IsScalar()) d.extra[kv.first.as<std::string>()] = kv.second.as<std::string>();
    }
    d.solver_iterations = get<int>(e, "solver_iterations", 0, file, "extra.");
  }
}

}  // namespace

void parseSidecar(RobotDescription& d) {
  const std::string& file = d.sidecar_path;
  YAML::Node root = loadSidecar(file);
  checkSectionFields(root, file);
  checkGripperNumbers(root, file);
  parseLevel(root, d, file);
  const YAML::Node t = root["treels"];
  if (!t) throw ConfigError(file, "treels", "missing");
  readTreels(t, d, file);
  checkLevel(d, file);
  checkTreels(t, d, file);
  parseTurret(root, d, file);
  parseMaterials(root, d, file);
  checkGripper(root, d, file);
  if (const YAML::Node arm = root["side_arm"]) checkSideArm(arm, d, file);
  parseExtra(root, d, file);
  d.sidecar = root;
}

}  // namespace sbot
