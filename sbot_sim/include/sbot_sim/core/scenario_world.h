// The World a scenario file describes, built the same way by the simulator node and the headless tools.
#pragma once

#include <memory>

#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/world.h"

namespace sbot {

/// The scenario's world settings and terrain, its robots at their start poses (refused if two of them
/// start inside each other), its static links (seed 2.2.3) and the effects of its effects file (the
/// calibration workbench's format). Throws ConfigError naming `scenario.source` and the field.
/// Lamps and ambient light are the sensed environment's (sensors/environment.h), not the World's.
std::unique_ptr<World> buildScenarioWorld(const Scenario& scenario);

}  // namespace sbot
