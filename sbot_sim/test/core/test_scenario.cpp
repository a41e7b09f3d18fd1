// Scenario parsing: valid files produce the robots; malformed ones name the file and the field.
#include <gtest/gtest.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/scenario.h"

namespace sbot {
namespace {

std::string errorOf(const std::string& yaml) {
  try {
    parseScenario(yaml, "bad.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Scenario, SwarmGridAndExplicitRobots) {
  const Scenario s = parseScenario(R"(
seed: 5
duration: 12
world: {step: 0.005, terrain: {type: plane, arena: {size: 3}}}
robots: [{name: leader, level: simple, pose: {x: 1, y: 2, yaw: 0.5}}]
swarm: {count: 4, level: simple, layout: grid, spacing: 0.4}
)", "ok.yaml");
  EXPECT_EQ(s.world.seed, 5u);
  EXPECT_DOUBLE_EQ(s.world.step, 0.005);
  EXPECT_DOUBLE_EQ(s.duration, 12);
  ASSERT_EQ(s.robots.size(), 5u);
  EXPECT_EQ(s.robots[0].name, "leader");
  EXPECT_DOUBLE_EQ(s.robots[0].pose.yaw, 0.5);
  EXPECT_EQ(s.robots[1].name, "sbot_1");
  EXPECT_EQ(s.world.terrain.boxes.size(), 4u);
  EXPECT_FALSE(s.world.lock_idle_turret) << "idle turrets on their hinge by default";
  EXPECT_TRUE(parseScenario("world: {lock_idle_turret: true}", "ok.yaml").world.lock_idle_turret);
}

TEST(Scenario, RobotCountOverride) {
  const std::string yaml = "swarm: {count: 4, layout: random, spacing: 0.3, area: 3}";
  EXPECT_EQ(parseScenario(yaml, "x.yaml", 20).robots.size(), 20u);
  EXPECT_EQ(parseScenario(yaml, "x.yaml", 1).robots.size(), 1u);
  // Random layout keeps robots apart.
  const Scenario s = parseScenario(yaml, "x.yaml", 20);
  for (std::size_t i = 0; i < s.robots.size(); ++i)
    for (std::size_t j = i + 1; j < s.robots.size(); ++j)
      EXPECT_GE(std::hypot(s.robots[i].pose.x - s.robots[j].pose.x, s.robots[i].pose.y - s.robots[j].pose.y), 0.3);
}

TEST(Scenario, ErrorsNameFileAndField) {
  EXPECT_NE(errorOf("world: {step: -1}").find("bad.yaml: field 'world.step'"), std::string::npos);
  EXPECT_NE(errorOf("world: {step: fast}").find("'world.step': expected a number"), std::string::npos);
  EXPECT_NE(errorOf("world: {solver: magic}").find("'world.solver': expected 'quickstep' or 'exact', found 'magic'"),
            std::string::npos);
  EXPECT_NE(errorOf("robots: [{level: huge}]").find("'robots[0].level': unknown model level 'huge'"),
            std::string::npos);
  EXPECT_NE(errorOf("robots: [{pose: {x: 1, z: 2}}]").find("'robots[0].pose.z': unknown field"), std::string::npos);
  EXPECT_NE(errorOf("wrold: {}").find("'wrold': unknown field"), std::string::npos);
  EXPECT_NE(errorOf("world: {lock_idle_turret: sometimes}").find("'world.lock_idle_turret'"), std::string::npos);
  EXPECT_NE(errorOf("world: {terrain: {type: lava}}").find("'world.terrain.type'"), std::string::npos);
  EXPECT_NE(errorOf("seed: [1").find("bad.yaml: not valid YAML"), std::string::npos);
  EXPECT_NE(errorOf("robots: [{name: a}, {name: a}]").find("duplicate robot name 'a'"), std::string::npos);
  EXPECT_NE(errorOf("world: {gravity: .nan}").find("'world.gravity': must be finite"), std::string::npos);
}

TEST(Scenario, EffectsFileIsRelativeToTheScenario) {
  EXPECT_EQ(parseScenario("effects: fitted.yaml", "/data/run/scenario.yaml").effects_file, "/data/run/fitted.yaml");
  EXPECT_EQ(parseScenario("effects: /abs/e.yaml", "/data/s.yaml").effects_file, "/abs/e.yaml");
  EXPECT_EQ(parseScenario("seed: 1", "/data/s.yaml").effects_file, "");
}

TEST(Scenario, MissingFileIsReported) {
  try {
    loadScenario("/nonexistent/scenario.yaml");
    FAIL() << "no exception";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scenario.yaml: cannot open"), std::string::npos);
  }
}

}  // namespace
}  // namespace sbot
