// Scenario parsing: valid files produce the robots; malformed ones name the file and the field.
#include <gtest/gtest.h>

#include <cmath>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/terrain.h"
#include "sbot_sim/core/world.h"

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

/// `yaml` is refused with a message that contains `expected`.
void refused(const std::string& yaml, const std::string& expected) {
  const std::string e = errorOf(yaml);
  EXPECT_NE(e.find(expected), std::string::npos) << yaml << "\n  gave: '" << e << "'";
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
  // A link to a listed robot the override leaves out said "unknown robot" of a robot in the file.
  const std::string linked = "robots: [{name: a, pose: {x: 0, y: 0, yaw: 0}}, {name: b, pose: {x: 1, y: 0, yaw: 0}}]\n"
                             "links: [{holder: a, held: b}]\n";
  try {
    parseScenario(linked, "x.yaml", 1);
    ADD_FAILURE() << "a link to a robot left out was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'links[0].held': robot 'b' is left out by the robot count override 1"),
              std::string::npos) << e.what();
  }
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

// Values that parsed but then misbehaved: an int cast that wrapped (solver_iterations 1e12), a
// count that exhausted memory (1e8 robots, resolution 1e5), a name ROS cannot advertise topics
// under, a gravity pointing up, contact softness outside ODE's ranges.
TEST(Scenario, RefusesValuesThatWouldMisbehaveLater) {
  refused("world: {solver_iterations: 1e12}", "'world.solver_iterations': must be a whole number in [1, 100000], found 1e+12");
  refused("world: {solver_iterations: 2.5}", "'world.solver_iterations': must be a whole number");
  refused("swarm: {count: 100000000}", "'swarm.count': must be a whole number in [0, 10000]");
  refused("seed: -1", "'seed': must be a whole number in [0, ");
  refused("world: {terrain: {type: rough, resolution: 100000}}", "'world.terrain.resolution': must be a whole number in [8, 4096]");
  refused("world: {terrain: {type: rough, seed: 0.5}}", "'world.terrain.seed': must be a whole number");
  refused("world: {gravity: -9.81}", "'world.gravity': must be >= 0");
  refused("world: {step: 1e-7}", "'world.step': must be in [0.0001, 0.5], found 1e-07");
  // yaml-cpp keeps both copies of a repeated key and reads the first: the second was lost silently.
  refused("seed: 1\nworld:\n  step: 0.01\n  step: 0.1\n", "key 'step' appears twice in one mapping (lines 3 and 4)");
  refused("robots: [{name: a, x: 0, x: 1}]", "key 'x' appears twice");
  // An alias inside the value it names overflowed the stack of every loader; aliases nested ten deep
  // ("billion laughs", 10^11 values) walked for hours. Every loader runs the same check.
  refused("extra: &e [*e]", "an alias refers to a value that contains it (anchor at line 1)");
  refused("world: &w {terrain: *w}", "an alias refers to a value that contains it");
  std::string laughs = "l0: &l0 [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n";
  for (int i = 1; i <= 10; ++i) {
    laughs += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) laughs += (k ? ", *l" : "*l") + std::to_string(i - 1);
    laughs += "]\n";
  }
  refused(laughs, "more than 1000000 values once its aliases (*name) are expanded");
  // A plain alias (the same value used twice) is still allowed.
  EXPECT_EQ(parseScenario("world: {step: &s 0.01}\nswarm: {count: 0}\n", "ok.yaml").world.step, 0.01);
  refused("world: {contact: {erp: 5}}", "'world.contact.erp': must be in [0, 1], found 5");
  refused("world: {contact: {cfm: -1}}", "'world.contact.cfm': must be >= 0");
  refused("world: {contact: {bounce: 2}}", "'world.contact.bounce': must be in [0, 1]");
  refused("world: {contact: {max_contacts: 17}}", "'world.contact.max_contacts': must be a whole number in [1, 16]");
  refused("world: {contact: {materials: {track: -1}}}", "'world.contact.materials.track': must be >= 0");
  // A coefficient for a name nothing is made of would never apply.
  refused("world: {contact: {materials: {lava: 1}}}", "'world.contact.materials.lava': no robot material or terrain surface");
  EXPECT_EQ(parseScenario("world: {contact: {materials: {lava: 0.2}}, terrain: {type: composite, boxes: "
                          "[{center: [1, 0, 0.05], size: [0.1, 0.1, 0.1], surface: lava}]}}",
                          "ok.yaml").world.contact.material_mu.at("lava"), 0.2)
      << "a surface of this terrain may have its own coefficient";
  refused("world: {terrain: {type: composite, boxes: [{name: a, center: [1, 0, 0]}, {name: a, center: [2, 0, 0]}]}}",
          "'world.terrain.boxes[1].name': 'a' names another box too");
  refused("world: {gravity: 1e30}", "'world.gravity': must be <= 1000 m/s^2");
  refused("world: {sleep_at_rest: sometimes}", "'world.sleep_at_rest': expected true or false");
  // Values that abort inside ODE, or hang there:
  // over-relaxation from 2 on diverges; a rough terrain of 1 cm took minutes a step, of 1e-300 m aborted.
  refused("world: {solver_sor: 3}", "'world.solver_sor': must be in [0.01, 1.99], found 3");
  refused("world: {terrain: {type: rough, size: 0.01}}", "'world.terrain.size': must be in [0.1, 10000], found 0.01");
  refused("world: {contact: {materials: {? [track]: 1}}}", "a key at line 1 is not a name");
  // Accepted and ignored before: a rough terrain's fields on another kind, an unknown layout of
  // nobody, a box with an arena wall's name.
  refused("world: {terrain: {type: plane, heightmap_image: hills.png}}",
          "'world.terrain.heightmap_image': belongs to a rough terrain; this one is plane");
  refused("swarm: {count: 0, layout: spiral}", "'swarm.layout': expected grid or random, found 'spiral'");
  refused("world: {terrain: {type: composite, boxes: [{name: arena_north, center: [1, 0, 0]}], arena: {size: 2}}}",
          "'world.terrain.boxes[0].name': 'arena_north' is the name of one of the arena's walls");
  TerrainConfig fine;
  fine.type = TerrainConfig::Type::Rough;
  fine.size_x = fine.size_y = 0.1;  // 128 samples: 0.79 mm cells
  try {
    makeHeightMap(fine);
    ADD_FAILURE() << "a height field of sub-millimetre cells was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'terrain.size': 128 x 128 samples over 0.1 x 0.1 m make cells of 0.787"),
              std::string::npos) << e.what();
  }
  fine.resolution = 64;  // 1.6 mm cells
  EXPECT_EQ(makeHeightMap(fine).rows, 64);
  refused("swarm: {count: 2, center: [0, .nan]}", "'swarm.center': must be finite");
  refused("swarm: {count: 2, center: [0, here]}", "'swarm.center': expected [x, y] of numbers");
  refused("world: {terrain: {type: composite, boxes: [{center: [0, 0]}]}}", "'world.terrain.boxes[0].center': expected [x, y, z]");
  for (const std::string name : {"", "1abc", "a b", "a-b", "sbot/x"})
    refused("robots: [{name: '" + name + "'}]", "'robots[0].name': invalid robot name '" + name + "'");
  EXPECT_EQ(parseScenario("robots: [{name: Leader_2}]", "ok.yaml").robots[0].name, "Leader_2");
  try {
    parseScenario("swarm: {count: 3}", "big.yaml", kMaxRobots + 1);
    ADD_FAILURE() << "a robot count override above kMaxRobots was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds 10000"), std::string::npos) << e.what();
  }
}

