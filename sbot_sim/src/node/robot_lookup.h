// Finding a robot named in a service request, with the error message every service gives.
#pragma once

#include <sstream>
#include <string>

#include "sbot_sim/core/world.h"

namespace sbot_node {

/// The world's robots for a message: "sbot_0..sbot_19" when they are named canonically, otherwise
/// the first ten names; "none" for none.
inline std::string robotSummary(sbot::World* world) {
  if (!world || world->robots().empty()) return "none";
  const auto robots = world->robots();
  bool canonical = robots.size() > 1;
  for (std::size_t i = 0; canonical && i < robots.size(); ++i)
    canonical = robots[i]->name() == "sbot_" + std::to_string(i);
  if (canonical) return robots.front()->name() + ".." + robots.back()->name();
  std::ostringstream out;
  for (std::size_t i = 0; i < robots.size() && i < 10; ++i) out << (i ? ", " : "") << robots[i]->name();
  if (robots.size() > 10) out << ", ... (" << robots.size() << " robots)";
  return out.str();
}

/// The robot `name`, or nullptr with `message` saying why (no world after a failed reset, or an
/// unknown name with the names there are).
inline sbot::Robot* lookupRobot(sbot::World* world, const std::string& name, std::string& message) {
  if (!world) {
    message = "no world (a reset failed)";
    return nullptr;
  }
  sbot::Robot* robot = world->findRobot(name);
  if (!robot) message = "unknown robot '" + name + "' (robots: " + robotSummary(world) + ")";
  return robot;
}

}  // namespace sbot_node
