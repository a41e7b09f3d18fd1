// One run of the seed 4.3 composite-course experiment (switching_experiment, its gtest): an s-bot
// drives the route of a course scenario, either at one fixed level or with dynamic model switching
// (sbot::swarm::LevelPolicy on the terrain ahead). See switching_experiment.cpp for the driver.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/types.h"

namespace switching {

struct Route {
  std::vector<sbot::Vec3> waypoints;
  double goal_radius = 0.05;
  double time_limit = 120;
};

struct CourseRunConfig {
  double small_gap_max = 0.04;   ///< [m] LevelPolicyConfig::small_gap_max (our Medium stalls at 45 mm)
  double lookahead = -1;         ///< [m] < 0: LevelPolicyConfig default
  double demote_delay = -1;      ///< [s] < 0: LevelPolicyConfig default
  double policy_rate = 5;        ///< [Hz] decisions
  std::string path_csv;          ///< t, x, y, z, yaw, level at 10 Hz; empty = none
};

struct RunResult {
  int run = 0;
  bool reached = false;
  double sim = 0, wall = 0, cpu = 0;
  double x = 0, y = 0;
  int switches = 0;
  std::map<std::string, double> level_time;
  std::string end;
};

/// Waypoints, goal radius and time limit from a `<scenario>.route.yaml`.
Route loadRoute(const std::string& path);
/// Run `k` (world seed 1000 + k, start jitter from k) in `mode`: "switching" or a level name.
RunResult runCourse(const CourseRunConfig& config, const sbot::Scenario& scenario, const Route& route,
                    const std::string& mode, int k);
/// CPU time of this process [s].
double cpuSeconds();

}  // namespace switching