// The Fast level is scaled for 1/50 g (seed 3.1): a scenario must give it that gravity, and not put
// it beside full-size robots, which would live in 1/50 g too; the full-size levels take any gravity.
TEST(Scenario, FastNeedsItsGravityAndRunsAlone) {
  const std::string earth = errorOf("robots: [{name: a, level: fast}]");
  EXPECT_NE(earth.find("level fast is scaled for a gravity of 0.1962 m/s^2"), std::string::npos) << earth;
  EXPECT_NE(earth.find("this world has 9.81 m/s^2"), std::string::npos) << earth;
  const std::string mixed = errorOf("world: {gravity: 0.1962, step: 0.1}\nrobots: [{name: a, level: fast}, {name: b, level: simple}]");
  EXPECT_NE(mixed.find("cannot share a world with full-size robots (simple)"), std::string::npos) << mixed;
  EXPECT_EQ(parseScenario("world: {gravity: 0.1962, step: 0.1}\nswarm: {count: 3, level: fast}", "ok.yaml").robots.size(), 3u);
  EXPECT_EQ(parseScenario("world: {gravity: 1.62}\nrobots: [{level: detailed}]", "moon.yaml").robots.size(), 1u);
  EXPECT_EQ(gravityProblem(loadLevel("fast"), 0.1962), "");
  EXPECT_NE(gravityProblem(loadLevel("fast"), 9.81), "");
  EXPECT_EQ(gravityProblem(loadLevel("medium"), 0.1962), "") << "full-size levels take any gravity";
}

