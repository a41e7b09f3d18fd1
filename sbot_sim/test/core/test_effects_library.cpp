// The effects library (sbot_sim/core/effects): the registry, null values that really switch an effect
// off, and each drive effect doing what its description says in the simulator.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <cmath>

#include "sbot_sim/core/effects/drive_effects.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/errors.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

struct Outcome {
  Pose2D pose;
  double turned = 0;         ///< integrated yaw change [rad]
  double torque_left = 0;    ///< mean API torque units over the last second
  double encoder_left = 0;   ///< track speed [m/s] as the encoders read it (Robot::encoderSpeed)
  double api_left = 0;       ///< getSpeed's left reading [API units]
  std::vector<double> x;     ///< x every step
};

/// One Simple (or `level`) robot from rest, commands (l, r) in API units for `seconds`.
Outcome drive(const std::vector<EffectConfig>& effects, int l, int r, double seconds,
              const std::string& level = "simple", std::uint64_t seed = 1) {
  World w(flatWorld(seed));
  for (const auto& e : makeEffects(effects)) w.addEffect(e);
  Robot& robot = w.addRobot(loadLevel(level), {0.1, -0.2, 0.3}, "sbot_0");
  runFor(w, 0.2);
  for (const auto& e : w.effects()) e->reset();
  robot.setSpeed(l, r);
  Outcome o;
  double last = robot.basePose().yaw();
  const int n = static_cast<int>(seconds / w.config().step + 0.5);
  int torque_n = 0;
  for (int k = 0; k < n; ++k) {
    w.step();
    const double y = robot.basePose().yaw();
    o.turned += wrapAngle(y - last);
    last = y;
    o.x.push_back(robot.basePose().position.x());
    if (k >= n - 100) {  // torque and encoder: means over the last second (single samples jitter)
      int tl, tr;
      robot.getTrackTorque(&tl, &tr);
      o.torque_left += tl;
      o.encoder_left += robot.encoderSpeed(0);
      int sl, sr;
      robot.getSpeed(&sl, &sr);
      o.api_left += sl;
      ++torque_n;
    }
  }
  o.torque_left /= std::max(1, torque_n);
  o.encoder_left /= std::max(1, torque_n);
  o.api_left /= std::max(1, torque_n);
  const Pose p = robot.basePose();
  o.pose = {p.position.x(), p.position.y(), p.yaw()};
  return o;
}

double distance(const Outcome& a) { return std::hypot(a.pose.x - 0.1, a.pose.y + 0.2); }

TEST(EffectRegistry, EveryEffectHasConsistentParameterSpecs) {
  const EffectRegistry& reg = EffectRegistry::instance();
  const auto names = reg.names();
  for (const char* required : {"speed_scale", "motor_asymmetry", "track_width", "turn_skid", "latency", "dead_band",
                               "motor_lag", "accel_limit", "torque_saturation", "rolling_resistance",
                               "track_friction_anisotropy", "battery_sag", "ir_reflectance", "ir_incidence",
                               "ir_ambient", "ir_gain_offset", "light_angular", "light_ambient"})
    EXPECT_TRUE(reg.has(required)) << required;
  for (const auto& n : names) {
    const EffectInfo& info = reg.info(n);
    EXPECT_FALSE(info.params.empty()) << n;
    EXPECT_FALSE(info.title.empty()) << n;
    EXPECT_FALSE(info.channels.empty()) << n;
    for (const auto& p : info.params) {
      EXPECT_FALSE(p.unit.empty()) << n << "." << p.name;
      EXPECT_LE(p.lower, p.null_value) << n << "." << p.name;
      EXPECT_GE(p.upper, p.null_value) << n << "." << p.name;
      EXPECT_GT(p.scale, 0) << n << "." << p.name;
    }
    EXPECT_TRUE(reg.create(n, {})->isNull()) << n << " without parameters must be off";
  }
}

