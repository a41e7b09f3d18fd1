// World::castRays (a sensor's ray bundle searched once by its bounding box) must see exactly what
// World::castRay sees ray by ray: on boxes turned every way, other robots, the ground plane and a
// rough height field, with and without the sensing robot ignored.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "sim_fixture.h"

namespace sbot::test {
namespace {

void expectSameHits(const World& w, const Robot* ignore, std::mt19937& rng, int bundles, int* hits_seen) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int b = 0; b < bundles; ++b) {
    const Vec3 origin(0.4 * u(rng), 0.4 * u(rng), 0.02 + 0.1 * (u(rng) + 1));
    const Vec3 axis = Vec3(u(rng), u(rng), 0.5 * u(rng)).normalized();
    std::vector<Vec3> dirs;
    for (int i = 0; i < 5; ++i) dirs.push_back((axis + 0.3 * Vec3(u(rng), u(rng), u(rng))).normalized());
    if (b % 7 == 0) dirs.assign(3, Vec3::UnitX());  // axis-aligned rays: a flat bounding box
    const double length = 0.05 + 0.3 * (u(rng) + 1);
    const std::vector<RayHit> bundle = w.castRays(origin, dirs, length, ignore);
    ASSERT_EQ(bundle.size(), dirs.size());
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const RayHit one = w.castRay(origin, dirs[i], length, ignore);
      ASSERT_EQ(bundle[i].hit, one.hit) << "bundle " << b << " ray " << i;
      EXPECT_DOUBLE_EQ(bundle[i].distance, one.distance);
      if (!one.hit) continue;
      ++*hits_seen;
      EXPECT_EQ(bundle[i].surface, one.surface);
      EXPECT_EQ(bundle[i].robot, one.robot);
      EXPECT_LT((bundle[i].point - one.point).norm(), 1e-12);
      EXPECT_LT((bundle[i].normal - one.normal).norm(), 1e-12);
    }
  }
}

TEST(WorldRays, BundleSeesWhatSingleRaysSeeAmongBoxesAndRobots) {
  WorldConfig c = flatWorld();
  c.terrain.type = TerrainConfig::Type::Composite;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 12; ++i) {
    BoxObstacle box;
    box.name = "box_" + std::to_string(i);
    box.center = Vec3(0.5 * u(rng), 0.5 * u(rng), 0.05 + 0.05 * u(rng));
    box.size = Vec3(0.02 + 0.1 * (u(rng) + 1), 0.02 + 0.1 * (u(rng) + 1), 0.02 + 0.05 * (u(rng) + 1));
    box.yaw = M_PI * u(rng);
    box.pitch = 0.3 * u(rng);
    box.surface = i % 2 ? "white_paper" : "black_card";
    c.terrain.boxes.push_back(box);
  }
  World w(c);
  Robot& a = w.addRobot(loadLevel("medium"), {-0.3, 0.6, 0}, "sbot_a");
  w.addRobot(loadLevel("detailed"), {0.3, 0.6, 1.0}, "sbot_b");
  w.addRobot(loadLevel("simple"), {0.0, -0.6, 2.0}, "sbot_c");
  runFor(w, 0.2);
  int hits = 0;
  expectSameHits(w, nullptr, rng, 400, &hits);
  expectSameHits(w, &a, rng, 400, &hits);
  EXPECT_GT(hits, 1000) << "the bundles must actually hit things for the comparison to mean anything";
}

// Several bundles searched at once (a sensor ring, castRayBundles) see what each bundle sees alone.
TEST(WorldRays, RingOfBundlesSeesWhatEachBundleSees) {
  WorldConfig c = flatWorld();
  c.terrain.type = TerrainConfig::Type::Composite;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 8; ++i) {
    BoxObstacle box;
    box.name = "box_" + std::to_string(i);
    box.center = Vec3(0.3 * u(rng), 0.3 * u(rng), 0.05);
    box.size = Vec3(0.05, 0.08, 0.1);
    box.yaw = M_PI * u(rng);
    c.terrain.boxes.push_back(box);
  }
  World w(c);
  Robot& a = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_a");
  w.addRobot(loadLevel("simple"), {0.15, 0.05, 1.0}, "sbot_b");
  runFor(w, 0.2);
  int hits = 0;
  for (int ring = 0; ring < 50; ++ring) {
    std::vector<Vec3> origins;
    std::vector<std::vector<Vec3>> dirs;
    for (int k = 0; k < 15; ++k) {  // a ring around the robot, each sensor a 5-ray cone outwards
      const double bearing = 2 * M_PI * k / 15 + 0.1 * u(rng);
      const Vec3 out(std::cos(bearing), std::sin(bearing), 0.1 * u(rng));
      origins.push_back(Vec3(0, 0, 0.06) + 0.06 * Vec3(out.x(), out.y(), 0));
      std::vector<Vec3> cone;
      for (int i = 0; i < 5; ++i) cone.push_back((out + 0.2 * Vec3(u(rng), u(rng), u(rng))).normalized());
      dirs.push_back(cone);
    }
    const double length = 0.05 + 0.25 * (u(rng) + 1);
    const Robot* ignore = ring % 2 ? &a : nullptr;
    const auto together = w.castRayBundles(origins, dirs, length, ignore);
    ASSERT_EQ(together.size(), origins.size());
    for (std::size_t k = 0; k < origins.size(); ++k) {
      const std::vector<RayHit> alone = w.castRays(origins[k], dirs[k], length, ignore);
      ASSERT_EQ(together[k].size(), alone.size());
      for (std::size_t i = 0; i < alone.size(); ++i) {
        ASSERT_EQ(together[k][i].hit, alone[i].hit) << "ring " << ring << " bundle " << k << " ray " << i;
        EXPECT_DOUBLE_EQ(together[k][i].distance, alone[i].distance);
        EXPECT_EQ(together[k][i].surface, alone[i].surface);
        EXPECT_EQ(together[k][i].robot, alone[i].robot);
        hits += alone[i].hit;
      }
    }
  }
  EXPECT_GT(hits, 500) << "the rings must actually hit things for the comparison to mean anything";
  EXPECT_THROW(w.castRayBundles({Vec3::Zero()}, {}, 0.1, nullptr), std::invalid_argument);
}

TEST(WorldRays, BundleSeesWhatSingleRaysSeeOnRoughTerrain) {
  WorldConfig c = flatWorld();
  c.terrain.type = TerrainConfig::Type::Rough;
  c.terrain.ground_plane = false;
  c.terrain.height_range = 0.08;  // [m] bumps up to the rays' origins
  World w(c);
  std::mt19937 rng(11);
  int hits = 0;
  expectSameHits(w, nullptr, rng, 300, &hits);
  EXPECT_GT(hits, 250);
}

TEST(WorldRays, NothingInReachGivesMissesAtFullLength) {
  World w(flatWorld());
  const std::vector<RayHit> h = w.castRays(Vec3(0, 0, 0.5), {Vec3::UnitX(), Vec3(1, 1, 0)}, 0.2, nullptr);
  ASSERT_EQ(h.size(), 2u);
  for (const RayHit& r : h) {
    EXPECT_FALSE(r.hit);
    EXPECT_DOUBLE_EQ(r.distance, 0.2);
  }
  EXPECT_TRUE(w.castRays(Vec3(0, 0, 0.5), {}, 0.2, nullptr).empty());
}

}  // namespace
}  // namespace sbot::test