// Positions ODE's collision spaces cannot index (a robot spawned at x = 1e300 stopped the simulator
// with an ODE assertion): refused by the World wherever a robot or a box enters it, naming it.
TEST(Scenario, PositionsOutsideTheSimulatedSpaceAreRefused) {
  World w(WorldConfig{});
  try {
    w.addRobot(loadLevel("simple"), {1e300, 0, 0}, "far");
    ADD_FAILURE() << "a robot at x = 1e300 was spawned";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("robots (far)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("outside the simulated space"), std::string::npos) << e.what();
  }
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "near");
  EXPECT_THROW(r.setBasePose(Pose(Vec3(0, -2e5, 0.1), Quat::Identity())), ConfigError);
  EXPECT_NO_THROW(r.setBasePose(Pose(Vec3(0, -9e4, 0.1), Quat::Identity()))) << "inside: 90 km";
  w.stepN(10);  // and the world still steps
  WorldConfig c;
  c.terrain.type = TerrainConfig::Type::Composite;
  c.terrain.boxes.push_back({"huge", Vec3(0, 0, 0), Vec3(1e300, 1, 1), 0, 0, "ground"});
  EXPECT_THROW(World{c}, ConfigError);
}

// A robot is dropped onto the highest ground under its own outline. Under its axis-aligned box it
// was, and a Simple 0.5-2 cm clear of a wall at 45 deg had a corner of that box over the wall: it
// was spawned 10 cm up, at the wall's height, and fell beside it.
TEST(Scenario, ARobotBesideADiagonalWallSpawnsOnTheFloorUnlessItsOutlineIsOverIt) {
  int beside = 0, over = 0;
  for (const std::string level : {"simple", "medium", "detailed"}) {
    const double open_floor_z = World(WorldConfig{}).addRobot(loadLevel(level), {0, 0, 0}, "a").basePose().position.z();
    for (double face : {0.065, 0.07, 0.08, 0.09}) {  // [m] the wall's face from the robot's centre, along (1, 1)
      WorldConfig c;
      BoxObstacle wall;
      wall.name = "wall";
      wall.size = Vec3(0.02, 1.0, 0.1);
      wall.yaw = M_PI / 4;
      wall.center = Vec3(1, 1, 0) * ((face + 0.01) / std::sqrt(2.0)) + Vec3(0, 0, 0.05);
      c.terrain.boxes.push_back(wall);
      World w(c);
      Robot& r = w.addRobot(loadLevel(level), {0, 0, 0}, "a");
      const double spawned_z = r.basePose().position.z();
      Pose on_floor = r.basePose();
      on_floor.position.z() = open_floor_z;
      r.setBasePose(on_floor);
      const bool overlaps_on_floor = w.deepestOverlap(r).depth > 0;
      if (overlaps_on_floor) {
        ++over;
        EXPECT_GT(spawned_z, open_floor_z + 0.09) << level << ", face " << face << ": over the wall, set on its top";
      } else {
        ++beside;
        EXPECT_NEAR(spawned_z, open_floor_z, 1e-9) << level << ", face " << face << ": clear of the wall, on the floor";
      }
    }
  }
  EXPECT_GT(beside, 0);
  EXPECT_GT(over, 0) << "the Medium's and Detailed's corners reach a wall 6.5 cm away";
}

