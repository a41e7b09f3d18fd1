// What the trial files (experiments_terrain.cpp, experiments_efficiency.cpp) share with
// experiments.cpp: the trials' set-up and stepping helpers. Not part of the interface (experiments.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "experiments.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace validation {
namespace detail {

WorldConfig configFor(const RobotDescription& d, std::uint64_t seed, const Drive& drive = Drive());

/// Per-trial generator of the start perturbations.
struct Jitter {
  std::mt19937_64 gen;
  Jitter(const std::string& what, double param, int trial)
      : gen(std::hash<std::string>()(what) ^ (static_cast<std::uint64_t>(std::lround(param * 1e6)) * 1000003ULL) ^
            (static_cast<std::uint64_t>(trial) * 0x9E3779B97F4A7C15ULL)) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen); }
};

Vec3 upOf(const Robot& r);
double angleBetween(const Vec3& a, const Vec3& b);
double headingOf(const Robot& r);
/// How far the robot's heading has turned from `h0` [rad, 0..pi].
double headingChangeSince(const Robot& r, double h0);
/// Tables 4.6 and 4.2.4: a robot whose heading turned more than this has changed course ("c/c").
constexpr double kCourseChange = 0.35;  // [rad], 20 deg

/// Steps between two calls of runFor's check: ~0.05 s (every step for Fast's 0.1 s).
int checkEvery(const World& w);

extern bool g_trace;  // setTrace

/// One line of the --trace output (every 0.1 s of simulated time): the first robot's base pose and
/// attitude, its driven wheels' load, its tracks' speeds, the turret's angle and the front gripper
/// tip's height.
void traceLine(World& w);

/// Step `w` for `seconds`, calling `check` every checkEvery(w) steps (~0.05 s); stop when it returns true.
template <typename F>
void runFor(World& w, double seconds, F check) {
  const int every = checkEvery(w);
  const int trace_every = std::max(1, static_cast<int>(std::lround(0.1 / w.config().step)));
  const int steps = static_cast<int>(std::ceil(seconds / w.config().step));
  for (int s = 0; s < steps; ++s) {
    w.step();
    if (g_trace && (s + 1) % trace_every == 0) traceLine(w);
    if ((s + 1) % every == 0 && check()) return;
  }
}

/// A box whose top face is a ramp of `angle` (rising along +x for angle > 0, falling for < 0)
/// starting at `foot` (the top face's edge at x = foot.x, height foot.z), `length` along the slope.
BoxObstacle ramp(const Vec3& foot, double angle, double length, const std::string& name);

/// Adds a block standing on the floor over [x0, x1], `top` high; none if top <= 0.
void addBlock(std::vector<BoxObstacle>& boxes, double x0, double x1, double top, const std::string& name);

/// Holds every servo joint that is neither a track, the turret nor the side arm at its spawn position.
void holdServos(Robot& r);

/// A robot of `d` at `p`, its servos held (holdServos).
Robot& spawn(World& w, const RobotDescription& d, const Pose2D& p);

}  // namespace detail
}  // namespace validation
}  // namespace sbot
