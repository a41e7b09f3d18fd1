// The shipped terrain scenarios (config/scenarios/{rough_terrain,composite_course}.yaml) load, and a
// robot spawned on the rough terrain's height field rests on it at the right height. A validation
// trial's world written as a scenario (sbot_validate --scenario) reads back as that very world.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/terrain.h"
#include "sbot_sim/core/world.h"
#include "experiments.h"

namespace sbot {
namespace {

const std::string kScenarios = std::string(SWARMBOT3D_SOURCE_DIR) + "/config/scenarios/";

TEST(TerrainScenarios, RoughTerrainRobotRestsOnHeightField) {
  Scenario s = loadScenario(kScenarios + "rough_terrain.yaml");
  ASSERT_EQ(s.world.terrain.type, TerrainConfig::Type::Rough);
  // A higher range than the scenario's 8 cm so that "on the height field" differs clearly
  // from "on a plane at z = 0".
  s.world.terrain.height_range = 0.20;
  const HeightMap map = makeHeightMap(s.world.terrain);
  EXPECT_EQ(map.rows, 128);
  EXPECT_EQ(map.cols, 128);
  World w(s.world);
  // Find a gentle, high spot: the robot should rest at ground height + wheel radius there.
  double best_x = 0, best_y = 0, best_h = -1;
  for (double x = -2.0; x <= 2.0; x += 0.05) {
    for (double y = -2.0; y <= 2.0; y += 0.05) {
      const double h = w.terrainHeight(x, y);
      double rough = 0;
      for (double dx : {-0.06, 0.0, 0.06})
        for (double dy : {-0.06, 0.0, 0.06}) rough = std::max(rough, std::fabs(w.terrainHeight(x + dx, y + dy) - h));
      if (rough < 0.004 && h > best_h) { best_h = h; best_x = x; best_y = y; }
    }
  }
  ASSERT_GT(best_h, 0.05) << "no gentle high spot in the height map";
  for (const std::string level : {"simple", "medium"}) {
    Robot& r = w.addRobot(loadLevel(level), {best_x, best_y, 0.3}, level);
    r.setSpeed(0, 0);
    w.stepN(200);
    const Vec3 p = r.basePose().position;
    const double ground = w.terrainHeight(p.x(), p.y());
    EXPECT_NEAR(p.z() - ground, 0.022, 0.006) << level << " base height above the height field";
    EXPECT_LT(r.linearVelocity().norm(), 0.02) << level << " is not at rest";
    EXPECT_GT((r.basePose().orientation * Vec3::UnitZ()).z(), std::cos(0.2)) << level << " is not upright";
    w.removeRobot(level);
  }
}

TEST(TerrainScenarios, CompositeCourseLoads) {
  const Scenario s = loadScenario(kScenarios + "composite_course.yaml");
  ASSERT_EQ(s.world.terrain.type, TerrainConfig::Type::Composite);
  EXPECT_EQ(s.world.terrain.boxes.size(), 7u);
  World w(s.world);
  // The ramp's top face: 10 deg from its foot at the step top (x 0.245, z 0.115).
  EXPECT_NEAR(w.terrainHeight(0.245 + 0.2 * std::cos(0.174533), 0), 0.115 + 0.2 * std::sin(0.174533), 0.003);
  EXPECT_NEAR(w.terrainHeight(-0.4775, 0), 0.0, 1e-6) << "inside the 45 mm gap";
  EXPECT_NEAR(w.terrainHeight(0.8, 0), 0.1845, 1e-3) << "plateau";
  Robot& r = w.addRobot(loadLevel(s.robots.at(0).level), s.robots.at(0).pose, s.robots.at(0).name);
  w.stepN(100);
  EXPECT_NEAR(r.basePose().position.z(), 0.10 + 0.022, 0.006) << "on the start platform";
}

// Every kind that can be written: the parsed scenario holds the trial's terrain, step, gravity,
// seed, contact model and start pose exactly (doubles in their shortest round-trip form), so a
// robot spawned from it starts where the trial's does.
TEST(TerrainScenarios, ATrialsWorldWrittenAsAScenarioReadsBackExactly) {
  int written = 0;
  for (const validation::ExperimentKind& k : validation::experimentKinds()) {
    if (!k.world) continue;
    ++written;
    const double param = k.name == "uphill" || k.name == "downhill" ? 0.7 : 0.037;
    for (const std::string level : {"fast", "detailed"}) {
      const validation::TrialWorld t = k.world(level, param, 3, validation::Drive());
      Scenario a;
      a.world = t.world;
      a.robots.push_back({"sbot_0", level, t.start});
      const Scenario b = parseScenario(scenarioYaml(a, "trial"), "/abs/trial.yaml");
      const std::string what = k.name + " " + level;
      EXPECT_EQ(b.world.step, t.world.step) << what;
      EXPECT_EQ(b.world.gravity, t.world.gravity) << what;
      EXPECT_EQ(b.world.seed, t.world.seed) << what;
      EXPECT_EQ(b.world.contact.material_mu, t.world.contact.material_mu) << what;
      EXPECT_EQ(b.world.contact.mu, t.world.contact.mu) << what;
      EXPECT_EQ(b.world.terrain.type, t.world.terrain.type) << what;
      ASSERT_EQ(b.world.terrain.boxes.size(), t.world.terrain.boxes.size()) << what;
      for (std::size_t i = 0; i < t.world.terrain.boxes.size(); ++i) {
        EXPECT_EQ(b.world.terrain.boxes[i].center, t.world.terrain.boxes[i].center) << what << " box " << i;
        EXPECT_EQ(b.world.terrain.boxes[i].size, t.world.terrain.boxes[i].size) << what << " box " << i;
        EXPECT_EQ(b.world.terrain.boxes[i].pitch, t.world.terrain.boxes[i].pitch) << what << " box " << i;
      }
      ASSERT_EQ(b.robots.size(), 1u);
      EXPECT_EQ(b.robots[0].level, level);
      EXPECT_EQ(b.robots[0].pose.x, t.start.x) << what;
      EXPECT_EQ(b.robots[0].pose.y, t.start.y) << what;
      EXPECT_EQ(b.robots[0].pose.yaw, t.start.yaw) << what;
    }
  }
  EXPECT_EQ(written, 5) << "gap, step, stepb, uphill and downhill";
}

// The half-size Fast robot meets its terrain halved (seed 4.2.2): a cell's gap width and step height
// are full-size values, halved in the Fast trial's world (at full height a 30 mm Fast step cell
// would be a step taller than the half-size robot's wheels).
TEST(TerrainScenarios, TheFastRobotsGapsAndStepsAreHalved) {
  auto box = [](const validation::TrialWorld& t, const std::string& name) {
    for (const BoxObstacle& b : t.world.terrain.boxes)
      if (b.name == name) return b;
    ADD_FAILURE() << "no box " << name;
    return BoxObstacle{};
  };
  auto gapOf = [&](const validation::TrialWorld& t) {
    const BoxObstacle near = box(t, "near_side"), far = box(t, "far_side");
    return (far.center.x() - far.size.x() / 2) - (near.center.x() + near.size.x() / 2);
  };
  const validation::Drive drive;
  EXPECT_NEAR(gapOf(validation::gapWorld("detailed", 0.04, 0, drive)), 0.04, 1e-12);
  EXPECT_NEAR(gapOf(validation::gapWorld("fast", 0.04, 0, drive)), 0.02, 1e-12);
  for (const bool backward : {false, true}) {
    EXPECT_NEAR(box(validation::stepWorld("detailed", 0.016, backward, 0, drive), "step").size.z(), 0.016, 1e-12);
    EXPECT_NEAR(box(validation::stepWorld("fast", 0.016, backward, 0, drive), "step").size.z(), 0.008, 1e-12);
  }
}

}  // namespace
}  // namespace sbot
