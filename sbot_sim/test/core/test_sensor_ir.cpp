// IR proximity sensors (seed 2.2.6, Table 2.8, sbot.h getProximitySensor): the response through
// the API points, the ray-traced model against walls, the 10 % distance noise, the effects hook,
// seeding, and the look-up-table model of Fast/Simple (s-bots only, no walls).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "sbot_sim/core/sensors/proximity.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

// Spawn a robot exactly where it would rest on the flat floor, even if a box is close (addRobot
// would lift it onto any box within its bounding box).
Robot& spawnOnFloor(World& w, const std::string& level, const Pose2D& at, const std::string& name) {
  return w.addRobotAt(loadLevel(level), spawnPose(level, at, "base_link"), name);
}

// The sensor's axis (+x) projected on the floor, unit length: the direction walls and neighbours are
// placed along.
Vec3 floorAxis(const Pose& sensor) {
  Vec3 axis = sensor.orientation * Vec3::UnitX();
  axis.z() = 0;
  axis.normalize();
  return axis;
}

// A 2 cm thick wall whose near face is `distance` in front of `sensor`, facing it.
BoxObstacle wallFacing(const Pose& sensor, double distance, const std::string& surface = "white_paper") {
  const Vec3 axis = floorAxis(sensor);
  BoxObstacle b;
  b.name = "wall";
  b.size = Vec3(0.02, 0.40, 0.30);
  b.center = sensor.position + (distance + 0.01) * axis;
  b.center.z() = 0.15;
  b.yaw = std::atan2(axis.y(), axis.x());
  b.surface = surface;
  return b;
}

// Five rays on a 30 deg cone: the centre ray at d, four at d / cos(15 deg) on a flat wall.
double wallMean(double d) { return d * (1 + 4 / std::cos(15 * M_PI / 180)) / 5; }

// ---- response --------------------------------------------------------------------------------------

TEST(IrResponse, PassesThroughTheApiPoints) {
  const LogLogResponse r = proximityResponse();
  // sbot.h: "20 is 15 cm, 50 is 5 cm, 1000 is 1 cm, 3700 is 0.5 cm".
  EXPECT_NEAR(r.reading(0.15), 20, 1e-9);
  EXPECT_NEAR(r.reading(0.05), 50, 1e-9);
  EXPECT_NEAR(r.reading(0.01), 1000, 1e-9);
  EXPECT_NEAR(r.reading(0.005), 3700, 1e-9);
  // Between the points it is a power law: 2.5 cm lies between 1000 and 50 on the log-log line.
  EXPECT_NEAR(r.reading(0.025), 1000 * std::pow(2.5, std::log(50.0 / 1000) / std::log(5.0)), 1e-6);
  // Extrapolation: 20 cm (the range limit, Table 2.8) reads 15.7; beyond, nothing.
  EXPECT_NEAR(r.reading(0.20), 15.73, 0.01);
  EXPECT_EQ(r.reading(0.2001), 0.0);
  // Saturation at 8191 below 3.3 mm; the 2 mm minimum distance and contact read 8191.
  EXPECT_EQ(r.reading(0.003), 8191.0);
  EXPECT_EQ(r.reading(0.0), 8191.0);
  EXPECT_LT(r.reading(0.0035), 8191.0);
  // Monotone decreasing.
  for (double d = 0.0034; d < 0.19; d *= 1.05) EXPECT_GT(r.reading(d), r.reading(d * 1.05)) << d;
  // The inverse recovers distances (also beyond the range, for weak table readings).
  for (double d : {0.004, 0.0075, 0.03, 0.1, 0.19, 0.5}) EXPECT_NEAR(r.distance(r.signal(d)), d, 1e-9 * d + 1e-12);
}

TEST(IrResponse, TheSeedRegressionWouldMissTheApiPoints) {
  // Why the regression of eq. 2.5 is not used: in mm it reads 222 at 5 cm (API 50), in cm 1329.
  auto regression = [](double x) { return std::exp(8.44352 - 0.777545 * std::log(x)); };
  EXPECT_NEAR(regression(50.0), 221.8, 0.5);
  EXPECT_NEAR(regression(5.0), 1328.9, 0.5);
  const LogLogResponse r = proximityResponse();
  for (auto [d, api] : {std::pair{0.15, 20.0}, {0.05, 50.0}, {0.01, 1000.0}, {0.005, 3700.0}}) {
    EXPECT_LE(std::abs(r.reading(d) / api - 1), 0.10) << d;
    EXPECT_GT(std::abs(regression(d * 1000) / api - 1), 0.20) << d;
  }
}

