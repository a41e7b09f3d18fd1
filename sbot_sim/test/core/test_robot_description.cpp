// Loading a level's URDF and sidecar (robot_description.h): the real files load; a copy with one
// value broken is refused with a ConfigError naming the file and the field, never loaded into a
// robot that is massless, shapeless or cannot drive (or that ODE aborts on: a negative radius).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/sensor_common.h"

namespace sbot {
namespace {

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A level's two files (Simple's unless named), copied into a fresh folder so that one value can be broken.
class BrokenCopy {
 public:
  explicit BrokenCopy(const std::string& level = "simple") : level_(level) {
    char dir[] = "/tmp/sbot_description_XXXXXX";
    dir_ = mkdtemp(dir);
    const std::string src = descriptionDirectory() + "/urdf/" + level;
    urdf_ = read(src + ".urdf");
    sidecar_ = read(src + ".sbot.yaml");
  }
  ~BrokenCopy() {
    std::remove(urdfPath().c_str());
    std::remove(sidecarPath().c_str());
    rmdir(dir_.c_str());
  }
  std::string urdfPath() const { return dir_ + "/" + level_ + ".urdf"; }
  std::string sidecarPath() const { return dir_ + "/" + level_ + ".sbot.yaml"; }

  /// Replace the first `from` found after `anchor` in the URDF (or the sidecar).
  void breakUrdf(const std::string& anchor, const std::string& from, const std::string& to) { replace(urdf_, anchor, from, to); }
  void breakSidecar(const std::string& from, const std::string& to) { replace(sidecar_, "", from, to); }

