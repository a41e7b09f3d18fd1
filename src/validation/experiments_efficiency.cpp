// The efficiency trials (Table 4.4): real-time multiplier, step cost, steady speed, spin rate, a
// connected pair.
#include "experiments.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sbot_sim/core/world.h"

#include "experiments_internal.h"

namespace sbot {
namespace validation {

using namespace detail;

// ---- Table 4.4: efficiency ------------------------------------------------------------------------

namespace {

volatile unsigned g_sensor_sink = 0;

/// Table 4.4's workload: one s-bot of `level` on flat ground, a new random setSpeed every simulated
/// second, and (with_sensors) the proximity ring, ground and light sensors read every step, as the
/// seed's controllers do. Returns the wall time [s]; `sensor_s` (optional) gets the sensors' share.
double randomWalk(World& w, Robot& r, double sim_seconds, bool with_sensors, double* sensor_s = nullptr) {
  using Clock = std::chrono::steady_clock;
  sensors::Environment env(w);
  sensors::SensorSuite suite(w, r, env);
  const bool ground = suite.available(sensors::SensorChannel::Ground);
  const bool light = suite.available(sensors::SensorChannel::Light);
  const double dt = w.config().step;
  const int steps = static_cast<int>(sim_seconds / dt);
  const int change_every = std::max(1, static_cast<int>(1.0 / dt));
  unsigned sink = 0;
  double sensing = 0;
  const auto t0 = Clock::now();
  for (int i = 0; i < steps; ++i) {
    if (i % change_every == 0) {
      r.setSpeed(static_cast<int>(r.random().uniform("walk", -70, 70)),
                 static_cast<int>(r.random().uniform("walk", -70, 70)));
    }
    w.step();
    if (!with_sensors) continue;
    const auto s0 = sensor_s ? Clock::now() : Clock::time_point();
    suite.update(dt);
    for (unsigned v : suite.getAllProximitySensors()) sink += v;
    if (ground) for (unsigned v : suite.getAllGroundSensors()) sink += v;
    if (light) for (unsigned v : suite.getAllLightSensors()) sink += v;
    if (sensor_s) sensing += std::chrono::duration<double>(Clock::now() - s0).count();
  }
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  if (sensor_s) *sensor_s = sensing;
  g_sensor_sink = sink;  // keeps the reads from being optimised away
  return wall;
}

}  // namespace

Outcome rtmTrial(const std::string& level, double sim_seconds, bool with_sensors) {
  const RobotDescription& d = loadLevel(level);
  World w(configFor(d, 7));
  Robot& r = spawn(w, d, {0, 0, 0});
  const double wall = randomWalk(w, r, sim_seconds, with_sensors);
  Outcome o{"ok"};
  o.value = w.time() / wall;
  o.value2 = 1000.0 * wall / static_cast<double>(w.stepCount());
  return o;
}

StepCost profileTrial(const std::string& level, double sim_seconds) {
  const RobotDescription& d = loadLevel(level);
  World w(configFor(d, 7));
  Robot& r = spawn(w, d, {0, 0, 0});
  w.stepN(static_cast<int>(0.5 / w.config().step));  // settle; not profiled
  w.enableProfile(true);
  const double t_sim0 = w.time();
  double sensing = 0;
  const double wall = randomWalk(w, r, sim_seconds, true, &sensing);
  const World::StepProfile& p = w.profile();
  StepCost c;
  c.rtm = (w.time() - t_sim0) / wall;
  c.wall_us_per_step = 1e6 * wall / static_cast<double>(p.steps);
  c.commands = p.commands_s / wall;
  c.collision = p.collision_s / wall;
  c.solver = p.solver_s / wall;
  c.feedback = p.feedback_s / wall;
  c.sensors = sensing / wall;
  c.contacts_per_step = static_cast<double>(p.contacts) / static_cast<double>(p.steps);
  c.bodies = static_cast<int>(r.bodyCount());
  c.iterations = w.solverIterations();
  c.step_s = w.config().step;
  return c;
}

Outcome steadySpeedTrial(const std::string& level, int units) {
  const RobotDescription& d = loadLevel(level);
  WorldConfig c = configFor(d, 8);
  World w(c);
  Robot& r = spawn(w, d, {0, 0, 0});
  r.setSpeed(units, units);
  runFor(w, 3.0, [] { return false; });
  const Vec3 a = r.basePose().position;
  runFor(w, 3.0, [] { return false; });
  const Vec3 b = r.basePose().position;
  Outcome o{"ok"};
  o.value = (b - a).head<2>().norm() / 3.0;
  return o;
}

Outcome spinRateTrial(const std::string& level, int units) {
  const RobotDescription& d = loadLevel(level);
  World w(configFor(d, 8));
  Robot& r = spawn(w, d, {0, 0, 0});
  r.setSpeed(units, -units);
  runFor(w, 1.0, [] { return false; });  // past the acceleration phase
  constexpr double kSpan = 3.0;           // [s] measured
  double turned = 0, last = headingOf(r);
  const int n = static_cast<int>(std::lround(kSpan / w.config().step));
  for (int i = 0; i < n; ++i) {
    w.step();
    turned += std::remainder(headingOf(r) - last, 2 * M_PI);
    last = headingOf(r);
  }
  Outcome o{"ok"};
  o.value = -turned / kSpan;  // left forward, right back: clockwise, negative yaw
  o.value2 = 2 * units * d.treels.speed_unit / r.trackWidth();
  return o;
}

Outcome connectedPairTrial(const std::string& level) {
  const RobotDescription& d = loadLevel(level);
  WorldConfig c = configFor(d, 9);
  World w(c);
  Robot& holder = w.addRobot(d, {0, 0, 0}, "holder");
  Robot& held = w.addRobot(d, {0.3 * lengthScale(level), 0, 0}, "held");
  holdServos(holder);
  holdServos(held);
  swarm::createStaticLink(w, {"holder", "held", swarm::kFrontGripper});
  auto distance = [&] { return (held.basePose().position - holder.basePose().position).head<2>().norm(); };
  runFor(w, 1.0, [] { return false; });
  Outcome o{"ok"};
  o.value = distance();
  holder.setSpeed(-30, -30);
  held.setSpeed(-30, -30);
  runFor(w, 2.0, [] { return false; });
  o.value2 = distance();
  return o;
}

}  // namespace validation
}  // namespace sbot