// ---- ray-traced model (Basic) ----------------------------------------------------------------------

class RayTracedWall : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(RayTracedWall, ReadsTheApiValueWithinTenPercent) {
  const auto [d, api] = GetParam();
  const Pose2D at{0, 0, 0.3};
  const Pose sensor = spawnPose("basic", at, "ir_3");
  WorldConfig c = flatWorld(7);
  c.terrain.boxes.push_back(wallFacing(sensor, d));
  World w(c);
  Robot& r = spawnOnFloor(w, "basic", at, "sbot_0");
  ProximitySensors ir(w, r, ProximitySensors::Model::RayTraced);
  EXPECT_NEAR(ir.rawDistance(3), wallMean(d), 1e-4 + 1e-3 * d);
  // Noise-free value within 10 % of the API point (the cone's mean distance is 2.8 % long).
  EXPECT_NEAR(ir.response().reading(ir.rawDistance(3)), api, 0.10 * api);
  // Noisy readings: every one inside the +-10 % distance band, the mean within 10 % of the API.
  const double lo = ir.response().signal(1.1 * wallMean(d)), hi = ir.response().signal(0.9 * wallMean(d));
  double sum = 0;
  unsigned mn = 100000, mx = 0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    const unsigned v = ir.read(3);
    EXPECT_GE(v, std::floor(lo));
    EXPECT_LE(v, std::ceil(hi));
    mn = std::min(mn, v);
    mx = std::max(mx, v);
    sum += v;
  }
  EXPECT_NEAR(sum / n, api, 0.10 * api);
  EXPECT_GT(mx - mn, 0.5 * (hi - lo)) << "noise must span most of the +-10 % band";
}

INSTANTIATE_TEST_SUITE_P(ApiPoints, RayTracedWall,
                         ::testing::Values(std::pair{0.15, 20.0}, std::pair{0.05, 50.0}, std::pair{0.01, 1000.0},
                                           std::pair{0.005, 3700.0}));

TEST(RayTracedIr, FloorAndOwnBodyAreNotSeen) {
  // On a flat floor with nothing around, after settling, all 15 sensors read 0: the own robot is
  // ignored and the lower rays (10.6 deg down) reach the floor only beyond the 20 cm range.
  for (const std::string level : {"basic", "medium", "detailed"}) {
    World w(flatWorld());
    Robot& r = w.addRobot(loadLevel(level), {0, 0, 0}, "sbot_0");
    runFor(w, 0.5);
    ProximitySensors ir(w, r, ProximitySensors::Model::RayTraced);
    const auto v = ir.readAll();
    for (int i = 0; i < kProximitySensors; ++i) EXPECT_EQ(v[i], 0u) << level << " ir_" << i;
  }
}

TEST(RayTracedIr, OnlyTheSensorFacingTheWallSeesIt) {
  const Pose2D at{0, 0, 0};
  const Pose sensor = spawnPose("basic", at, "ir_7");  // 180 deg: straight back
  WorldConfig c = flatWorld();
  c.terrain.boxes.push_back(wallFacing(sensor, 0.03));
  World w(c);
  Robot& r = spawnOnFloor(w, "basic", at, "sbot_0");
  ProximitySensors ir(w, r, ProximitySensors::Model::RayTraced);
  const auto v = ir.readAll();
  EXPECT_GT(v[7], 80u);
  // Neighbours 20 deg apart see the wall obliquely (farther, fewer rays) or not at all.
  EXPECT_LT(v[6], v[7]);
  EXPECT_LT(v[8], v[7]);
  // 60 deg off, the axis meets the 40 cm wide wall plane 0.087 / cos 60 - 0.057 = 11.7 cm away.
  for (int i : {4, 10}) {
    EXPECT_GT(v[i], 15u) << "ir_" << i;
    EXPECT_LT(v[i], 40u) << "ir_" << i;
  }
  // 80 deg and more off axis: the wall is out of range.
  for (int i : {0, 1, 2, 3, 11, 12, 13, 14}) EXPECT_EQ(v[i], 0u) << "ir_" << i;
  EXPECT_THROW(ir.read(15), std::out_of_range);
  EXPECT_THROW(ir.read(-1), std::out_of_range);
}

