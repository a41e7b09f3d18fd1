// Sensor effects (effects/sensor_effects.h): defined on the reading, applied to the raw distance or
// illuminance the sensor modules pass through Effect::onSensor.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/effects/sensor_effects.h"
#include "sbot_sim/core/sensors/proximity.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

/// Reading of the proximity response for a distance (the Medium level's curve).
double reading(double distance) {
  static const sensors::LogLogResponse r =
      sensors::proximityResponse(sensors::proximityRayModel(loadLevel("medium")));
  return r.signal(distance);
}

struct Bench {
  World world{flatWorld()};
  Robot* robot = nullptr;
  Bench() { robot = &world.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0"); }
  /// Pass a sample through one effect built from `cfg`; returns the new value.
  double apply(const EffectConfig& cfg, SensorSample s) {
    const auto effects = makeEffects({cfg});
    effects[0]->onSensor(*robot, s);
    return s.value;
  }
};

// The sensor-path counterpart of DriveEffects.NullValuesLeaveTheSimulationBitIdentical: every effect
// of the library at its null value returns every kind of sample unchanged to the bit (an effect that
// maps a distance to a reading and back would not).
TEST(SensorEffects, NullValuesLeaveEveryReadingBitIdentical) {
  Bench b;
  const std::vector<SensorSample> samples{{"ir", 4, 0.03, "black_card", 0.5},
                                          {"ir", 0, 0.12, "", 0.0},
                                          {"ground", 1, 0.004, "white_paper", 0.1},
                                          {"light", 2, 150.0, "", 0.7},
                                          {kTrackSpeedChannel, 0, 0.11, "", 0.0}};
  for (const auto& name : EffectRegistry::instance().names())
    for (const SensorSample& s : samples)
      EXPECT_EQ(b.apply({name, {}, {}, ""}, s), s.value) << name << " at its null value changed a " << s.channel
                                                         << " sample";
}

TEST(SensorEffects, IrEffectsActOnTheReading) {
  Bench b;
  const double d = 0.03, r0 = reading(d);
  SensorSample s{"ir", 4, d, "black_card", 0.5};
  const double refl = b.apply({"ir_reflectance", {{"black_card", 0.3}}, {}, ""}, s);
  EXPECT_NEAR(reading(refl) / r0, 0.3, 1e-6) << "reflectance multiplies the reading";
  EXPECT_GT(refl, d) << "a darker surface looks farther away";
  SensorSample white = s;
  white.surface = "white_paper";
  EXPECT_DOUBLE_EQ(b.apply({"ir_reflectance", {{"black_card", 0.3}}, {}, ""}, white), d) << "other labels unchanged";
  EXPECT_NEAR(reading(b.apply({"ir_incidence", {{"exponent", 2.0}}, {}, ""}, s)) / r0, std::pow(std::cos(0.5), 2), 1e-6);
  EXPECT_NEAR(reading(b.apply({"ir_ambient", {{"offset", 25.0}}, {}, ""}, s)) - r0, 25.0, 1e-6);
  EXPECT_NEAR(reading(b.apply({"ir_gain_offset", {{"gain4", 1.5}, {"offset4", -10.0}}, {}, ""}, s)), 1.5 * r0 - 10, 1e-6);
  s.index = 5;
  EXPECT_DOUBLE_EQ(b.apply({"ir_gain_offset", {{"gain4", 1.5}}, {}, ""}, s), d) << "only sensor 4";
  SensorSample ground{"ground", 0, 0.002, "ground", 0};
  EXPECT_DOUBLE_EQ(b.apply({"ir_ambient", {{"offset", 25.0}}, {}, ""}, ground), 0.002) << "proximity only";
}

TEST(SensorEffects, LightEffects) {
  Bench b;
  SensorSample s{"light", 2, 40.0, "", 0.6};
  EXPECT_NEAR(b.apply({"light_angular", {{"exponent", 3.0}}, {}, ""}, s), 40.0 * std::pow(std::cos(0.6), 2), 1e-9);
  EXPECT_DOUBLE_EQ(b.apply({"light_angular", {}, {}, ""}, s), 40.0) << "exponent 1 is the module's Lambert lobe";
  EXPECT_DOUBLE_EQ(b.apply({"light_ambient", {{"offset", 3.0}}, {}, ""}, s), 43.0);
}

TEST(SensorEffects, ReflectanceChangesWhatTheProximityModuleReads) {
  // A Medium robot 3 cm from a black wall with sensor ir_2 (axis 80 deg) facing it; average many
  // noisy reads with and without the effect.
  auto meanReading = [](bool effect) {
    WorldConfig c = flatWorld();
    c.terrain.boxes.push_back({"wall", Vec3(1.01, 0, 0.05), Vec3(0.02, 1, 0.1), 0, 0, "black_card"});
    World w(c);
    if (effect) w.addEffect(makeEffects({{"ir_reflectance", {{"black_card", 0.4}}, {}, ""}})[0]);
    Robot& r = w.addRobot(loadLevel("medium"), {1.0 - 0.03 - 0.05, 0, -80 * M_PI / 180}, "sbot_0");
    sensors::Environment env(w);
    sensors::SensorSuite suite(w, r, env);
    double sum = 0;
    for (int i = 0; i < 400; ++i) sum += suite.getProximitySensor(2);
    return sum / 400;
  };
  const double plain = meanReading(false), dark = meanReading(true);
  ASSERT_GT(plain, 100) << "the sensor sees the wall";
  EXPECT_NEAR(dark / plain, 0.4, 0.04);
}

}  // namespace
}  // namespace sbot::test