  /// The ConfigError's message, or "" if the copy loaded.
  std::string loadError() const {
    std::ofstream(urdfPath()) << urdf_;
    std::ofstream(sidecarPath()) << sidecar_;
    try {
      loadRobotDescription(urdfPath(), sidecarPath());
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }

 private:
  static void replace(std::string& text, const std::string& anchor, const std::string& from, const std::string& to) {
    const std::size_t a = text.find(anchor);
    ASSERT_NE(a, std::string::npos) << "anchor '" << anchor << "' not in the file";
    const std::size_t i = text.find(from, a);
    ASSERT_NE(i, std::string::npos) << "'" << from << "' not in the file after '" << anchor << "'";
    text.replace(i, from.size(), to);
  }
  std::string level_, dir_, urdf_, sidecar_;
};

TEST(RobotDescription, TheUnbrokenCopyLoads) { EXPECT_EQ(BrokenCopy().loadError(), ""); }

TEST(RobotDescription, ShapesMustHaveAPositiveSize) {
  for (const std::string radius : {"-0.01", "0"}) {
    BrokenCopy c;
    c.breakUrdf("<collision>", "<sphere radius=\"0.018\"/>", "<sphere radius=\"" + radius + "\"/>");
    EXPECT_NE(c.loadError().find("simple.urdf: field 'link base_link/collision/geometry/sphere radius': must be in [0.0001, 200000] m, found " + radius),
              std::string::npos)
        << radius << ": " << c.loadError();
  }
}

// urdfdom drops an element it cannot parse (only a message on stderr): the chassis lost its
// collision sphere and its mass.
TEST(RobotDescription, AnElementUrdfdomDroppedIsAnError) {
  BrokenCopy shape;
  shape.breakUrdf("<collision>", "<sphere radius=\"0.018\"/>", "<sphere radius=\"nan\"/>");
  EXPECT_NE(shape.loadError().find("field 'link base_link': urdfdom could not parse all of it"), std::string::npos)
      << shape.loadError();
  BrokenCopy mass;
  mass.breakUrdf("<link name=\"base_link\">", "<mass value=\"0.25\"/>", "<mass value=\"heavy\"/>");
  EXPECT_NE(mass.loadError().find("field 'link base_link': urdfdom could not parse all of it"), std::string::npos)
      << mass.loadError();
}

TEST(RobotDescription, MotorNumbersMustBeFiniteAndPositive) {
  const std::pair<std::string, std::string> cases[] = {
      {"  max_torque: 0.21971", "treels.max_torque"},
      {"  speed_unit: 0.0028", "treels.speed_unit"},
      {"  gear_ratio: 150", "treels.gear_ratio"},
      {"  wheel_radius: 0.022", "treels.wheel_radius"},
      {"  friction_scale: 2", "treels.friction_scale"},
      {"  friction_force_limit: 1.2", "treels.friction_force_limit"},
  };
  for (const auto& [line, field] : cases) {
    for (const std::string bad : {".nan", "0", "-1"}) {
      BrokenCopy c;
      c.breakSidecar(line, line.substr(0, line.find(':') + 2) + bad);
      EXPECT_NE(c.loadError().find("simple.sbot.yaml: field '" + field + "': must be a finite number > 0"), std::string::npos)
          << line << " -> " << bad << ": " << c.loadError();
    }
  }
  // The level's step: a world's range (a 5 s "step" ran no step at all, or one of 245 m falls).
  for (const std::string bad : {".nan", "0", "-1", "5", "1e-300"}) {
    BrokenCopy step;
    step.breakSidecar("recommended_step: 0.01", "recommended_step: " + bad);
    EXPECT_NE(step.loadError().find("field 'recommended_step': expected a step in [0.0001, 0.5] s"), std::string::npos)
        << bad << ": " << step.loadError();
  }
  BrokenCopy law;
  law.breakSidecar("friction_law: coulomb", "friction_law: sticky");
  EXPECT_NE(law.loadError().find("field 'treels.friction_law': expected 'coulomb' or 'force_limit', found 'sticky'"),
            std::string::npos)
      << law.loadError();
  BrokenCopy turret;
  turret.breakSidecar("max_torque: 1.4881352", "max_torque: .nan");
  EXPECT_NE(turret.loadError().find("field 'turret.max_torque'"), std::string::npos) << turret.loadError();
  BrokenCopy gravity;
  gravity.breakSidecar("gravity: 9.81", "gravity: -9.81");
  EXPECT_NE(gravity.loadError().find("field 'gravity': must be a finite number >= 0"), std::string::npos) << gravity.loadError();
  for (const std::string bad : {".nan", "-1"}) {
    BrokenCopy creep;
    creep.breakSidecar("creep_stiffness: 5.6", "creep_stiffness: " + bad);
    EXPECT_NE(creep.loadError().find("field 'treels.creep_stiffness': must be a finite number >= 0"), std::string::npos)
        << bad << ": " << creep.loadError();
  }
}

TEST(RobotDescription, TheTurretCannotBeADrivenWheel) {
  BrokenCopy c;
  c.breakSidecar("turret: {joint: turret_joint", "turret: {joint: left_wheel_joint");
  EXPECT_NE(c.loadError().find("field 'turret.joint': 'left_wheel_joint' is a driven treels joint"), std::string::npos)
      << c.loadError();
}

// The actuator modules' optional sidecar numbers (front gripper, side arm).
TEST(RobotDescription, ActuatorNumbersMustBeFinite) {
  RobotDescription d;
  d.sidecar_path = "x.sbot.yaml";
  d.sidecar = YAML::Load("gripper: {jaw_speed: 0.5, jaw_torque: .nan, elevation_speed: fast}");
  EXPECT_EQ(sidecarNumber(d, "gripper", "jaw_speed", 1.0), 0.5);
  EXPECT_EQ(sidecarNumber(d, "gripper", "elevation_torque", 1.0), 1.0) << "absent: the fallback";
  EXPECT_EQ(sidecarNumber(d, "side_arm", "unit", 2.0), 2.0) << "no entry: the fallback";
  for (const char* key : {"jaw_torque", "elevation_speed"}) {
    try {
      sidecarNumber(d, "gripper", key, 1.0);
      ADD_FAILURE() << key << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("x.sbot.yaml: field 'gripper." + std::string(key) + "'"), std::string::npos)
          << e.what();
    }
  }
}

// Sensor parameters in the sidecar's `extra` (kept as text, read by the sensor models).
TEST(RobotDescription, SensorExtrasMustBeFiniteAndRayCountsWhole) {
  RobotDescription d;
  d.sidecar_path = "x.sbot.yaml";
  EXPECT_EQ(sensors::extraCount(d, "ir_rays", 5, 1, 1000), 5) << "absent: the fallback";
  d.extra["ir_rays"] = "7";
  EXPECT_EQ(sensors::extraCount(d, "ir_rays", 5, 1, 1000), 7);
  for (const std::string bad : {"-3", "0", "2.5", "1e9"}) {
    d.extra["ir_rays"] = bad;
    try {
      sensors::extraCount(d, "ir_rays", 5, 1, 1000);
      ADD_FAILURE() << "ir_rays " << bad << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("x.sbot.yaml: field 'extra/ir_rays': expected a whole number in [1, 1000]"),
                std::string::npos) << e.what();
    }
  }
  d.extra["ir_noise"] = "nan";
  EXPECT_THROW(sensors::extraNumber(d, "ir_noise", 0.1), ConfigError);
}