class RecordingEffect : public Effect {
 public:
  explicit RecordingEffect(double scale) : scale_(scale) {}
  std::string name() const override { return "recording"; }
  void onSensor(const Robot&, SensorSample& s) override {
    samples.push_back(s);
    s.value *= scale_;
  }
  std::vector<SensorSample> samples;

 private:
  double scale_;
};

TEST(RayTracedIr, EffectsSeeTheNoiseFreeDistanceAndCanChangeIt) {
  const Pose2D at{0, 0, 0};
  const Pose sensor = spawnPose("basic", at, "ir_0");
  WorldConfig c = flatWorld();
  c.terrain.boxes.push_back(wallFacing(sensor, 0.02, "black_paper"));
  World w(c);
  Robot& r = spawnOnFloor(w, "basic", at, "sbot_0");
  auto effect = std::make_shared<RecordingEffect>(2.0);  // a dark surface: as if twice as far
  w.addEffect(effect);
  ProximitySensors ir(w, r, ProximitySensors::Model::RayTraced);
  const unsigned v = ir.read(0);
  ASSERT_EQ(effect->samples.size(), 1u);
  const SensorSample& s = effect->samples[0];
  EXPECT_EQ(s.channel, "ir");
  EXPECT_EQ(s.index, 0);
  EXPECT_NEAR(s.value, wallMean(0.02), 1e-4);  // raw, before noise
  EXPECT_EQ(s.surface, "black_paper");
  EXPECT_NEAR(s.incidence, 0.0, 0.05);  // the nearest ray (centre) hits the wall head-on
  // The reading corresponds to twice the distance (+-10 % noise).
  EXPECT_GE(v, std::floor(ir.response().signal(2.2 * wallMean(0.02))));
  EXPECT_LE(v, std::ceil(ir.response().signal(1.8 * wallMean(0.02))));
  // Sensors that see nothing do not call the effects.
  ir.read(7);
  EXPECT_EQ(effect->samples.size(), 1u);
}

std::vector<unsigned> readSequence(std::uint64_t seed, const std::string& robot_name) {
  const Pose2D at{0, 0, 0};
  const Pose sensor = spawnPose("basic", at, "ir_0");
  WorldConfig c = flatWorld(seed);
  c.terrain.boxes.push_back(wallFacing(sensor, 0.04));
  World w(c);
  Robot& r = spawnOnFloor(w, "basic", at, robot_name);
  ProximitySensors ir(w, r, ProximitySensors::Model::RayTraced);
  std::vector<unsigned> out;
  for (int i = 0; i < 20; ++i) out.push_back(ir.read(0));
  return out;
}

TEST(RayTracedIr, NoiseComesFromTheRobotsSeededStream) {
  EXPECT_EQ(readSequence(3, "sbot_0"), readSequence(3, "sbot_0"));
  EXPECT_NE(readSequence(3, "sbot_0"), readSequence(4, "sbot_0"));
  EXPECT_NE(readSequence(3, "sbot_0"), readSequence(3, "sbot_1")) << "each robot has its own stream";
}

// readAll casts the whole ring at once; its readings (noise included, drawn in the same order)
// are those of read(0..14) in an identically seeded world.
TEST(RayTracedIr, ReadAllReadsWhatEachSensorReads) {
  auto ring = [](bool all_at_once) {
    WorldConfig c = flatWorld(9);
    const Pose2D at{0, 0, 0.2};
    c.terrain.boxes.push_back(wallFacing(spawnPose("medium", at, "ir_2"), 0.03));
    c.terrain.boxes.push_back(wallFacing(spawnPose("medium", at, "ir_9"), 0.08));
    World w(c);
    Robot& r = spawnOnFloor(w, "medium", at, "sbot_0");
    w.addRobot(loadLevel("simple"), {-0.16, 0.02, 0}, "sbot_1");
    ProximitySensors ir(w, r, ProximitySensors::Model::RayTraced);
    std::vector<unsigned> out;
    for (int n = 0; n < 5; ++n) {
      if (all_at_once) {
        for (unsigned v : ir.readAll()) out.push_back(v);
      } else {
        for (int i = 0; i < kProximitySensors; ++i) out.push_back(ir.read(i));
      }
    }
    return out;
  };
  const std::vector<unsigned> together = ring(true), one_by_one = ring(false);
  EXPECT_EQ(together, one_by_one);
  int seen = 0;
  for (unsigned v : together) seen += v > 0;
  EXPECT_GE(seen, 3 * 5) << "the walls and the neighbour must be seen for the comparison to mean anything";
}

