// Light sensors (seed 2.2.8, 2.4.2, Tables 2.10/2.14, sbot.h getLightSensor): inverse-square point
// lamps in mcd, 0.1685 mcd/cm^2 per unit, saturation at 700, cosine angular sensitivity, shadowing,
// ambient light, and the lit (blinking) LEDs of other robots.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "sbot_sim/core/sensors/light.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

constexpr double kUnit = 0.1685;  // Table 2.10 [mcd/cm^2]

// Expected noise-free, unshadowed reading of `sensor` for a lamp (no ambient).
double expectedReading(const Pose& sensor, const Vec3& lamp, double intensity) {
  const Vec3 v = lamp - sensor.position;
  const double c = (sensor.orientation * Vec3::UnitX()).dot(v.normalized());
  const double d_cm = v.norm() * 100;
  return std::min(700.0, std::max(0.0, c) * intensity / (d_cm * d_cm) / kUnit);
}

TEST(LightModel, InverseSquareInMcdPerSquareCentimetre) {
  // 1000 mcd at 1 m = 100 cm: 0.1 mcd/cm^2; at 50 cm four times that; 60 deg off axis half.
  EXPECT_NEAR(pointIlluminance(1000, 1.0, 1.0), 0.1, 1e-12);
  EXPECT_NEAR(pointIlluminance(1000, 0.5, 1.0), 0.4, 1e-12);
  EXPECT_NEAR(pointIlluminance(1000, 1.0, 0.5), 0.05, 1e-12);
  EXPECT_EQ(pointIlluminance(1000, 1.0, -0.2), 0.0);
  EXPECT_EQ(lightAngularSensitivity(std::cos(100 * M_PI / 180)), 0.0);
}

struct LampScene {
  std::unique_ptr<World> world;
  std::unique_ptr<Environment> env;
  Robot* robot = nullptr;
  Pose sensor;  // light_2 (left)
  Vec3 lamp;
};

// A Medium s-bot at the origin and a lamp 50 cm from its left light sensor (light_2), 10 cm higher.
LampScene lampScene(double intensity, const std::vector<BoxObstacle>& boxes = {}) {
  LampScene s;
  const Pose2D at{0, 0, 0};
  s.sensor = spawnPose("medium", at, "light_2");
  s.lamp = s.sensor.position + Vec3(0, 0.5, 0.1);
  WorldConfig c = flatWorld();
  c.terrain.boxes = boxes;
  s.world = std::make_unique<World>(c);
  s.robot = &s.world->addRobotAt(loadLevel("medium"), spawnPose("medium", at, "base_link"), "sbot_0");
  s.env = std::make_unique<Environment>(*s.world);
  s.env->addLamp(s.lamp, intensity);
  return s;
}

TEST(LightSensors, LampReadingFollowsTheUnitsOfTable210) {
  // Intensity giving 300 units on axis at 50 cm: 300 x 0.1685 x 50^2 mcd (a ~126 cd lamp).
  const double intensity = 300 * kUnit * 0.5 * 0.5 * 1e4;
  LampScene s = lampScene(intensity);
  LightSensors light(*s.world, *s.robot, *s.env);
  const auto v = light.readAll();
  const double expect2 = expectedReading(s.sensor, s.lamp, intensity);
  EXPECT_NEAR(expect2, 300 * 0.5 * 0.5 / (0.5 * 0.5 + 0.1 * 0.1) * std::cos(std::atan(0.2)), 1e-6);
  EXPECT_NEAR(v[2], expect2, 1.0);
  // 45 deg either side: the cosine lobe (and a slightly longer distance).
  for (int i : {1, 3}) {
    const Pose p = s.robot->linkPose("light_" + std::to_string(i));
    EXPECT_NEAR(v[i], expectedReading(p, s.lamp, intensity), 1.0) << i;
    EXPECT_LT(v[i], 0.8 * v[2]);
    EXPECT_GT(v[i], 0.6 * v[2]);
  }
  // Sensors facing away read 0.
  for (int i : {5, 6, 7}) EXPECT_EQ(v[i], 0u) << i;
  // Run-time lamp control (VortexWorld setLampIntensity / getLampIntensity).
  s.env->setLampIntensity(0, intensity / 3);
  EXPECT_DOUBLE_EQ(s.env->getLampIntensity(0), intensity / 3);
  EXPECT_NEAR(light.read(2), expect2 / 3, 1.0);
  s.env->setLampIntensity(0, 0);
  EXPECT_EQ(light.read(2), 0u);
}

TEST(LightSensors, SaturateAt700) {
  LampScene s = lampScene(10 * 300 * kUnit * 0.5 * 0.5 * 1e4);
  LightSensors light(*s.world, *s.robot, *s.env);
  EXPECT_EQ(light.read(2), 700u);
  EXPECT_GT(light.illuminance(2), 700 * kUnit * 3) << "well over-saturated, yet 700";
}

