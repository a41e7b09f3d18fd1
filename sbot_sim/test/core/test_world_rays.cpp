// World::castRays (a sensor's ray bundle searched once by its bounding box, each ray then tested
// only against the geoms whose bounding boxes meet its segment's) must see exactly what
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

/// A flat composite world with `n` upright boxes of `size` standing on the floor within +-`spread`
/// m of the origin, each turned at random. Draws from `rng` (positions, then yaw, box by box).
WorldConfig worldWithUprightBoxes(std::mt19937& rng, int n, double spread, const Vec3& size) {
  WorldConfig c = flatWorld();
  c.terrain.type = TerrainConfig::Type::Composite;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < n; ++i) {
    BoxObstacle box;
    box.name = "box_" + std::to_string(i);
    box.center = Vec3(spread * u(rng), spread * u(rng), size.z() / 2);
    box.size = size;
    box.yaw = M_PI * u(rng);
    c.terrain.boxes.push_back(box);
  }
  return c;
}

// Several bundles searched at once (a sensor ring, castRayBundles) see what each bundle sees alone.
TEST(WorldRays, RingOfBundlesSeesWhatEachBundleSees) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  World w(worldWithUprightBoxes(rng, 8, 0.3, Vec3(0.05, 0.08, 0.1)));
  Robot& a = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_a");
  w.addRobot(loadLevel("simple"), {0.15, 0.05, 1.0}, "sbot_b");
  runFor(w, 0.2);
  int hits = 0;
  for (int ring = 0; ring < 50; ++ring) {
    std::vector<Vec3> origins, dirs;  // bundle k: dirs[5k .. 5k + 4]
    for (int k = 0; k < 15; ++k) {    // a ring around the robot, each sensor a 5-ray cone outwards
      const double bearing = 2 * M_PI * k / 15 + 0.1 * u(rng);
      const Vec3 out(std::cos(bearing), std::sin(bearing), 0.1 * u(rng));
      origins.push_back(Vec3(0, 0, 0.06) + 0.06 * Vec3(out.x(), out.y(), 0));
      for (int i = 0; i < 5; ++i) dirs.push_back((out + 0.2 * Vec3(u(rng), u(rng), u(rng))).normalized());
    }
    const double length = 0.05 + 0.25 * (u(rng) + 1);
    const Robot* ignore = ring % 2 ? &a : nullptr;
    const std::vector<RayHit> together = w.castRayBundles(origins, dirs, length, ignore);
    ASSERT_EQ(together.size(), dirs.size());
    for (std::size_t k = 0; k < origins.size(); ++k) {
      const std::vector<Vec3> cone(dirs.begin() + 5 * k, dirs.begin() + 5 * k + 5);
      const std::vector<RayHit> alone = w.castRays(origins[k], cone, length, ignore);
      ASSERT_EQ(alone.size(), 5u);
      for (std::size_t i = 0; i < alone.size(); ++i) {
        const RayHit& t = together[5 * k + i];
        ASSERT_EQ(t.hit, alone[i].hit) << "ring " << ring << " bundle " << k << " ray " << i;
        EXPECT_DOUBLE_EQ(t.distance, alone[i].distance);
        EXPECT_EQ(t.surface, alone[i].surface);
        EXPECT_EQ(t.robot, alone[i].robot);
        hits += alone[i].hit;
      }
    }
  }
  EXPECT_GT(hits, 500) << "the rings must actually hit things for the comparison to mean anything";
  // Directions that do not split into equal bundles are refused.
  EXPECT_THROW(w.castRayBundles({Vec3::Zero(), Vec3::UnitX()}, {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()}, 0.1,
                                nullptr),
               std::invalid_argument);
  EXPECT_THROW(w.castRayBundles({}, {Vec3::UnitX()}, 0.1, nullptr), std::invalid_argument);
  EXPECT_TRUE(w.castRayBundles({}, {}, 0.1, nullptr).empty());
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

