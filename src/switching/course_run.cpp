#include "course_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <random>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/actuators/gripper.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/swarm/level_policy.h"
#include "sbot_sim/core/world.h"
#include "sbot_sim/core/yaml_checks.h"

namespace switching {

namespace {
double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }
}  // namespace

double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

Route loadRoute(const std::string& path) {
  const auto refuse = [&](const std::string& field, const std::string& what) {
    throw std::runtime_error(path + (field.empty() ? "" : ": field '" + field + "'") + ": " + what);
  };
  YAML::Node n;
  try {
    n = YAML::Load(sbot::readInputFile(path, "route file"));
  } catch (const sbot::ConfigError& e) {
    refuse("", e.what());
  } catch (const YAML::Exception& e) {
    refuse("", "not valid YAML (line " + std::to_string(e.mark.line + 1) + "): " + e.msg);
  }
  if (const std::string problem = sbot::yamlStructureProblem(n); !problem.empty()) refuse("", problem);
  if (!n.IsMap()) refuse("", "expected a mapping with waypoints, goal_radius, time_limit");
  for (const auto& kv : n) {
    const std::string key = kv.first.as<std::string>();
    if (key != "waypoints" && key != "goal_radius" && key != "time_limit")
      refuse(key, "unknown field (expected waypoints, goal_radius, time_limit)");
  }
  const auto number = [&](const YAML::Node& v, const std::string& field) {
    double x = 0;
    try {
      x = v.as<double>();
    } catch (const YAML::Exception&) {
      refuse(field, "expected a number");
    }
    if (!std::isfinite(x)) refuse(field, "must be finite");
    return x;
  };
  Route r;
  const YAML::Node w = n["waypoints"];
  if (!w || !w.IsSequence()) refuse("waypoints", "expected a list of [x, y] in m");
  for (std::size_t i = 0; i < w.size(); ++i) {
    const std::string field = "waypoints[" + std::to_string(i) + "]";
    if (!w[i].IsSequence() || w[i].size() != 2) refuse(field, "expected [x, y] in m");
    r.waypoints.emplace_back(number(w[i][0], field), number(w[i][1], field), 0);
  }
  if (r.waypoints.size() < 2) refuse("waypoints", "needs at least two waypoints");
  if (n["goal_radius"]) r.goal_radius = number(n["goal_radius"], "goal_radius");
  if (n["time_limit"]) r.time_limit = number(n["time_limit"], "time_limit");
  if (!(r.goal_radius > 0)) refuse("goal_radius", "must be > 0 m");
  if (!(r.time_limit > 0) || r.time_limit > 3600) refuse("time_limit", "must be in (0, 3600] s");
  return r;
}

