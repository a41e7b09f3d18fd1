// Environment (lamps, ambient, light rings with the sbot.h blinking codes, speakers, climate) and
// the temperature / humidity sensors (seed 2.2.11: humidity lags ~4 s).
#include <gtest/gtest.h>

#include <cmath>

#include "sbot_sim/core/sensors/climate.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

TEST(Blinking, PeriodsOfTheSbotHCodes) {
  const double expected[] = {0, 0.1, 0.2, 0.3, 0.4, 0.5, 1, 2, 3, 4, 5};
  for (unsigned code = 0; code <= 10; ++code) EXPECT_DOUBLE_EQ(blinkPeriod(code), expected[code]) << code;
  EXPECT_DOUBLE_EQ(1 / blinkPeriod(BLINKING_RATE_10), 10.0);
  EXPECT_DOUBLE_EQ(1 / blinkPeriod(BLINKING_RATE_0_25), 0.25);
  EXPECT_THROW(blinkPeriod(11), std::out_of_range);
}

TEST(Blinking, HalfPeriodOnHalfOffFromWhenItWasSet) {
  for (unsigned code = 1; code <= 10; ++code) {
    LedRing ring;
    ring.groups[3] = LedGroup{0, 9, 0, code, 2.0};
    const double T = blinkPeriod(code);
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(ring.isLit(3, 2.0 + k * T)) << code;
      EXPECT_TRUE(ring.isLit(3, 2.0 + (k + 0.45) * T)) << code;
      EXPECT_FALSE(ring.isLit(3, 2.0 + (k + 0.55) * T)) << code;
      EXPECT_FALSE(ring.isLit(3, 2.0 + (k + 0.95) * T)) << code;
    }
    EXPECT_FALSE(ring.isLit(2, 2.0)) << "other groups are dark";
  }
  // 10 Hz (hardware maximum; the seed's simulator stopped at 5 Hz): 50 ms on, 50 ms off.
  LedRing ring;
  ring.groups[0] = LedGroup{15, 0, 0, BLINKING_RATE_10, 0.0};
  EXPECT_TRUE(ring.isLit(0, 0.00));
  EXPECT_TRUE(ring.isLit(0, 0.04));
  EXPECT_FALSE(ring.isLit(0, 0.05));
  EXPECT_FALSE(ring.isLit(0, 0.09));
  EXPECT_TRUE(ring.isLit(0, 0.10));
  // Steady and black.
  ring.groups[1] = LedGroup{1, 0, 0, BLINKING_RATE_NO_BLINK, 0.0};
  ring.groups[2] = LedGroup{0, 0, 0, BLINKING_RATE_1, 0.0};
  for (double t : {0.0, 0.3, 0.7, 123.4}) {
    EXPECT_TRUE(ring.isLit(1, t));
    EXPECT_FALSE(ring.isLit(2, t));
  }
  EXPECT_THROW(ring.isLit(8, 0), std::out_of_range);
}

TEST(Environment, LightRingApiWithTheWorldClock) {
  World w(flatWorld());
  Environment env(w);
  runFor(w, 0.3);
  env.setLightColor("r1", 5, 20, 7, 0, BLINKING_RATE_1);  // 20 clamps to 15
  const LedGroup& g = env.ledRing("r1").groups[5];
  EXPECT_EQ(g.r, 15u);
  EXPECT_EQ(g.g, 7u);
  EXPECT_NEAR(g.since, 0.3, 1e-9);
  EXPECT_TRUE(env.isLit("r1", 5, w.time()));
  runFor(w, 0.6);  // 0.6 s into a 1 s period
  EXPECT_FALSE(env.isLit("r1", 5, w.time()));
  runFor(w, 0.5);
  EXPECT_TRUE(env.isLit("r1", 5, w.time()));
  EXPECT_THROW(env.setLightColor("r1", 8, 1, 1, 1, 0), std::out_of_range);
  EXPECT_THROW(env.setSameLightColor("r1", 1, 1, 1, 42), std::out_of_range);
  EXPECT_EQ(env.ledRing("r1").groups[0].r, 0u) << "a rejected call changes nothing";
  env.setSameLightColor("r1", 1, 2, 3, BLINKING_RATE_NO_BLINK);
  for (const LedGroup& led : env.ledRing("r1").groups) EXPECT_EQ(led.b, 3u);
  std::array<unsigned, 8> r{}, gg{}, b{}, blink{};
  r[7] = 15;
  blink[7] = BLINKING_RATE_5;
  env.setAllLightColor("r1", r, gg, b, blink);
  EXPECT_FALSE(env.ledRing("r1").groups[0].on());
  EXPECT_EQ(env.ledRing("r1").groups[7].blink, unsigned(BLINKING_RATE_5));
  EXPECT_FALSE(env.ledRing("unknown robot").anyOn());
  env.forgetRobot("r1");
  EXPECT_FALSE(env.ledRing("r1").anyOn());
}

