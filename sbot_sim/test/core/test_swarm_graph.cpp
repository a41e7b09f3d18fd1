// The swarm graph (seed 2.3, eq. 2.16) and static links (seed 2.2.3).
#include <gtest/gtest.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sim_fixture.h"

namespace sbot {
namespace {

TEST(SwarmGraph, PositionsHeadingsConnectionsComponents) {
  World w(test::flatWorld());
  for (int i = 0; i < 5; ++i) w.addRobot(loadLevel("simple"), {0.5 * i, 0, 0.1 * i}, "sbot_" + std::to_string(i));
  swarm::SwarmGraph g = swarm::computeSwarmGraph(w);
  ASSERT_EQ(g.n, 5u);
  EXPECT_EQ(g.components, 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(g.names[i], "sbot_" + std::to_string(i));
    EXPECT_NEAR(g.positions[i].x(), 0.5 * i, 1e-6);
    EXPECT_NEAR(g.headings[i], 0.1 * i, 1e-6);
    EXPECT_EQ(g.component[i], i);
  }
  swarm::createStaticLink(w, {"sbot_1", "sbot_0", swarm::kFrontGripper});
  swarm::createStaticLink(w, {"sbot_3", "sbot_4", swarm::kSideArm}, /*place=*/false);
  g = swarm::computeSwarmGraph(w);
  EXPECT_EQ(g.connection(1, 0), swarm::kFrontGripper);
  EXPECT_EQ(g.connection(0, 1), swarm::kNone);
  EXPECT_EQ(g.connection(3, 4), swarm::kSideArm);
  EXPECT_EQ(g.components, 3u);
  EXPECT_EQ(g.component[0], g.component[1]);
  EXPECT_EQ(g.component[3], g.component[4]);
  EXPECT_NE(g.component[2], g.component[0]);
  EXPECT_NE(g.component[2], g.component[3]);
  // Placement: held's centre 0.147 m in front of the holder.
  const Vec3 d = g.positions[0] - g.positions[1];
  EXPECT_NEAR(d.head<2>().norm(), 0.147, 0.002);
  // Deleting a robot drops its connections.
  w.removeRobot("sbot_4");
  g = swarm::computeSwarmGraph(w);
  EXPECT_EQ(g.n, 4u);
  EXPECT_EQ(g.components, 3u);
}

TEST(SwarmGraph, ScenarioChainsOfFiveHoldTogether) {
  const Scenario s = parseScenario(R"(
seed: 3
world: {terrain: {type: plane}}
robots:
  - {name: sbot_0, level: simple, pose: {x: 0, y: 0, yaw: 0}}
  - {name: sbot_1, level: simple, pose: {x: -0.2, y: 0, yaw: 0}}
  - {name: sbot_2, level: simple, pose: {x: -0.4, y: 0, yaw: 0}}
  - {name: sbot_3, level: simple, pose: {x: -0.6, y: 0, yaw: 0}}
  - {name: sbot_4, level: simple, pose: {x: -0.8, y: 0, yaw: 0}}
links:
  - {holder: sbot_1, held: sbot_0, kind: front_gripper}
  - {holder: sbot_2, held: sbot_1}
  - {holder: sbot_3, held: sbot_2}
  - {holder: sbot_4, held: sbot_3}
)", "<chain>");
  ASSERT_EQ(s.links.size(), 4u);
  World w(s.world);
  for (const auto& r : s.robots) w.addRobot(loadLevel(r.level), r.pose, r.name);
  swarm::addScenarioLinks(w, s.links);
  // Placement: each held robot (and what it already holds) moved in front of its holder.
  const double x0 = w.robot("sbot_0").basePose().position.x();
  EXPECT_NEAR(x0, -0.8 + 4 * 0.147, 0.003);
  for (Robot* r : w.robots()) r->setSpeed(40, 40);
  test::runFor(w, 3.0);
  const swarm::SwarmGraph g = swarm::computeSwarmGraph(w);
  EXPECT_EQ(g.components, 1u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(g.connection(i + 1, i), swarm::kFrontGripper);
    EXPECT_NEAR((g.positions[i + 1] - g.positions[i]).head<2>().norm(), 0.147, 0.01) << i;
  }
  EXPECT_GT(g.positions[0].x() - x0, 0.25);  // the chain drove forward (40 units = 0.112 m/s)
}

TEST(SwarmGraph, MalformedLinksAreReported) {
  const char* base = "robots: [{name: a}, {name: b}]\n";
  EXPECT_THROW(parseScenario(std::string(base) + "links: [{holder: a, held: c}]", "<x>"), ConfigError);
  EXPECT_THROW(parseScenario(std::string(base) + "links: [{holder: a, held: a}]", "<x>"), ConfigError);
  EXPECT_THROW(parseScenario(std::string(base) + "links: [{holder: a, held: b, kind: glue}]", "<x>"), ConfigError);
  EXPECT_THROW(parseScenario(std::string(base) + "links: [{holder: a, held: b, colour: red}]", "<x>"), ConfigError);
  EXPECT_NO_THROW(parseScenario(std::string(base) + "links: [{holder: a, held: b, kind: side_arm}]", "<x>"));
  // A gripper holds one robot: a second link of the same holder and kind replaced the first unseen.
  try {
    parseScenario("robots: [{name: a}, {name: b}, {name: c}]\nlinks: [{holder: a, held: b}, {holder: a, held: c}]", "<x>");
    ADD_FAILURE() << "a second front-gripper link of one holder was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'links[1]': 'a' already holds 'b' with its front_gripper (links[0])"),
              std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(parseScenario("robots: [{name: a}, {name: b}, {name: c}]\n"
                                "links: [{holder: a, held: b}, {holder: a, held: c, kind: side_arm}]", "<x>"))
      << "its side arm may hold another";
}

}  // namespace
}  // namespace sbot
