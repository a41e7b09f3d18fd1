// The model-switching policy (core/swarm/level_policy.h) on synthetic terrains and on the seed 4.3
// composite course.
#include <gtest/gtest.h>

#include <cmath>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/swarm/level_policy.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace swarm {
namespace {

constexpr double kPlateau = 0.05;

HeightFunction gapAt(double x0, double width) {
  return [=](double x, double) { return x >= x0 && x < x0 + width ? 0.0 : kPlateau; };
}

TEST(LevelPolicy, TiersOnSyntheticTerrain) {
  LevelPolicyConfig c;
  const Pose2D at_origin{0, 0, 0};
  auto tier = [&](const HeightFunction& h, const Pose2D& p = Pose2D{0, 0, 0}) {
    return requiredTier(measureTerrain(h, p, c), c);
  };
  EXPECT_EQ(tier([](double, double) { return 0.0; }), 0);
  EXPECT_EQ(tier(gapAt(0.10, 0.030)), 1);
  EXPECT_NEAR(measureTerrain(gapAt(0.10, 0.030), at_origin, c).gap, 0.030, 0.0051);
  EXPECT_EQ(tier(gapAt(0.10, 0.045)), 1);  // seed default: up to 5 cm is Medium's
  EXPECT_EQ(tier(gapAt(0.05, 0.070)), 2);
  EXPECT_EQ(tier(gapAt(0.40, 0.030)), 0);   // beyond the look-ahead
  EXPECT_EQ(tier(gapAt(-0.20, 0.030)), 0);  // behind the robot
  EXPECT_EQ(tier(gapAt(0.16, 0.200)), 1);   // only the near edge in view: gap of 2 cm so far
  EXPECT_EQ(tier(gapAt(0.10, 0.200)), 2);   // 8 cm seen: wider than a small gap
  c.small_gap_max = 0.04;
  EXPECT_EQ(tier(gapAt(0.10, 0.045)), 2);
  // Heading matters: the same gap along y is not ahead of a robot facing +x.
  EXPECT_EQ(tier([](double, double y) { return y > 0.1 && y < 0.13 ? 0.0 : kPlateau; }), 0);
  EXPECT_EQ(tier([](double, double y) { return y > 0.1 && y < 0.13 ? 0.0 : kPlateau; }, Pose2D{0, 0, M_PI / 2}), 1);
  // Slopes: 0.2 rad is Medium's, 0.6 rad Detailed's.
  EXPECT_EQ(tier([](double x, double) { return x > 0.05 ? std::tan(0.2) * (x - 0.05) : 0.0; }), 1);
  EXPECT_EQ(tier([](double x, double) { return x > 0.05 ? std::tan(0.6) * (x - 0.05) : 0.0; }), 2);
  // Roughness: columns of 4 cm with pseudo-random heights.
  auto columns = [](double hr) {
    return [hr](double x, double y) {
      const int i = static_cast<int>(std::floor(x / 0.04)), j = static_cast<int>(std::floor(y / 0.04));
      const unsigned v = static_cast<unsigned>(i * 73856093) ^ static_cast<unsigned>(j * 19349663);
      return hr * ((v % 1000) / 1000.0);
    };
  };
  EXPECT_EQ(tier(columns(0.0005)), 0);
  EXPECT_EQ(tier(columns(0.006)), 1);
  EXPECT_EQ(tier(columns(0.014)), 2);
}

TEST(LevelPolicy, HysteresisAndOverride) {
  LevelPolicyConfig c;
  c.demote_delay = 1.0;
  LevelPolicy p(c);
  TerrainFeatures flat, gap, wide;
  gap.gap = 0.03;
  wide.gap = 0.08;
  EXPECT_EQ(p.decide("a", 0.0, flat), "basic");
  EXPECT_EQ(p.decide("a", 0.2, gap), "medium");     // promoted at once
  EXPECT_EQ(p.decide("a", 0.4, wide), "detailed");
  EXPECT_EQ(p.decide("a", 0.6, flat), "detailed");  // demotion waits demote_delay
  EXPECT_EQ(p.decide("a", 1.4, flat), "detailed");
  EXPECT_EQ(p.decide("a", 1.6, flat), "basic");
  EXPECT_EQ(p.decide("a", 1.8, gap), "medium");
  EXPECT_EQ(p.decide("a", 2.0, flat), "medium");
  EXPECT_EQ(p.decide("a", 2.4, gap), "medium");     // the requirement came back: the clock restarts
  EXPECT_EQ(p.decide("a", 3.0, flat), "medium");
  EXPECT_EQ(p.decide("a", 4.0, flat), "basic");
  EXPECT_EQ(p.decide("a", 4.2, flat, /*gripping=*/true), "detailed");
  p.setOverride("a", "simple");
  EXPECT_EQ(p.decide("a", 5.0, wide), "simple");
  EXPECT_EQ(p.overrideOf("a"), "simple");
  p.setOverride("a", "");
  EXPECT_EQ(p.decide("a", 5.2, wide), "detailed");
  EXPECT_EQ(p.decide("b", 5.2, flat), "basic");  // robots are independent
}

TEST(LevelPolicy, CompositeCourseSegmentsGetTheirLevels) {
  const Scenario s = loadScenario(descriptionDirectory() + "/../config/scenarios/composite_course_switching.yaml");
  World w(s.world);
  HeightCache h([&w](double x, double y) { return w.terrainHeight(x, y); });
  LevelPolicyConfig c;
  c.small_gap_max = 0.04;
  auto tier = [&](double x, double y, double yaw) { return requiredTier(measureTerrain(h.function(), {x, y, yaw}, c), c); };
  EXPECT_EQ(tier(0.5, 0, 0), 0);      // start: flat
  EXPECT_EQ(tier(1.42, 0, 0), 1);     // before the 30 mm gap
  EXPECT_EQ(tier(2.2, 0, 0), 0);
  EXPECT_EQ(tier(2.95, 0, 0), 1);     // 40 mm gap
  EXPECT_EQ(tier(4.3, 0, 0), 1);      // moderately rough
  EXPECT_EQ(tier(5.3, 0.6, M_PI / 2), 0);
  EXPECT_EQ(tier(5.3, 1.4, M_PI / 2), 1);   // on the slope
  EXPECT_EQ(tier(5.3, 2.35, M_PI / 2), 2);  // 45 mm gap
  EXPECT_EQ(tier(5.3, 3.0, M_PI / 2), 0);
  EXPECT_EQ(tier(5.3, 4.0, M_PI / 2), 2);   // very rough
  EXPECT_EQ(tier(5.3, 4.7, M_PI / 2), 0);
}

}  // namespace
}  // namespace swarm
}  // namespace sbot