// ---- look-up-table model (Simple) ------------------------------------------------------------------

TEST(LutIr, SeesANeighbourLikeTheRayTracedModelButNoWalls) {
  const Pose2D at{0, 0, 0.5};
  const Pose sensor = spawnPose("simple", at, "ir_2");
  const Vec3 axis = floorAxis(sensor);
  const double radius = turretRadius(loadLevel("simple"));
  for (double gap : {0.008, 0.03, 0.08}) {
    World w(flatWorld(11));
    Robot& a = w.addRobot(loadLevel("simple"), at, "a");
    const Vec3 c = sensor.position + (gap + radius) * axis;
    w.addRobot(loadLevel("simple"), {c.x(), c.y(), 1.0}, "b");
    ProximitySensors lut(w, a, ProximitySensors::Model::LookupTable, &defaultIrLookupTable());
    ProximitySensors ray(w, a, ProximitySensors::Model::RayTraced);
    const double from_lut = lut.response().reading(lut.rawDistance(2));
    const double from_rays = ray.response().reading(ray.rawDistance(2));
    ASSERT_GT(from_rays, 0) << gap;
    // The table averages 16 headings of the neighbour; one heading differs by a few per cent.
    EXPECT_NEAR(from_lut, from_rays, 0.15 * from_rays) << "gap " << gap;
    // Noisy reads stay in the +-10 % distance band around the table value.
    const double d = lut.rawDistance(2);
    for (int i = 0; i < 50; ++i) {
      const unsigned v = lut.read(2);
      EXPECT_GE(v, std::floor(lut.response().signal(1.1 * d)));
      EXPECT_LE(v, std::ceil(lut.response().signal(0.9 * d)));
    }
    // The other sensors pointing away see nothing.
    EXPECT_EQ(lut.read(9), 0u);
  }
  // A wall instead of a robot: invisible to the table model (seed: "no walls, obstacles").
  WorldConfig c = flatWorld();
  c.terrain.boxes.push_back(wallFacing(sensor, 0.02));
  World w(c);
  Robot& a = spawnOnFloor(w, "simple", at, "a");
  ProximitySensors lut(w, a, ProximitySensors::Model::LookupTable, &defaultIrLookupTable());
  EXPECT_EQ(lut.read(2), 0u);
  ProximitySensors ray(w, a, ProximitySensors::Model::RayTraced);
  EXPECT_GT(ray.read(2), 200u);
}

TEST(LutIr, FastNeighboursAreLookedUpAtTheirOwnSurfaceGap) {
  // Fast s-bots are half size: a Fast neighbour 3 cm from a Fast sensor reads like a Simple one
  // 3 cm away (gap measured to its own, smaller turret).
  const Pose2D at{0, 0, 0};
  const Pose sensor = spawnPose("fast", at, "ir_0");
  const Vec3 axis = floorAxis(sensor);
  const double radius = turretRadius(loadLevel("fast"));
  EXPECT_NEAR(radius, 0.0285, 1e-6);
  WorldConfig cfg = flatWorld();
  cfg.gravity = loadLevel("fast").gravity;
  World w(cfg);
  Robot& a = w.addRobot(loadLevel("fast"), at, "a");
  const Vec3 c = sensor.position + (0.03 + radius) * axis;
  w.addRobot(loadLevel("fast"), {c.x(), c.y(), 0}, "b");
  ProximitySensors lut(w, a, ProximitySensors::Model::LookupTable, &defaultIrLookupTable());
  EXPECT_NEAR(lut.response().reading(lut.rawDistance(0)), defaultIrLookupTable().lookup(0.03, 0), 1.0);
}

}  // namespace
}  // namespace sbot::test
