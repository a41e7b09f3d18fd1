// Scenario files (config/scenarios/*.yaml): world settings, seed and the robots to spawn.
//
//   seed: 42                      # root of every random stream
//   duration: 60                  # [s] simulated, 0 = run until stopped
//   world:
//     step: 0.01                  # [s]
//     gravity: 9.81               # [m/s^2]
//     solver_iterations: 40
//     contact: {mu: 1.0, erp: 0.2, cfm: 1.0e-5, coulomb: true, materials: {caster: 0.0}}
//     terrain:
//       type: plane               # plane | composite | rough
//       boxes: [{name: wall_n, center: [0, 2, 0.05], size: [4, 0.02, 0.1], yaw: 0, surface: white_paper}]
//       arena: {size: 4.0, height: 0.1}   # shorthand: four walls around the origin
//   robots:                       # explicit robots ...
//     - {name: sbot_0, level: simple, pose: {x: 0, y: 0, yaw: 0}}   # name: see robotNameProblem
//   swarm:                        # ... and/or generated ones, named sbot_<i> after the explicit ones
//     {count: 20, level: simple, layout: grid, spacing: 0.3, center: [0, 0]}   # layout grid|random
//   world.lamps: [{position: [x, y, z], intensity: mcd, colour: [r, g, b]}]   # the sensed environment
//   world.ambient_light: 0.0      # [mcd/cm^2] (sensors/environment.h)
//   links:                        # static connections (seed 2.2.3), made at start (and at reset):
//     - {holder: sbot_1, held: sbot_0, kind: front_gripper}   # kind front_gripper | side_arm;
//                                 # held is moved to holder's gripper_tip (see core/swarm/swarm_graph.h)
#pragma once

#include <string>
#include <vector>

#include "sbot_sim/core/types.h"
#include "sbot_sim/core/world_config.h"

namespace sbot {

/// The most robots a scenario may spawn (swarm.count, or the node's ~robots override): a typo such
/// as `count: 1e8` then fails with a message instead of exhausting the machine's memory.
constexpr int kMaxRobots = 10000;

struct RobotSpawn {
  std::string name;
  std::string level = "simple";
  Pose2D pose;
};

/// A lamp of the sensed environment (`world.lamps[]`, sensors/environment.h Environment::addLamp).
struct LampSpawn {
  Vec3 position = Vec3::Zero();  ///< [m]
  double intensity = 0;          ///< [mcd] (milli-candela, the seed's light unit), >= 0
  Vec3 colour = Vec3::Ones();    ///< RGB in [0, 1], as the camera sees it
};

/// A static link of the scenario's `links` list (core/swarm/swarm_graph.h createStaticLink).
struct LinkSpawn {
  std::string holder, held;
  int kind = 1;                  ///< 1 front gripper, 2 side arm (sbot_msgs/SwarmGraph)
};

struct Scenario {
  std::string source;            ///< file it was read from
  WorldConfig world;
  std::vector<RobotSpawn> robots;
  std::vector<LinkSpawn> links;  ///< after the robots; every name is one of `robots`
  std::vector<LampSpawn> lamps;  ///< world.lamps: what the light sensors and the camera see
  double ambient_light = 0;      ///< world.ambient_light [mcd/cm^2], >= 0
  double duration = 0;           ///< [s], 0 = unlimited
  /// Effects file (`effects: FILE`, relative to the scenario): the calibration workbench's format,
  /// so an accepted effect becomes part of the simulation. Empty = none.
  std::string effects_file;
};

/// Parse a scenario. `robot_count` >= 0 overrides swarm.count. Throws ConfigError naming the file
/// and the field for anything malformed (unknown level, negative step, non-numeric pose, ...).
Scenario loadScenario(const std::string& path, int robot_count = -1);
Scenario parseScenario(const std::string& yaml_text, const std::string& source, int robot_count = -1);

/// `scenario` as a scenario file that parseScenario reads back to the same world, robots, links,
/// seed and duration (`name` and `description` head it; the node's lamps are not part of a
/// Scenario). Rough terrain is written with its image path as it is, so give an absolute one.
/// Throws ConfigError for what the format cannot hold: a rough terrain that is not square.
std::string scenarioYaml(const Scenario& scenario, const std::string& name, const std::string& description = "");

/// The robots' levels against the world's gravity (the parsers call it; call it again after
/// changing levels): a Fast robot only in its 1/50 g and never beside full-size robots. Throws
/// ConfigError naming `source`, the robot and both gravities.
void checkGravityOfLevels(const Scenario& scenario, const std::string& source);

}  // namespace sbot