TEST(EffectRegistry, BadParametersNameTheField) {
  const EffectRegistry& reg = EffectRegistry::instance();
  try {
    reg.create("speed_scale", {{"scale", 5.0}}, "my.yaml", "effects[0]");
    FAIL() << "out of bounds accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "my.yaml");
    EXPECT_EQ(e.field(), "effects[0].params.scale");
    EXPECT_NE(std::string(e.what()).find("bounds"), std::string::npos) << e.what();
  }
  EXPECT_THROW(reg.create("speed_scale", {{"radius", 1.0}}), ConfigError);
  EXPECT_THROW(reg.create("warp_drive", {}), ConfigError);
  EXPECT_THROW(reg.create("latency", {{"delay", std::nan("")}}), ConfigError);
  EXPECT_THROW(reg.info("warp_drive"), UnknownName);
}

TEST(DriveEffects, NullValuesLeaveTheSimulationBitIdentical) {
  const Outcome base = drive({}, 40, 25, 1.5);
  for (const auto& n : EffectRegistry::instance().names()) {
    const Outcome o = drive({{n, {}, {}, ""}}, 40, 25, 1.5);
    EXPECT_EQ(base.pose.x, o.pose.x) << n;
    EXPECT_EQ(base.pose.y, o.pose.y) << n;
    EXPECT_EQ(base.pose.yaw, o.pose.yaw) << n;
  }
}

TEST(DriveEffects, SpeedScaleMovesTheGroundNotTheEncoders) {
  const Outcome base = drive({}, 40, 40, 3.0);
  const Outcome fast = drive({{"speed_scale", {{"scale", 1.1}}, {}, ""}}, 40, 40, 3.0);
  EXPECT_NEAR(distance(fast) / distance(base), 1.1, 0.02);
  EXPECT_NEAR(fast.encoder_left, base.encoder_left, 0.01 * std::abs(base.encoder_left))
      << "encoders read the commanded rotation";
  // The API reading (getSpeed: controllers, the node's track_state) is that encoder, not the wheel
  // rotation the scaled motor command produces (44 units).
  EXPECT_NEAR(fast.api_left, 40, 1.0) << "getSpeed reads the encoder through the sensor-path effects";
}

TEST(DriveEffects, MotorAsymmetryCurvesAStraightCommand) {
  const Outcome left_strong = drive({{"motor_asymmetry", {{"asymmetry", 0.05}}, {}, ""}}, 40, 40, 3.0);
  const Outcome right_strong = drive({{"motor_asymmetry", {{"asymmetry", -0.05}}, {}, ""}}, 40, 40, 3.0);
  EXPECT_LT(left_strong.turned, -0.1) << "a stronger left track turns right (clockwise)";
  EXPECT_GT(right_strong.turned, 0.1);
}

// Effects do not commute; a world applies them in pipeline order, so an effects file is a set.
TEST(DriveEffects, ListingOrderDoesNotChangeTheSimulation) {
  const EffectConfig asymmetry{"motor_asymmetry", {{"asymmetry", 0.05}}, {}, ""};
  const EffectConfig width{"track_width", {{"ratio", 1.5}}, {}, ""};
  const Outcome a = drive({asymmetry, width}, 40, 40, 3.0);
  const Outcome b = drive({width, asymmetry}, 40, 40, 3.0);
  EXPECT_EQ(a.pose.x, b.pose.x);
  EXPECT_EQ(a.pose.y, b.pose.y);
  EXPECT_EQ(a.turned, b.turned);
  // The motors' asymmetry comes before the ground's turn slip, which then divides its curve.
  const Outcome alone = drive({asymmetry}, 40, 40, 3.0);
  EXPECT_NEAR(a.turned, alone.turned / 1.5, 0.1 * std::abs(alone.turned / 1.5));
}

