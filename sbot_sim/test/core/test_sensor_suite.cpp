// SensorSuite: the modules each level offers (from its sidecar), the sbot.h read functions, the
// light-ring/speaker actuators, per-step battery, and reproducibility of a whole sensing run.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

std::set<std::string> channelsOf(const SensorSuite& s) {
  std::set<std::string> out;
  for (SensorChannel c : s.availableChannels()) out.insert(channelName(c));
  return out;
}

TEST(SensorSuite, EachLevelOffersWhatItsSidecarSays) {
  const std::set<std::string> common{"proximity", "slope", "sound", "fake_camera", "battery", "climate"};
  std::set<std::string> full = common;
  full.insert("ground");
  full.insert("light");
  const std::map<std::string, std::pair<std::string, std::set<std::string>>> expected{
      {"fast", {"lut", common}},
      {"simple", {"lut", common}},
      {"basic", {"raytrace", common}},
      {"medium", {"raytrace", full}},
      {"detailed", {"raytrace", full}},
  };
  for (const auto& [level, exp] : expected) {
    WorldConfig c = flatWorld();
    c.gravity = loadLevel(level).gravity;
    World w(c);
    Robot& r = w.addRobot(loadLevel(level), {0, 0, 0}, "sbot_0");
    Environment env(w);
    SensorSuite s(w, r, env);
    EXPECT_EQ(s.proximityModel(), exp.first) << level;
    EXPECT_EQ(channelsOf(s), exp.second) << level;
    // Unavailable channels read zeros.
    if (!s.available(SensorChannel::Ground)) {
      for (unsigned v : s.getAllGroundSensors()) EXPECT_EQ(v, 0u);
      EXPECT_EQ(s.getGroundSensor(3), 0u);
      EXPECT_EQ(s.ground(), nullptr);
    }
    if (!s.available(SensorChannel::Light)) {
      for (unsigned v : s.getAllLightSensors()) EXPECT_EQ(v, 0u);
    }
    EXPECT_THROW(s.getProximitySensor(15), std::out_of_range);
    EXPECT_THROW(s.getGroundSensor(4), std::out_of_range);
    EXPECT_THROW(s.getLightSensor(8), std::out_of_range);
    EXPECT_THROW(s.getSoundIntensity(3), std::out_of_range);
  }
}

TEST(SensorSuite, OptionsOverrideTheSidecar) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  Environment env(w);
  SuiteOptions o;
  o.ir_model = "raytrace";
  o.light_sensors = true;
  SensorSuite s(w, r, env, o);
  EXPECT_EQ(s.proximityModel(), "raytrace");
  EXPECT_TRUE(s.available(SensorChannel::Light));
  EXPECT_FALSE(s.available(SensorChannel::Ground));
  o.ir_model = "sonar";
  EXPECT_THROW(SensorSuite(w, r, env, o), ConfigError);
}

TEST(SensorSuite, TwoRobotsSeeEachOther) {
  World w(flatWorld(21));
  Robot& a = w.addRobot(loadLevel("medium"), {0, 0, 0}, "a");
  Robot& b = w.addRobot(loadLevel("medium"), {0, 0.16, 0}, "b");  // to the left, rings 4.6 cm apart
  runFor(w, 0.3);
  Environment env(w);
  SensorSuite sa(w, a, env), sb(w, b, env);
  // a's IR sensors pointing left (ir_4 at +100 deg, ir_3 at 80 deg) see b; the rear ones do not.
  const auto ir = sa.getAllProximitySensors();
  EXPECT_GT(std::max(ir[3], ir[4]), 30u);
  EXPECT_EQ(ir[10], 0u);
  // b lights its LEDs through its suite; a's fake camera and a's left light sensor see them.
  sb.setSameLightColor(0, 15, 0, BLINKING_RATE_NO_BLINK);
  const auto blobs = sa.getFakeCameraBlobs();
  ASSERT_FALSE(blobs.empty());
  EXPECT_EQ(blobs[0].source, "b");
  EXPECT_NEAR(blobs[0].bearing, M_PI / 2, 0.5);
  EXPECT_GT(sa.getLightSensor(2), 0u);
  EXPECT_EQ(sb.getLightSensor(2), 0u) << "b's own LEDs do not light its sensors";
  // b's speaker, heard by a's microphones, loudest at the one facing b (mic_1 at +120 deg).
  sb.setSpeaker(1500, 1.0);
  const auto tpa = sa.getAllSoundIntensities();
  EXPECT_GT(tpa[1], tpa[0] * 0.9);
  EXPECT_GT(tpa[1], 0.3);
  EXPECT_EQ(sb.getSoundIntensity(0), 0.0);
  sb.stopSpeaker();
  EXPECT_EQ(sa.getSoundIntensity(1), 0.0);
  // Slope: the inclinometer's reading of base_link, rounded.
  int pitch = 99, roll = 99;
  sa.getSlope(&pitch, &roll);
  EXPECT_EQ(pitch, std::lround(slopeOf(a.basePose().orientation).pitch));
  EXPECT_EQ(roll, std::lround(slopeOf(a.basePose().orientation).roll));
  EXPECT_LE(std::abs(pitch), 10) << "on a flat floor";
  EXPECT_TRUE(sa.imuOrientation().isApprox(a.basePose().orientation));
  // Battery: integrated by update(dt) only.
  const double soc = sa.battery().stateOfCharge();
  runFor(w, 0.1);
  EXPECT_EQ(sa.battery().stateOfCharge(), soc);
  sa.update(60.0);
  EXPECT_NEAR(soc - sa.battery().stateOfCharge(), 2.5 * 60 / BatteryParams().energy(), 1e-4);
  EXPECT_EQ(sa.getBatteryVoltage(), 213u);
  float t = 0, h = 0;
  sa.getTemperatureAndHumidityLeft(&t, &h);
  EXPECT_FLOAT_EQ(t, 22.0f);
  EXPECT_FLOAT_EQ(h, 45.0f);
}