// /sim/set_pose put a robot 5 m under the floor and reported success; it then rose through the
// ground at 0.5 m/s. placeRobot refuses a pose that buries it in the ground or another robot, and
// leaves the robot as it was.
TEST(Scenario, ARobotIsNotPlacedInsideTheGroundOrAnotherRobot) {
  for (const std::string level : {"simple", "medium", "detailed"}) {
    World w(WorldConfig{});
    Robot& a = w.addRobot(loadLevel(level), {0, 0, 0}, "a");
    Robot& b = w.addRobot(loadLevel(level), {0.5, 0, 0}, "b");
    w.stepN(50);
    const Pose settled = a.basePose();
    EXPECT_LE(w.deepestOverlap(a).depth, World::kPlacementTolerance) << level << ": settled on the floor";
    const std::string under = w.placeRobot(a, Pose(Vec3(1, 1, -5), Quat::Identity()));
    EXPECT_NE(under.find("robot 'a' there would sit"), std::string::npos) << level << ": " << under;
    EXPECT_NE(under.find("inside the ground"), std::string::npos) << level << ": " << under;
    EXPECT_TRUE(a.basePose().position.isApprox(settled.position, 1e-12)) << level << ": not moved";
    const Pose on_b(b.basePose().position, Quat::Identity());
    EXPECT_NE(w.placeRobot(a, on_b).find("inside robot 'b'"), std::string::npos) << level;
    // The same height a metre away is free.
    EXPECT_EQ(w.placeRobot(a, Pose(settled.position + Vec3(1, 1, 0), settled.orientation)), "") << level;
    EXPECT_TRUE(a.basePose().position.isApprox(settled.position + Vec3(1, 1, 0), 1e-9)) << level;
  }
}