TEST(DriveEffects, TrackWidthAndSkidSlowSpins) {
  const Outcome base = drive({}, 40, -40, 2.0);
  const Outcome wide = drive({{"track_width", {{"ratio", 1.25}}, {}, ""}}, 40, -40, 2.0);
  EXPECT_NEAR(wide.turned / base.turned, 1 / 1.25, 0.03);
  // Skid grows with the turn rate: a fast spin loses a larger fraction than a slow one.
  const std::vector<EffectConfig> skid{{"turn_skid", {{"k", 0.2}}, {}, ""}};
  const double slow = drive(skid, 20, -20, 2.0).turned / drive({}, 20, -20, 2.0).turned;
  const double fast = drive(skid, 60, -60, 2.0).turned / drive({}, 60, -60, 2.0).turned;
  EXPECT_LT(slow, 0.95);
  EXPECT_LT(fast, slow - 0.05);
}

TEST(DriveEffects, LatencyDelaysTheStart) {
  const Outcome base = drive({}, 50, 50, 1.0);
  const Outcome late = drive({{"latency", {{"delay", 0.2}}, {}, ""}}, 50, 50, 1.0);
  // 1 cm: a step command first rocks the two-wheeled Simple robot onto its rear caster and back
  // (~2 mm along x), which a smaller threshold would take for the start.
  auto firstMove = [](const Outcome& o) {
    for (std::size_t k = 0; k < o.x.size(); ++k)
      if (std::abs(o.x[k] - o.x.front()) > 0.01) return static_cast<double>(k) * 0.01;
    return 99.0;
  };
  EXPECT_NEAR(firstMove(late) - firstMove(base), 0.2, 0.03);
}

TEST(DriveEffects, DeadBandSwallowsSmallCommands) {
  const std::vector<EffectConfig> band{{"dead_band", {{"threshold", 0.03}}, {}, ""}};
  // Below the band the robot does what it does standing (quickstep's creep, until it sleeps at
  // rest); 8 units undamped would take it 4.4 cm.
  EXPECT_NEAR(distance(drive(band, 8, 8, 2.0)), distance(drive({}, 0, 0, 2.0)), 0.001)
      << "8 units = 2.2 cm/s is below a 3 cm/s dead-band";
  const double d = distance(drive(band, 50, 50, 2.0)), d0 = distance(drive({}, 50, 50, 2.0));
  EXPECT_NEAR(d0 - d, 0.03 * 2.0, 0.015) << "above it the track runs threshold slower";
}

TEST(DriveEffects, LagAndRampSlowTheAcceleration) {
  // Distance lost to the transient grows with the time constant / ramp time. (Not exactly v tau or
  // v t / 2: the nominal robot is itself slow to spin up its reflected rotor inertia, and the two
  // transients overlap: a 0.3 s lag loses 1.4 cm of v tau = 5 cm.)
  const double d0 = distance(drive({}, 60, 60, 2.5));
  auto loss = [&](const char* effect, const char* param, double v) {
    return d0 - distance(drive({{effect, {{param, v}}, {}, ""}}, 60, 60, 2.5));
  };
  const double lag1 = loss("motor_lag", "tau", 0.3), lag2 = loss("motor_lag", "tau", 0.6);
  EXPECT_GT(lag1, 0.01);
  EXPECT_LT(lag1, 60 * 0.0028 * 0.3 + 0.005);
  EXPECT_GT(lag2, lag1 + 0.6 * 60 * 0.0028 * 0.3) << "each extra 0.3 s of lag loses ~v * 0.3 s";
  const double ramp1 = loss("accel_limit", "ramp_time", 1.0), ramp2 = loss("accel_limit", "ramp_time", 2.0);
  EXPECT_GT(ramp1, 0.03);
  EXPECT_LT(ramp1, 60 * 0.0028 * (60.0 / 70.0) * 1.0 / 2 + 0.005);
  EXPECT_GT(ramp2, ramp1 + 0.6 * 60 * 0.0028 * (60.0 / 70.0) * 1.0 / 2);
}