TEST(SensorSuite, SlopeBatteryAndClimatePassThroughTheEffects) {
  struct Offsets : Effect {
    std::string name() const override { return "offsets"; }
    void onSensor(const Robot&, SensorSample& s) override {
      seen.insert(s.channel + "/" + std::to_string(s.index));
      if (s.channel == "slope" && s.index == 0) s.value += 7.0;      // inclinometer pitch offset
      if (s.channel == "battery") s.value -= 1.0;                    // meter reads 1 V low
      if (s.channel == "humidity" && s.index == 1) s.value = 150.0;  // broken right sensor
    }
    std::set<std::string> seen;
  };
  World w(flatWorld());
  Robot& r = w.addRobotAt(loadLevel("simple"), Pose(Vec3(0, 0, 0.2), Quat::Identity()), "sbot_0");
  Environment env(w);
  SensorSuite s(w, r, env);
  auto fx = std::make_shared<Offsets>();
  w.addEffect(fx);
  int pitch = 0, roll = 0;
  s.getSlope(&pitch, &roll);
  EXPECT_EQ(pitch, 7);
  EXPECT_EQ(roll, 0);
  // 8.4 V open circuit - 0.045 V at 2.5 W - 1 V = 7.355 V = 188 units.
  EXPECT_EQ(s.getBatteryVoltage(), 188u);
  float t = 0, h = 0;
  s.getTemperatureAndHumidityRight(&t, &h);
  EXPECT_FLOAT_EQ(h, 100.0f) << "clamped to the API range after the effect";
  s.getTemperatureAndHumidityLeft(&t, &h);
  EXPECT_FLOAT_EQ(h, 45.0f);
  for (const char* c : {"slope/0", "slope/1", "battery/0", "temperature/0", "temperature/1", "humidity/0",
                        "humidity/1"}) {
    EXPECT_TRUE(fx->seen.count(c)) << c;
  }
}

std::vector<unsigned> sensingRun(std::uint64_t seed) {
  World w(flatWorld(seed));
  Robot& a = w.addRobot(loadLevel("simple"), {0, 0, 0}, "a");
  // b 16 cm away at 40 deg, in front of ir_0 (straight ahead is the IR blind spot of the gripper).
  w.addRobot(loadLevel("simple"), {0.16 * std::cos(0.7), 0.16 * std::sin(0.7), 0}, "b");
  Environment env(w);
  SensorSuite s(w, a, env);
  std::vector<unsigned> out;
  a.setSpeed(10, 12);
  for (int i = 0; i < 50; ++i) {
    w.step();
    s.update(w.config().step);
    for (unsigned v : s.getAllProximitySensors()) out.push_back(v);
  }
  return out;
}

TEST(SensorSuite, SameSeedSameReadings) {
  const auto r1 = sensingRun(5), r2 = sensingRun(5), r3 = sensingRun(6);
  EXPECT_EQ(r1, r2);
  EXPECT_NE(r1, r3);
  unsigned max = 0;
  for (unsigned v : r1) max = std::max(max, v);
  EXPECT_GT(max, 50u) << "the neighbour in front must be seen";
}

}  // namespace
}  // namespace sbot::test