TEST(Environment, LampsAmbientAndSpeakers) {
  World w(flatWorld());
  Environment env(w);
  EXPECT_EQ(env.addLamp(Vec3(1, 2, 3), 5000), 0);
  EXPECT_EQ(env.addLamp(Vec3(0, 0, 1), 0, Vec3(1, 0, 0)), 1);
  env.setLampIntensity(1, 750.5);
  EXPECT_DOUBLE_EQ(env.getLampIntensity(0), 5000);
  EXPECT_DOUBLE_EQ(env.getLampIntensity(1), 750.5);
  EXPECT_THROW(env.setLampIntensity(2, 1), std::out_of_range);
  EXPECT_THROW(env.getLampIntensity(-1), std::out_of_range);
  EXPECT_THROW(env.setLampIntensity(0, -1), std::invalid_argument);
  // Light sensors cast rays towards every lamp: one beyond the simulated space is refused.
  EXPECT_THROW(env.addLamp(Vec3(1e300, 0, 1), 10), std::invalid_argument);
  EXPECT_THROW(env.setLampPosition(0, Vec3(0, 0, std::nan(""))), std::invalid_argument);
  env.setAmbientLight(3.5);
  EXPECT_DOUBLE_EQ(env.getAmbientLight(), 3.5);
  EXPECT_FALSE(env.speaker("s").on);
  env.setSpeaker("s", 440, 0.8);
  EXPECT_TRUE(env.speaker("s").on);
  EXPECT_DOUBLE_EQ(env.speaker("s").frequency, 440);
  env.stopSpeaker("s");
  EXPECT_FALSE(env.speaker("s").on);
  EXPECT_THROW(env.setSpeaker("s", 0, 1), std::invalid_argument);
  EXPECT_THROW(env.setSpeaker("s", 100, -1), std::invalid_argument);
}

TEST(Climate, TemperatureIsImmediateAndClamped) {
  World w(flatWorld());
  Environment env(w);
  ClimateSensors c(env);
  float t = 0, h = 0;
  c.getTemperatureAndHumidityLeft(&t, &h);
  EXPECT_FLOAT_EQ(t, 22.0f);
  EXPECT_FLOAT_EQ(h, 45.0f);
  env.setTemperature(31.5);
  c.getTemperatureAndHumidityRight(&t, nullptr);
  EXPECT_FLOAT_EQ(t, 31.5f);
  env.setTemperature(200);
  c.getTemperatureAndHumidityRight(&t, nullptr);
  EXPECT_FLOAT_EQ(t, 123.0f);
  env.setTemperature(-60);
  c.getTemperatureAndHumidityLeft(&t, nullptr);
  EXPECT_FLOAT_EQ(t, -40.0f);
}

TEST(Climate, HumidityFollowsAFirstOrderLagOfFourSeconds) {
  World w(flatWorld());
  Environment env(w);
  ClimateSensors polled(env), lazy(env);
  runFor(w, 1.0);
  env.setHumidity(85);  // step 45 -> 85 at t = 1 s
  // `polled` is read every step, `lazy` only at the end: the exact lag makes them agree.
  while (w.time() < 5.0 - 1e-9) {
    w.step();
    polled.left().humidity();
  }
  const double expected = 85 - 40 * std::exp(-4.0 / 4.0);  // 63 % of the step after tau = 4 s
  EXPECT_NEAR(polled.left().humidity(), expected, 1e-6);
  EXPECT_NEAR(lazy.left().humidity(), expected, 1e-6);
  EXPECT_NEAR(lazy.right().humidity(), expected, 1e-6);
  // A second change at t = 5 s to 25 %: read at t = 7 s.
  env.setHumidity(25);
  runFor(w, 2.0);
  const double expected2 = 25 + (expected - 25) * std::exp(-2.0 / 4.0);
  EXPECT_NEAR(lazy.left().humidity(), expected2, 1e-6);
  float hum = 0;
  polled.getTemperatureAndHumidityRight(nullptr, &hum);
  EXPECT_NEAR(hum, expected2, 1e-4);
  // A sensor created now starts settled at the world value.
  ClimateSensors fresh(env);
  EXPECT_NEAR(fresh.left().humidity(), 25, 1e-9);
  // Values are clamped to [0, 100].
  env.setHumidity(140);
  EXPECT_DOUBLE_EQ(env.humidity(), 100);
}

}  // namespace
}  // namespace sbot::test