// The ground plane's bounding box is the half space below it: rays that end on it, just short of
// it or just above it must be told apart exactly as castRay does.
TEST(WorldRays, RaysEndingAtTheGroundPlaneAreCulledOnlyWhenTheyCannotReachIt) {
  World w(flatWorld());
  const Vec3 origin(0, 0, 0.1);
  std::vector<Vec3> dirs;
  for (double z : {-1.0, -0.5, -1e-3, 0.0, 1e-3}) dirs.push_back(Vec3(1, 0, z).normalized());
  for (double length : {0.0999, 0.1, 0.1001, 0.2, 100.0}) {
    const std::vector<RayHit> bundle = w.castRays(origin, dirs, length, nullptr);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const RayHit one = w.castRay(origin, dirs[i], length, nullptr);
      ASSERT_EQ(bundle[i].hit, one.hit) << "length " << length << " ray " << i;
      EXPECT_DOUBLE_EQ(bundle[i].distance, one.distance);
    }
  }
  // Straight down 0.2 m from 0.1 m: the plane, 0.1 m away; level: nothing.
  EXPECT_TRUE(w.castRays(origin, {-Vec3::UnitZ()}, 0.2, nullptr)[0].hit);
  EXPECT_NEAR(w.castRays(origin, {-Vec3::UnitZ()}, 0.2, nullptr)[0].distance, 0.1, 1e-12);
  EXPECT_FALSE(w.castRays(origin, {Vec3::UnitX()}, 0.2, nullptr)[0].hit);
}

// Lines of sight of their own lengths across a swarm (a fake camera's, castRaysOfLengths: a robot's
// geoms tested only when the segment crosses the robot's box) see what castRay sees one by one,
// among robots of every level, boxes and the ground, from the robots' camera height and grazing
// the floor, with and without the looking robot ignored.
TEST(WorldRays, LinesOfSightOfTheirOwnLengthsSeeWhatSingleRaysSee) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  World w(worldWithUprightBoxes(rng, 6, 0.8, Vec3(0.05, 0.1, 0.08)));
  const char* levels[] = {"simple", "medium", "detailed", "basic", "fast"};
  std::vector<Robot*> robots;
  for (int i = 0; i < 16; ++i)
    robots.push_back(&w.addRobot(loadLevel(levels[i % 5]), {0.4 * (i % 4) - 0.6, 0.4 * (i / 4) - 0.6, 0.5 * i},
                                 "sbot_" + std::to_string(i)));
  runFor(w, 0.2);
  int hits = 0, misses = 0;
  for (int view = 0; view < 60; ++view) {
    const Robot* looker = robots[view % robots.size()];
    const Vec3 origin = looker->basePose().position + Vec3(0, 0, 0.05 + 0.05 * u(rng));
    std::vector<Vec3> dirs;
    std::vector<double> lengths;
    for (const Robot* r : robots) {  // towards every robot's ring height, a little off its centre
      const Vec3 target = r->basePose().position + Vec3(0.06 * u(rng), 0.06 * u(rng), 0.03 + 0.03 * u(rng));
      if ((target - origin).norm() < 1e-3) continue;
      dirs.push_back(target - origin);
      lengths.push_back((target - origin).norm() - 0.003);
    }
    dirs.push_back(Vec3(1, 0.3, -0.2));  // down to the floor, and one of no length
    lengths.push_back(2.0);
    dirs.push_back(Vec3::UnitX());
    lengths.push_back(0.0);
    const Robot* ignore = view % 2 ? looker : nullptr;
    const std::vector<RayHit> all = w.castRaysOfLengths(origin, dirs, lengths, ignore);
    ASSERT_EQ(all.size(), dirs.size());
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const RayHit one = w.castRay(origin, dirs[i], lengths[i], ignore);
      ASSERT_EQ(all[i].hit, one.hit) << "view " << view << " ray " << i;
      EXPECT_DOUBLE_EQ(all[i].distance, one.distance);
      EXPECT_EQ(all[i].robot, one.robot);
      EXPECT_EQ(all[i].surface, one.surface);
      (one.hit ? hits : misses) += 1;
    }
  }
  EXPECT_GT(hits, 300) << "the lines of sight must be blocked often enough for the comparison to mean anything";
  EXPECT_GT(misses, 100) << "and clear often enough";
  EXPECT_THROW(w.castRaysOfLengths(Vec3::Zero(), {Vec3::UnitX()}, {0.1, 0.2}, nullptr), std::invalid_argument);
  EXPECT_TRUE(w.castRaysOfLengths(Vec3::Zero(), {}, {}, nullptr).empty());
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