RunResult runCourse(const CourseRunConfig& o, const sbot::Scenario& sc, const Route& route, const std::string& mode,
                    int k) {
  sbot::WorldConfig wc = sc.world;
  wc.seed = 1000 + k;
  std::mt19937 rng(k);
  std::uniform_real_distribution<double> jitter(-1, 1);
  const sbot::RobotSpawn& spawn = sc.robots.at(0);
  sbot::Pose2D start{spawn.pose.x + 0.005 * jitter(rng), spawn.pose.y + 0.005 * jitter(rng),
                     spawn.pose.yaw + jitter(rng) * M_PI / 180};
  const bool switching = mode == "switching";
  sbot::swarm::LevelPolicyConfig pc;
  pc.small_gap_max = o.small_gap_max;
  if (o.lookahead > 0) pc.lookahead = o.lookahead;
  if (o.demote_delay >= 0) pc.demote_delay = o.demote_delay;
  sbot::swarm::LevelPolicy policy(pc);

  RunResult res;
  res.run = k;
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = cpuSeconds();

  sbot::World world(wc);
  sbot::swarm::HeightCache cache([&world](double x, double y) { return world.terrainHeight(x, y); });
  const sbot::swarm::HeightFunction height = cache.function();
  std::string level = switching ? policy.decide(spawn.name, 0, height, start) : mode;
  sbot::Robot& robot = world.addRobot(sbot::loadLevel(level), start, spawn.name);
  // The front gripper module holds the arm level (Basic/Medium sticky box, Detailed arm and jaws
  // are on hinges that are otherwise passive). Its type follows the level: re-created at a switch.
  auto gripper = std::make_unique<sbot::actuators::FrontGripper>(world, robot);
  gripper->setElevation(0);

  std::unique_ptr<sbot::OutputFile> path;  // the run's path log, when asked for
  if (!o.path_csv.empty()) {
    path = std::make_unique<sbot::OutputFile>(o.path_csv);
    *path << "t,x,y,z,yaw,level\n";
  }
  const double dt = wc.step;
  const int control_every = std::max(1, static_cast<int>(std::round(0.1 / dt)));
  const int policy_every = std::max(1, static_cast<int>(std::round(1.0 / (o.policy_rate * dt))));
  std::size_t wp = 0;
  int cmd_left = 0, cmd_right = 0;
  sbot::Vec3 progress_pos = robot.basePose().position;
  double progress_t = 0;
  for (long s = 0;; ++s) {
    const double t = world.time();
    const sbot::Pose p = robot.basePose();
    const double yaw = p.yaw();
    if (s % policy_every == 0 && switching) {
      const std::string want = policy.decide(spawn.name, t, height, {p.position.x(), p.position.y(), yaw});
      if (want != level) {
        world.switchLevel(spawn.name, sbot::loadLevel(want));
        gripper = std::make_unique<sbot::actuators::FrontGripper>(world, robot);
        gripper->setElevation(0);
        level = want;
        ++res.switches;
      }
    }
    if (s % control_every == 0) {
      if (path) *path << t << "," << p.position.x() << "," << p.position.y() << "," << p.position.z() << "," << yaw << ","
                      << level << "\n";
      // Finished? Past the last waypoint's perpendicular line.
      const sbot::Vec3 a = route.waypoints[route.waypoints.size() - 2], b = route.waypoints.back();
      const sbot::Vec3 pos(p.position.x(), p.position.y(), 0);
      const sbot::Vec3 dir = (b - a).normalized();
      if (wp >= route.waypoints.size() - 1 && (pos - b).dot(dir) >= 0) {
        const double lateral = (pos - b - (pos - b).dot(dir) * dir).norm();
        res.reached = lateral <= route.goal_radius;
        res.end = res.reached ? "goal" : "passed the goal line off target";
        break;
      }
      if (t - progress_t >= 10.0) {
        if ((pos - progress_pos).norm() < 0.02) {
          res.end = "stuck";
          break;
        }
        progress_t = t;
        progress_pos = pos;
      }
      if (t >= route.time_limit) {
        res.end = "time limit";
        break;
      }
      // Intermediate waypoints are passed within 6 cm.
      while (wp < route.waypoints.size() - 1 && (route.waypoints[wp] - pos).norm() < 0.06) ++wp;
      const sbot::Vec3 target = route.waypoints[wp];
      const double e = wrap(std::atan2(target.y() - pos.y(), target.x() - pos.x()) - yaw);
      int left, right;
      if (std::abs(e) > 0.6) {
        left = e > 0 ? -20 : 20;
        right = -left;
      } else {
        // Slow down into a corner waypoint (the last one is a line to cross at full speed).
        const double dist = (target - pos).norm();
        const double v = wp + 1 < route.waypoints.size() ? std::max(20.0, std::min(60.0, 300.0 * (dist - 0.03))) : 60.0;
        const int turn = static_cast<int>(std::lround(std::max(-25.0, std::min(25.0, 60.0 * e))));
        left = static_cast<int>(v) - turn;
        right = static_cast<int>(v) + turn;
      }
      // Acceleration limit: at most 8 units (2.2 cm/s) per 0.1 s. An s-bot reversing a track at
      // full speed pitches over (the motors are far stronger than the traction).
      auto ramp = [](int target, int current) { return std::max(current - 8, std::min(current + 8, target)); };
      cmd_left = ramp(left, cmd_left);
      cmd_right = ramp(right, cmd_right);
      robot.setSpeed(cmd_left, cmd_right);
    }
    world.step();
    gripper->update(dt);
    res.level_time[level] += dt;
    const sbot::Vec3 up = robot.basePose().orientation * sbot::Vec3::UnitZ();
    if (up.z() < std::cos(80 * M_PI / 180)) {
      res.end = "toppled";
      break;
    }
  }
  res.sim = world.time();
  res.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  res.cpu = cpuSeconds() - cpu0;
  const sbot::Pose f = robot.basePose();
  res.x = f.position.x();
  res.y = f.position.y();
  if (path) path->commit();
  return res;
}

}  // namespace switching