// The same rule guards the other way robots enter a world (the node's /sim/spawn, tools).
TEST(Scenario, TheWorldRefusesRobotNamesRosCannotUse) {
  World w(WorldConfig{});
  EXPECT_THROW(w.addRobot(loadLevel("simple"), {0, 0, 0}, "2nd"), ConfigError);
  EXPECT_THROW(w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot 1"), ConfigError);
  EXPECT_EQ(w.robots().size(), 0u) << "nothing half-built is left behind";
  EXPECT_NO_THROW(w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_1"));
}

TEST(Scenario, EffectsFileIsRelativeToTheScenario) {
  EXPECT_EQ(parseScenario("effects: fitted.yaml", "/data/run/scenario.yaml").effects_file, "/data/run/fitted.yaml");
  EXPECT_EQ(parseScenario("effects: /abs/e.yaml", "/data/s.yaml").effects_file, "/abs/e.yaml");
  EXPECT_EQ(parseScenario("seed: 1", "/data/s.yaml").effects_file, "");
}

// scenarioYaml writes what parseScenario reads back (sbot_validate --scenario writes a validation
// trial's world with it, to be watched in the node).
TEST(Scenario, AWrittenScenarioReadsBackTheSame) {
  const Scenario a = parseScenario(R"(
seed: 11
duration: 42
effects: /abs/fitted.yaml
world:
  step: 0.005
  gravity: 9.7
  solver: exact
  solver_iterations: 33
  solver_sor: 1.2
  lock_idle_turret: true
  sleep_at_rest: false
  contact: {mu: 0.3, erp: 0.4, cfm: 2.0e-5, bounce: 0.1, max_contacts: 6, coulomb: false, materials: {track: 1.7, caster: 0.0}}
  terrain:
    type: composite
    ground_plane: false
    boxes:
      - {name: ramp, center: [0.1234567891, -0.2, 0.05], size: [0.6, 1.0, 0.05], yaw: 0.3, pitch: -0.7, surface: white_paper}
      - {name: step, center: [0.5, 0, 0.01], size: [1, 1, 0.02]}
  ambient_light: 0.25
  lamps: [{position: [1, 2, 0.3], intensity: 5000, colour: [1, 0.5, 0]}]
robots:
  - {name: holder, level: medium, pose: {x: -0.12, y: 0.003, yaw: 3.1}}
  - {name: held, level: medium, pose: {x: 0.2, y: 0, yaw: 0}}
links: [{holder: holder, held: held, kind: side_arm}]
)", "/abs/a.yaml");
  const Scenario b = parseScenario(scenarioYaml(a, "round_trip", "written and read back"), "/abs/b.yaml");
  EXPECT_EQ(b.world.seed, 11u);
  EXPECT_DOUBLE_EQ(b.duration, 42);
  EXPECT_EQ(b.effects_file, "/abs/fitted.yaml");
  EXPECT_DOUBLE_EQ(b.world.step, 0.005);
  EXPECT_DOUBLE_EQ(b.world.gravity, 9.7);
  EXPECT_EQ(b.world.solver, "exact");
  EXPECT_EQ(b.world.solver_iterations, 33);
  EXPECT_DOUBLE_EQ(b.world.solver_sor, 1.2);
  EXPECT_TRUE(b.world.lock_idle_turret);
  EXPECT_FALSE(b.world.rest.enabled);
  EXPECT_TRUE(parseScenario("world: {}", "/abs/c.yaml").world.rest.enabled);  // on by default
  EXPECT_DOUBLE_EQ(b.world.contact.mu, 0.3);
  EXPECT_DOUBLE_EQ(b.world.contact.erp, 0.4);
  EXPECT_DOUBLE_EQ(b.world.contact.cfm, 2.0e-5);
  EXPECT_DOUBLE_EQ(b.world.contact.bounce, 0.1);
  EXPECT_EQ(b.world.contact.max_contacts, 6);
  EXPECT_FALSE(b.world.contact.coulomb);
  EXPECT_EQ(b.world.contact.material_mu, a.world.contact.material_mu);
  EXPECT_EQ(b.world.terrain.type, TerrainConfig::Type::Composite);
  EXPECT_FALSE(b.world.terrain.ground_plane);
  ASSERT_EQ(b.world.terrain.boxes.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const BoxObstacle &x = a.world.terrain.boxes[i], &y = b.world.terrain.boxes[i];
    EXPECT_EQ(y.name, x.name);
    EXPECT_TRUE(y.center.isApprox(x.center, 1e-12)) << y.center.transpose();
    EXPECT_TRUE(y.size.isApprox(x.size, 1e-12));
    EXPECT_DOUBLE_EQ(y.yaw, x.yaw);
    EXPECT_DOUBLE_EQ(y.pitch, x.pitch);
    EXPECT_EQ(y.surface, x.surface);
  }
  ASSERT_EQ(b.robots.size(), 2u);
  EXPECT_EQ(b.robots[0].name, "holder");
  EXPECT_EQ(b.robots[0].level, "medium");
  EXPECT_DOUBLE_EQ(b.robots[0].pose.x, -0.12);
  EXPECT_DOUBLE_EQ(b.robots[0].pose.y, 0.003);
  EXPECT_DOUBLE_EQ(b.robots[0].pose.yaw, 3.1);
  ASSERT_EQ(b.links.size(), 1u);
  EXPECT_EQ(b.links[0].holder, "holder");
  EXPECT_EQ(b.links[0].kind, 2);
  EXPECT_DOUBLE_EQ(b.ambient_light, 0.25);
  ASSERT_EQ(b.lamps.size(), 1u);
  EXPECT_EQ(b.lamps[0].position, Vec3(1, 2, 0.3));
  EXPECT_DOUBLE_EQ(b.lamps[0].intensity, 5000);
  EXPECT_EQ(b.lamps[0].colour, Vec3(1, 0.5, 0));
}

// The sensed environment was read by the node alone: an infinite ambient light aborted it, NaN and
// negative values became 0 without a word, and a bad lamp dropped it and the lamps after it.
TEST(Scenario, LampsAndAmbientLightAreCheckedByField) {
  refused("world: {ambient_light: .inf}", "'world.ambient_light': must be finite");
  refused("world: {ambient_light: .nan}", "'world.ambient_light': must be finite");
  refused("world: {ambient_light: -100}", "'world.ambient_light': must be in [0, 1e+09] mcd/cm^2, found -100");
  refused("world: {ambient_light: bright}", "'world.ambient_light': expected a number, found 'bright'");
  const std::string ok = "{position: [0, 0, 1], intensity: 10}";
  refused("world: {lamps: [" + ok + ", {position: [0, 0, 1], intensity: .nan}]}", "'world.lamps[1].intensity': must be finite");
  refused("world: {lamps: [{position: [0, 0, 1], intensity: -1}]}", "'world.lamps[0].intensity': must be in [0, 1e+09] mcd, found -1");
  refused("world: {lamps: [{position: [0.8], intensity: 1}]}", "'world.lamps[0].position': expected [x, y, z]");
  refused("world: {lamps: [{intensity: 1}]}", "'world.lamps[0].position': missing");
  refused("world: {lamps: [{position: [1e9, 0, 1]}]}", "'world.lamps[0].position'");
  refused("world: {lamps: [{position: [0, 0, 1], colour: [1]}]}", "'world.lamps[0].colour': expected [x, y, z]");
  refused("world: {lamps: [{position: [0, 0, 1], colour: red}]}", "'world.lamps[0].colour': expected [x, y, z]");
  refused("world: {lamps: [{position: [0, 0, 1], colour: [.nan, 0, 0]}]}", "'world.lamps[0].colour': must be finite");
  refused("world: {lamps: [{position: [0, 0, 1], colour: [2, 0, 0]}]}", "'world.lamps[0].colour': expected [r, g, b] in [0, 1]");
  refused("world: {lamps: [{position: [0, 0, 1], brightness: 5}]}", "'world.lamps[0].brightness': unknown field");
  refused("world: {lamps: {a: 1}}", "'world.lamps': expected a list");
  refused("world: {lamps: [7]}", "'world.lamps[0]': expected a mapping");
  const Scenario s = parseScenario("world: {ambient_light: 0.5, lamps: [" + ok + ", " + ok + "]}", "ok.yaml");
  EXPECT_EQ(s.lamps.size(), 2u);
  EXPECT_DOUBLE_EQ(s.ambient_light, 0.5);
}

TEST(Scenario, RoughTerrainIsWrittenSquareOrRefused) {
  Scenario a;
  a.world.terrain.type = TerrainConfig::Type::Rough;
  a.world.terrain.size_x = a.world.terrain.size_y = 2.5;
  a.world.terrain.height_range = 0.08;
  a.world.terrain.heightmap_seed = 9;
  const Scenario b = parseScenario(scenarioYaml(a, "rough"), "/abs/r.yaml");
  EXPECT_EQ(b.world.terrain.type, TerrainConfig::Type::Rough);
  EXPECT_DOUBLE_EQ(b.world.terrain.size_y, 2.5);
  EXPECT_DOUBLE_EQ(b.world.terrain.height_range, 0.08);
  EXPECT_EQ(b.world.terrain.heightmap_seed, 9u);
  a.world.terrain.size_y = 3.0;
  EXPECT_THROW(scenarioYaml(a, "rough"), ConfigError);
}

TEST(Scenario, MissingFileIsReported) {
  try {
    loadScenario("/nonexistent/scenario.yaml");
    FAIL() << "no exception";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scenario.yaml: cannot open"), std::string::npos);
  }
}

// Stated ranges (sbot_sim/core/input_limits.h) and YAML null.
const char* kRobot = "robots: [{name: a, level: simple}]\n";

TEST(ScenarioRanges, EveryFieldHasAStatedRange) {
  refused(std::string("world: {terrain: {type: composite, boxes: [{size: [1e-20, 0.6, 0.1]}]}}\n") + kRobot,
          "field 'world.terrain.boxes[0].size': every edge must be in [0.0001, 200000] m, found 1e-20");
  refused("world: {terrain: {arena: {thickness: 1e-20}}}\n", "field 'world.terrain.arena.thickness': must be in [0.0001");
  refused("robots: [{name: a, pose: {yaw: -1e308}}]\n", "field 'robots[0].pose.yaw': must be in [-6.28319, 6.28319] rad");
  refused("robots: [{name: a, pose: {x: 0, y: 1e20}}]\n", "field 'robots[0].pose': position (0, 1e+20, 0) m is outside");
  refused("world: {terrain: {type: composite, boxes: [{yaw: 1e308}]}}\n", "field 'world.terrain.boxes[0].yaw': must be in");
  refused("world: {terrain: {type: composite, boxes: [{center: [1e9, 0, 0]}]}}\n",
          "field 'world.terrain.boxes[0].center': position (1e+09, 0, 0) m is outside");
  refused("world: {lamps: [{position: [0, 0, 1], intensity: 1e308}]}\n",
          "field 'world.lamps[0].intensity': must be in [0, 1e+09] mcd, found 1e+308");
  refused("world: {ambient_light: 1e308}\n", "field 'world.ambient_light': must be in [0, 1e+09] mcd/cm^2");
  refused("duration: 1e308\n", "field 'duration': must be in [0, 1e+09]");
  refused("swarm: {count: 2, spacing: 1e-30}\n", "field 'swarm.spacing': must be in [0.0001, 200000]");
  refused("swarm: {count: 2, center: [1e30, 0]}\n", "field 'swarm.center': position (1e+30, 0, 0) m is outside");
  refused("world: {terrain: {type: rough, height_range: 1e300}}\n", "field 'world.terrain.height_range': must be in [0, 10000]");
  refused("robots: [{name: " + std::string(10000, 'a') + "}]\n",
          "(a ROS name of at most 64 characters: a letter, then letters, digits or '_')");
  // The limits themselves are accepted.
  EXPECT_EQ(errorOf(std::string("world: {terrain: {type: composite, boxes: [{size: [1e-4, 0.6, 0.1], yaw: 6.28}]}}\n") + kRobot), "");
  EXPECT_EQ(errorOf("robots: [{name: " + std::string(64, 'a') + "}]\n"), "");
}

TEST(ScenarioRanges, YamlNullIsRefusedNotReadAsTheDefault) {
  refused("seed: ~\n", "field 'seed': is null (~); give a value, or leave the field out for its default");
  refused("robots: [{name: a, pose: {x: 0, yaw: ~}}]\n", "field 'robots[0].pose.yaw': is null");
  refused("robots: [{name: a, pose: {x: 0, yaw: }}]\n", "field 'robots[0].pose.yaw': is null");
  refused("world: {step: null}\n", "field 'world.step': is null");
  refused("robots: [{name: ~}]\n", "field 'robots[0].name': is null");
  refused("world: {contact: {materials: {ground: ~}}}\n", "field 'world.contact.materials.ground': is null");
  // An empty section still reads as all defaults.
  EXPECT_EQ(errorOf("world:\nrobots: [{name: a}]\n"), "");
}

}  // namespace
}  // namespace sbot