// Sidecars that would break the node: an `extra` value a module reads late would abort it from inside
// its sensor set-up (std::terminate), others would never be read and any value pass, a window of
// 1e7 s would take the node past 24 GB, and a copied sidecar's level or material go unnoticed. Each
// is refused when the sidecar loads, naming the field and what it expects.
TEST(RobotDescription, SidecarEntriesAreCheckedWhenTheyLoad) {
  const std::pair<std::string, std::string> cases[][2] = {
      {{"ir_model: lut", "ir_model: psychic"}, {"extra.ir_model", "expected one of lut|raytrace, found 'psychic'"}},
      {{"ir_range_max_m: 0.2", "ir_range_max_m: -0.2"}, {"extra.ir_range_max_m", "expected a finite number in (0, 10]"}},
      {{"ir_rays: 5", "ir_rays: 0"}, {"extra.ir_rays", "expected a whole number in [1, 1000], found '0'"}},
      {{"ir_rays: 5", "ir_rays: 1000000000"}, {"extra.ir_rays", "expected a whole number in [1, 1000]"}},
      {{"ir_count: 15", "ir_count: 0"}, {"extra.ir_count", "expected a whole number in [1, 15]"}},
      {{"ir_noise: 0.1", "ir_noise: -1"}, {"extra.ir_noise", "expected a finite number in [0, 10]"}},
      {{"ir_fit_a: 8.44352", "ir_fit_a: .nan"}, {"extra.ir_fit_a", "found '.nan'"}},
      {{"light_sensor_max_units: 700", "light_sensor_max_units: 0"}, {"extra.light_sensor_max_units", "(0, 1e+06]"}},
      {{"dynamical_bodies: 4", "dynamical_bodies: -4"}, {"extra.dynamical_bodies", "[1, 100]"}},
      {{"  camera: fake", "  camera: x"}, {"extra.camera", "expected one of fake|raw"}},
      {{"ground_sensors: false", "ground_sensors: maybe"}, {"extra.ground_sensors", "expected true or false"}},
      {{"ir_model: lut", "ir_model: lut\n  bogus_key: 1"}, {"extra.bogus_key", "unknown field"}},
      {{"ir_range_min_m: 0.002", "ir_range_min_m: 0.5"}, {"extra.ir_range_min_m", "must be below extra.ir_range_max_m"}},
      {{"torque_window: 0.1", "torque_window: 1e7"}, {"treels.torque_window", "must be <= 10 s"}},
      {{"base_link: chassis", "base_link: unobtainium"}, {"materials.base_link", "unknown material 'unobtainium'"}},
      {{"{type: none,", "{type: claw,"}, {"gripper.type", "expected none, sticky or jaws, found 'claw'"}},
      {{"tip_frame: gripper_tip", "tip_frame: nowhere"}, {"gripper.tip_frame", "no such link"}},
      {{"level: simple", "level: simple\nwheels: 6"}, {"wheels", "unknown field"}},
  };
  for (const auto& c : cases) {
    BrokenCopy copy;
    copy.breakSidecar(c[0].first, c[0].second);
    const std::string e = copy.loadError();
    EXPECT_NE(e.find("simple.sbot.yaml: field '" + c[1].first + "': "), std::string::npos) << c[0].second << ": " << e;
    EXPECT_NE(e.find(c[1].second), std::string::npos) << c[0].second << ": " << e;
  }
}