TEST(DriveEffects, BatterySagSlowsWithBatteryTime) {
  auto sagged = [](double elapsed) {
    World w(flatWorld());
    auto sag = std::make_shared<BatterySagEffect>(std::map<std::string, double>{{"rate", 0.05}});
    w.addEffect(sag);
    Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
    runFor(w, 0.2);
    sag->reset();
    sag->setElapsed("sbot_0", elapsed);
    r.setSpeed(40, 40);
    runFor(w, 1.0);  // spun up: the start transient is shorter at the lower speed
    const Vec3 start = r.basePose().position;
    runFor(w, 2.0);
    return (r.basePose().position - start).head<2>().norm();
  };
  EXPECT_NEAR(sagged(240) / sagged(0), 0.8, 0.02) << "5 %/min for 4 min";
}

TEST(DriveEffects, TorqueEffectsShowInTheTorqueReadings) {
  const Outcome base = drive({}, 40, 40, 3.0, "medium");
  const Outcome rolling = drive({{"rolling_resistance", {{"coefficient", 0.2}}, {}, ""}}, 40, 40, 3.0, "medium");
  EXPECT_GT(rolling.torque_left, base.torque_left + 2) << "rolling resistance loads the motors";
  const Outcome spin = drive({}, 40, -40, 2.0, "medium");
  const Outcome weak = drive({{"torque_saturation", {{"scale", 0.2}}, {}, ""}}, 40, -40, 2.0, "medium");
  EXPECT_LT(std::abs(weak.turned), 0.9 * std::abs(spin.turned)) << "skid steering needs torque";
}

TEST(DriveEffects, AnisotropicTrackFrictionChangesSkidSteering) {
  // Mean over three seeds: quickstep on six wheels turns one 2 s spin by a few % more or less from
  // seed to seed, and by as much for a lateral ratio of 0.9999 (-4.08 to -4.50 rad).
  auto turned = [](double ratio) {
    std::vector<EffectConfig> effects;
    if (ratio != 1.0) effects.push_back({"track_friction_anisotropy", {{"lateral_ratio", ratio}}, {}, ""});
    double sum = 0;
    for (std::uint64_t seed : {1, 2, 3}) sum += drive(effects, 40, -40, 2.0, "medium", seed).turned;
    return sum / 3;
  };
  const double off = turned(1.0), slippery = turned(0.3), almost = turned(0.999);
  EXPECT_GT(std::abs(slippery), 1.15 * std::abs(off)) << "less lateral grip: the six-wheel model skids round more easily";
  // lateral_ratio -> 1 is continuous with the effect off (the next test: it keeps the core's pyramid).
  EXPECT_LT(std::abs(almost - off), 0.2 * std::abs(slippery - off));
}

TEST(DriveEffects, AnisotropicTrackFrictionKeepsTheCoresFrictionDirection) {
  // Along the track is the pyramid's first direction the core gives a terrain contact (the way the
  // wheels roll: the heading on a floor, up a face ahead); across it, mu x lateral_ratio. A
  // robot-robot contact has no direction from the core and takes the robot's heading.
  World w(flatWorld());
  const Robot& r = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  TrackFrictionAnisotropyEffect effect({{"lateral_ratio", 0.5}});
  ContactContext ctx;
  ctx.robot_a = &r;
  ctx.material_a = "track";
  ctx.normal = Vec3(-1, 0, 0);  // a face ahead
  ctx.heading = Vec3(0, 1, 0);  // the projected heading's sideways remnant
  ctx.fdir1 = Vec3(0, 0, 1);    // the core's: up the face
  dSurfaceParameters surface{};
  surface.mu = 0.8;
  effect.onContact(ctx, surface);
  EXPECT_EQ(ctx.fdir1, Vec3(0, 0, 1));
  EXPECT_TRUE(surface.mode & dContactMu2);
  EXPECT_NEAR(surface.mu2, 0.4, 1e-12);
  ctx.fdir1 = Vec3::Zero();
  effect.onContact(ctx, surface);
  EXPECT_EQ(ctx.fdir1, ctx.heading);
}

}  // namespace
}  // namespace sbot::test
