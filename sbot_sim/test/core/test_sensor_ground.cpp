// Ground IR sensors (seed 2.2.7, Table 2.9, sbot.h getGroundSensor): the response through the API
// points (6 mm -> 1, 2 mm -> 25, 1 mm -> 100), the 0.1-6 cm range, noise, and the sensors of a
// Medium s-bot over a pad placed under one of them.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "sbot_sim/core/sensors/ground.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

// A 1.5 x 1.5 cm pad standing on the floor whose top is `gap` below ground sensor `link`.
BoxObstacle padUnder(const Pose& sensor, double gap) {
  BoxObstacle b;
  b.name = "pad";
  const double top = sensor.position.z() - gap;
  b.size = Vec3(0.015, 0.015, top);
  b.center = Vec3(sensor.position.x(), sensor.position.y(), top / 2);
  b.surface = "white_paper";
  return b;
}

double bundleMean(double d) { return d * (1 + 4 / std::cos(15 * M_PI / 180)) / 5; }

TEST(GroundResponse, PassesThroughTheApiPoints) {
  const LogLogResponse r = groundResponse(IrRayModel{0.001, 0.06, 0.52359878, 5, M_PI / 4});
  EXPECT_NEAR(r.reading(0.006), 1, 1e-9);
  EXPECT_NEAR(r.reading(0.002), 25, 1e-9);
  EXPECT_NEAR(r.reading(0.001), 100, 1e-9);
  // Closer than the 1 mm minimum distance counts as 1 mm.
  EXPECT_NEAR(r.reading(0.0002), 100, 1e-9);
  // Beyond 6 mm it keeps falling (slope -2.93): 12 mm rounds to 0; beyond 6 cm nothing at all.
  EXPECT_NEAR(r.reading(0.012), 0.131, 0.001);
  EXPECT_EQ(r.reading(0.0601), 0.0);
  EXPECT_NEAR(r.reading(0.003), 25 * std::pow(1.5, std::log(1.0 / 25) / std::log(3.0)), 1e-9);
}

class GroundPad : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(GroundPad, MediumFrontSensorReadsTheApiValue) {
  const auto [gap, api] = GetParam();
  const Pose2D at{0.2, -0.1, 0.7};
  // Held 1 cm above its resting pose (teleported, not stepped): the floor is then 14 mm below the
  // sensors, out of their 6 mm range, and a pad can sit at any gap up to 6 mm.
  auto lifted = [](Pose p) {
    p.position.z() += 0.01;
    return p;
  };
  const Pose sensor = lifted(spawnPose("medium", at, "ground_0"));
  WorldConfig c = flatWorld(5);
  c.terrain.boxes.push_back(padUnder(sensor, gap));
  World w(c);
  Robot& r = w.addRobotAt(loadLevel("medium"), lifted(spawnPose("medium", at, "base_link")), "sbot_0");
  GroundSensors g(w, r);
  EXPECT_NEAR(g.rawDistance(0), bundleMean(gap), 2e-5);
  EXPECT_NEAR(g.response().reading(g.rawDistance(0)), api, 0.10 * api);
  const double lo = g.response().signal(1.1 * bundleMean(gap)), hi = g.response().signal(0.9 * bundleMean(gap));
  double sum = 0;
  const int n = 300;
  for (int i = 0; i < n; ++i) {
    const unsigned v = g.read(0);
    EXPECT_GE(v, std::floor(lo));
    EXPECT_LE(v, std::ceil(hi));
    sum += v;
  }
  EXPECT_NEAR(sum / n, api, std::max(0.5, 0.10 * api));
  // The other three see the floor 14 mm below: out of range, 0.
  const auto all = g.readAll();
  for (int i = 1; i < kGroundSensors; ++i) EXPECT_EQ(all[i], 0u) << "ground_" << i;
  EXPECT_NEAR(g.rawDistance(2), bundleMean(sensor.position.z()), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(ApiPoints, GroundPad,
                         ::testing::Values(std::pair{0.006, 1.0}, std::pair{0.002, 25.0}, std::pair{0.001, 100.0}));

TEST(GroundSensors, NothingWithinSixCentimetresReadsZeroAndSkipsEffects) {
  struct Counter : Effect {
    std::string name() const override { return "counter"; }
    void onSensor(const Robot&, SensorSample& s) override {
      ++calls;
      EXPECT_EQ(s.channel, "ground");
    }
    int calls = 0;
  };
  // A robot held 10 cm above the floor (teleported, not stepped): nothing in range.
  World w(flatWorld());
  Robot& r = w.addRobotAt(loadLevel("medium"), Pose(Vec3(0, 0, 0.12), Quat::Identity()), "sbot_0");
  auto counter = std::make_shared<Counter>();
  w.addEffect(counter);
  GroundSensors g(w, r);
  EXPECT_TRUE(std::isinf(g.rawDistance(0)));
  for (unsigned v : g.readAll()) EXPECT_EQ(v, 0u);
  EXPECT_EQ(counter->calls, 0);
  // Resting on the floor, 4 mm above it: the effects are called and every sensor sees the floor
  // (a cliff reads 0, flat ground a few units).
  World w2(flatWorld());
  Robot& r2 = w2.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  w2.addEffect(counter);
  GroundSensors g2(w2, r2);
  for (unsigned v : g2.readAll()) {
    EXPECT_GE(v, 1u);  // spawned 1 mm above the floor (not stepped): 5 mm -> about 2
    EXPECT_LE(v, 12u);
  }
  EXPECT_EQ(counter->calls, 4);
  EXPECT_THROW(g2.read(4), std::out_of_range);
}

// readAll casts the four bundles at once; its readings (noise included, drawn in the same order)
// are those of read(0..3) in an identically seeded world, here half over a cliff.
TEST(GroundSensors, ReadAllReadsWhatEachSensorReads) {
  auto readings = [](bool all_at_once) {
    WorldConfig c = flatWorld(5);
    c.terrain.type = TerrainConfig::Type::Composite;
    c.terrain.ground_plane = false;
    BoxObstacle ledge;
    ledge.name = "ledge";
    ledge.center = Vec3(-0.5, 0, -0.05);
    ledge.size = Vec3(1.0, 1.0, 0.1);  // top at z = 0 up to x = 0: the robot's front is over the edge
    c.terrain.boxes.push_back(ledge);
    World w(c);
    Robot& r = w.addRobot(loadLevel("medium"), {-0.02, 0, 0}, "sbot_0");
    GroundSensors g(w, r);
    std::vector<unsigned> out;
    for (int n = 0; n < 10; ++n) {
      if (all_at_once) {
        for (unsigned v : g.readAll()) out.push_back(v);
      } else {
        for (int i = 0; i < kGroundSensors; ++i) out.push_back(g.read(i));
      }
    }
    return out;
  };
  const std::vector<unsigned> together = readings(true), one_by_one = readings(false);
  EXPECT_EQ(together, one_by_one);
  int seen = 0, cliff = 0;
  for (unsigned v : together) (v > 0 ? seen : cliff) += 1;
  EXPECT_GT(seen, 0) << "some sensors must see the ledge";
  EXPECT_GT(cliff, 0) << "and some the cliff, for the comparison to mean anything";
}

}  // namespace
}  // namespace sbot::test