// Descriptions that would abort the process
// inside ODE (an inertia that is not positive definite, 1e300 offsets or gravity, a NaN loop-joint
// anchor or a zero axis), or escape as std::out_of_range (a fixed turret joint) or as yaml-cpp's
// own words (a section that is no mapping, a key that is a list), or load with a typo or a
// contradiction unseen. Each is refused when it loads, naming the field.
TEST(RobotDescription, WhatODEWouldAbortOnIsRefusedWhenItLoads) {
  struct Case {
    std::string level, file, anchor, from, to, field, words;
  };
  const Case cases[] = {
      {"simple", "urdf", "<link name=\"base_link\">", "ixy=\"0\"", "ixy=\"1\"", "link base_link/inertial/inertia",
       "must be positive definite"},
      {"simple", "urdf", "<link name=\"base_link\">", "ixx=\"3.385e-05\"", "ixx=\"1e300\"",
       "link base_link/inertial/inertia", "must be at most 1000 kg m^2"},
      {"simple", "urdf", "<joint name=\"left_wheel_joint\"", "xyz=\"0 0.041 0\"", "xyz=\"1e300 0.041 0\"",
       "joint left_wheel_joint/origin xyz", "must be at most 100 m"},
      {"simple", "sidecar", "", "turret: {joint: turret_joint", "turret: {joint: caster_front_joint", "turret.joint",
       "must be revolute or continuous, found fixed"},
      {"simple", "sidecar", "", "gravity: 9.81", "gravity: 1e300", "gravity", "must be at most 1000 m/s^2"},
      {"simple", "sidecar", "", "turret: {joint: turret_joint", "turret: 5  # {joint: turret_joint", "turret",
       "expected a mapping"},
      {"simple", "sidecar", "", "  wheel_radius: 0.022", "  wheel_radius: 0.022\n  bogus_key: 5", "treels.bogus_key",
       "unknown field"},
      {"simple", "sidecar", "", "left_joints: [left_wheel_joint]", "left_joints: [right_wheel_joint]",
       "treels.left_joints/right_joints", "'right_wheel_joint' is listed twice"},
      {"simple", "sidecar", "", "wheel_radii: {}", "wheel_radii: {no_such_joint: 0.05}", "treels.wheel_radii.no_such_joint",
       "not a driven joint"},
      {"simple", "sidecar", "", "grip_point: 0.03", "grip_point: .nan", "gripper.grip_point", "must be finite"},
      {"detailed", "sidecar", "", "anchor_in_parent: [0.02, 0, 0]", "anchor_in_parent: [.nan, 0, 0]",
       "side_arm.loop_joints[0].anchor_in_parent", "must be finite"},
      {"detailed", "sidecar", "", "axis: [0, 0, 1]", "axis: [0, 0, 0]", "side_arm.loop_joints[0].axis", "zero axis"},
      {"detailed", "sidecar", "", "side_arm_cross_1a_joint,", "side_arm_cross_9_joint,", "side_arm.passive_joints[0]",
       "no joint 'side_arm_cross_9_joint'"},
      // Read by the node's gripper modules only, and wrong there without a word: a jaw that never
      // closed (its delay is aperture / speed), limits that were no range.
      {"detailed", "sidecar", "", "jaw_speed: 1", "jaw_speed: 0", "gripper.jaw_speed", "must be > 0"},
      {"detailed", "sidecar", "", "elevation_upper: 1.5707963", "elevation_upper: -2", "gripper.elevation_lower",
       "must be below gripper.elevation_upper"},
      {"detailed", "sidecar", "", "half_angle_max: 1.3962634", "half_angle_max: 0.1", "side_arm.rest_half_angle",
       "must be below side_arm.half_angle_max"},
  };
  for (const Case& c : cases) {
    BrokenCopy copy(c.level);
    if (c.file == "urdf") copy.breakUrdf(c.anchor, c.from, c.to);
    else copy.breakSidecar(c.from, c.to);
    const std::string e = copy.loadError();
    EXPECT_NE(e.find(c.level + (c.file == "urdf" ? ".urdf" : ".sbot.yaml") + ": field '" + c.field + "': "),
              std::string::npos) << c.to << ": " << e;
    EXPECT_NE(e.find(c.words), std::string::npos) << c.to << ": " << e;
  }
  BrokenCopy complex_key;
  complex_key.breakSidecar("materials: {base_link: chassis", "materials: {? [base_link]: chassis");
  EXPECT_NE(complex_key.loadError().find("is not a name"), std::string::npos) << complex_key.loadError();
}

}  // namespace
}  // namespace sbot
