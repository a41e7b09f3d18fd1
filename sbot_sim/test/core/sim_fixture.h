// Shared helpers for the core gtests: a flat world with one robot, and run-for-time utilities.
#pragma once

#include <memory>
#include <string>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world.h"

namespace sbot::test {

inline WorldConfig flatWorld(std::uint64_t seed = 1) {
  WorldConfig c;
  c.seed = seed;
  return c;
}

inline void runFor(World& w, double seconds) {
  const int n = static_cast<int>(seconds / w.config().step + 0.5);
  w.stepN(n);
}

/// The pose of `link` of a robot of `level` freshly spawned at `at` on the flat floor (spawning is
/// deterministic): where the sensor tests place walls, pads and lamps relative to a sensor.
inline Pose spawnPose(const std::string& level, const Pose2D& at, const std::string& link) {
  World w(flatWorld());
  return w.addRobot(loadLevel(level), at, "probe").linkPose(link);
}

/// Yaw difference wrapped to (-pi, pi].
inline double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace sbot::test
