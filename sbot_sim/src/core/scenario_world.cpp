#include "sbot_sim/core/scenario_world.h"

#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/swarm/swarm_graph.h"

namespace sbot {

std::unique_ptr<World> buildScenarioWorld(const Scenario& scenario) {
  auto world = std::make_unique<World>(scenario.world);
  for (const RobotSpawn& s : scenario.robots) world->addRobot(loadLevel(s.level), s.pose, s.name);
  if (const std::string overlap = world->robotsOverlapProblem(); !overlap.empty())
    throw ConfigError(scenario.source, "robots", overlap);
  swarm::addScenarioLinks(*world, scenario.links);
  if (!scenario.effects_file.empty())
    for (const EffectPtr& e : loadEffectsFile(scenario.effects_file, surfaceLabels(scenario.world.terrain)))
      world->addEffect(e);
  return world;
}

}  // namespace sbot