TEST(LightSensors, AmbientLightIsAddedEverywhere) {
  LampScene s = lampScene(0);
  LightSensors light(*s.world, *s.robot, *s.env);
  for (unsigned v : light.readAll()) EXPECT_EQ(v, 0u);
  s.env->setAmbientLight(100 * kUnit);
  EXPECT_DOUBLE_EQ(s.env->getAmbientLight(), 100 * kUnit);
  for (unsigned v : light.readAll()) EXPECT_EQ(v, 100u);
  EXPECT_THROW(s.env->setAmbientLight(-1), std::invalid_argument);
}

TEST(LightSensors, ABodyOnTheLineOfSightCastsAShadow) {
  const double intensity = 300 * kUnit * 0.5 * 0.5 * 1e4;
  const Pose sensor = spawnPose("medium", {0, 0, 0}, "light_2");
  BoxObstacle screen;
  screen.name = "screen";
  screen.center = sensor.position + Vec3(0, 0.25, 0.05);
  screen.size = Vec3(0.02, 0.01, 0.1);
  LampScene s = lampScene(intensity, {screen});
  LightSensors light(*s.world, *s.robot, *s.env);
  s.env->setAmbientLight(10 * kUnit);
  EXPECT_EQ(light.read(2), 10u) << "only the ambient light reaches it";
  // The neighbours 45 deg away look past the 2 cm wide screen.
  EXPECT_GT(light.read(1), 100u);
  EXPECT_GT(light.read(3), 100u);
}

TEST(LightSensors, TheOwnGripperShadowsTheFrontSensorUnlessDisabled) {
  const Pose2D at{0, 0, 0};
  const Pose front = spawnPose("medium", at, "light_0");
  World w(flatWorld());
  Robot& r = w.addRobotAt(loadLevel("medium"), spawnPose("medium", at, "base_link"), "sbot_0");
  Environment env(w);
  env.addLamp(front.position + Vec3(0.5, 0, 0.05), 1e5);
  LightSensors light(w, r, env);
  EXPECT_EQ(light.read(0), 0u);
  light.params().self_shadowing = false;
  EXPECT_NEAR(light.read(0), expectedReading(front, front.position + Vec3(0.5, 0, 0.05), 1e5), 1.0);
  EXPECT_GT(light.read(0), 50u);
}

TEST(LightSensors, LitLedsOfOtherRobotsCountOwnDoNot) {
  // Robot b 15 cm to the left of a (rings 3.6 cm apart), showing it its LED group 4 (rear);
  // a's light_2 looks at b.
  World w(flatWorld());
  Robot& a = w.addRobot(loadLevel("medium"), {0, 0, 0}, "a");
  Robot& b = w.addRobot(loadLevel("medium"), {0, 0.15, M_PI / 2}, "b");
  runFor(w, 0.3);
  Environment env(w);
  LightSensors light(w, a, env);
  // Own LEDs are not seen.
  env.setSameLightColor("a", 15, 15, 15, BLINKING_RATE_NO_BLINK);
  for (unsigned v : light.readAll()) EXPECT_EQ(v, 0u);
  // b's rear LED group (light_4 faces -x of b = -y world = toward a) at full white: 36 mcd.
  env.setLightColor("b", 4, 15, 15, 15, BLINKING_RATE_1);
  const Pose s = a.linkPose("light_2");
  const Vec3 led = b.linkPose("light_4").position;
  const double expected = expectedReading(s, led, 0.8 * 45);
  ASSERT_GT(expected, 5.0) << "test geometry: the LED must be bright enough to read";
  EXPECT_NEAR(light.illuminance(2) / kUnit, expected, 0.01);
  EXPECT_NEAR(light.read(2), expected, 1.0);
  // Blinking at 1 Hz: lit during the first half second after being set, dark in the second.
  runFor(w, 0.6);
  EXPECT_EQ(light.read(2), 0u);
  runFor(w, 0.5);
  EXPECT_GT(light.read(2), 5u);
  // An LED on the far side of b (light_0, facing +y world, away from a) is hidden by b's turret.
  env.setSameLightColor("b", 0, 0, 0, BLINKING_RATE_NO_BLINK);
  env.setLightColor("b", 0, 15, 15, 15, BLINKING_RATE_NO_BLINK);
  EXPECT_EQ(light.read(2), 0u);
}

TEST(LightSensors, EffectsSeeTheIlluminance) {
  struct Gain : Effect {
    std::string name() const override { return "gain"; }
    void onSensor(const Robot&, SensorSample& s) override {
      if (s.channel != "light") return;
      seen = s.value;
      s.value *= 0.5;
    }
    double seen = -1;
  };
  LampScene s = lampScene(300 * kUnit * 0.5 * 0.5 * 1e4);
  auto gain = std::make_shared<Gain>();
  s.world->addEffect(gain);
  LightSensors light(*s.world, *s.robot, *s.env);
  const unsigned v = light.read(2);
  EXPECT_NEAR(gain->seen, light.illuminance(2), 1e-9);
  EXPECT_NEAR(v, expectedReading(s.sensor, s.lamp, 300 * kUnit * 0.5 * 0.5 * 1e4) / 2, 1.0);
}

}  // namespace
}  // namespace sbot::test
