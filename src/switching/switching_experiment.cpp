// switching_experiment: seed 4.3 "navigation on composite terrain using dynamic model switching",
// headless on the core library. One s-bot drives the route of a composite course (three gaps, a
// slope, two rugged areas) N times with the Detailed model only and N times with dynamic model
// switching (Basic on flat ground, Medium / Detailed where the terrain ahead needs it:
// sbot::swarm::LevelPolicy), and compares wall time and final positions.
//
//   switching_experiment [--scenario config/scenarios/composite_course_switching.yaml]
//                        [--route <scenario>.route.yaml] [--runs 10] [--out DIR]
//                        [--modes detailed,switching]   (any level name: that level only) [--jobs 2]
//                        [--small-gap-max 0.032] [--lookahead 0.14] [--demote-delay 0.3]
//
// Each mode runs in its own child process (--jobs 2: both at once; --jobs 1: one after the other),
// so a mode's timing is that process's alone. Run k of either mode uses world seed 1000 + k and the
// same start-pose jitter (+-5 mm, +-1 deg). Output in DIR:
//   <mode>_run<k>.csv    t, x, y, z, yaw, level     (10 Hz)
//   <mode>_summary.csv   one line per run: reached, sim time, wall and CPU time, final x/y, switches,
//                        sim seconds per level
//   summary.txt          the comparison (also printed): wall/CPU time ratio, final-position error
// Plot: /usr/bin/python3 src/switching/plot_paths.py DIR  (seed Fig. 4.8 as DIR/paths.png).
//
// Driver: waypoint following on ground truth (60 units forward, slowing to 20 into a corner, heading
// gain, turning on the spot beyond 0.6 rad; commands change by at most 8 units per 0.1 s). A run ends when the robot passes the last waypoint's perpendicular line
// (reached if within goal_radius of it laterally), when it has not progressed 2 cm in 10 s
// (stuck: e.g. fell into a gap), when it tilts beyond 80 deg (toppled) or at time_limit. The front
// gripper module (core/actuators/gripper.h) holds the gripper arm level in both modes.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "course_run.h"
#include "sbot_sim/tools/cli_args.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/swarm/level_policy.h"
#include "sbot_sim/core/world.h"

#ifndef SWARMBOT3D_SOURCE_DIR
#define SWARMBOT3D_SOURCE_DIR "."
#endif

namespace {

using namespace switching;

struct Options {
  std::string scenario = std::string(SWARMBOT3D_SOURCE_DIR) + "/config/scenarios/composite_course_switching.yaml";
  std::string route;
  std::string out = "switching_results";
  int runs = 10;
  int jobs = 2;
  std::vector<std::string> modes{"detailed", "switching"};
  CourseRunConfig course;  // the policy's settings (defaults and why: see there); path_csv set per run
};

void runMode(const Options& o, const std::string& mode) {
  const sbot::Scenario sc = sbot::loadScenario(o.scenario);
  const Route route = loadRoute(o.route);
  sbot::OutputFile sum(o.out + "/" + mode + "_summary.csv");
  sum << "run,reached,end,sim_s,wall_s,cpu_s,final_x,final_y,switches,basic_s,medium_s,detailed_s\n";
  for (int k = 0; k < o.runs; ++k) {
    CourseRunConfig rc = o.course;
    rc.path_csv = o.out + "/" + mode + "_run" + std::to_string(k) + ".csv";
    const RunResult r = runCourse(rc, sc, route, mode, k);
    auto lt = [&](const char* l) { auto it = r.level_time.find(l); return it == r.level_time.end() ? 0.0 : it->second; };
    sum << r.run << "," << (r.reached ? 1 : 0) << "," << r.end << "," << r.sim << "," << r.wall << "," << r.cpu << ","
        << r.x << "," << r.y << "," << r.switches << "," << lt("basic") << "," << lt("medium") << ","
        << lt("detailed") << "\n";
    sum.flush();
    std::printf("%-9s run %d: %-5s sim %.1f s wall %.2f s cpu %.2f s final (%.4f, %.4f) switches %d "
                "[basic %.1f s, medium %.1f s, detailed %.1f s]\n",
                mode.c_str(), k, r.reached ? "goal" : r.end.c_str(), r.sim, r.wall, r.cpu, r.x, r.y, r.switches,
                lt("basic"), lt("medium"), lt("detailed"));
    std::fflush(stdout);
  }
  sum.commit();
}

struct ModeStats {
  int runs = 0, reached = 0;
  double wall = 0, cpu = 0, sim = 0;
  std::vector<double> x, y;
};

ModeStats readSummary(const std::string& file) {
  ModeStats s;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
    if (f.size() < 8) continue;
    ++s.runs;
    s.reached += std::stoi(f[1]);
    s.sim += std::stod(f[3]);
    s.wall += std::stod(f[4]);
    s.cpu += std::stod(f[5]);
    s.x.push_back(std::stod(f[6]));
    s.y.push_back(std::stod(f[7]));
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  sbot_tools::ArgReader args("switching_experiment", argc, argv);
  while (args.more()) {
    const std::string a = args.option();
    if (a == "--scenario") o.scenario = args.value();
    else if (a == "--route") o.route = args.value();
    else if (a == "--runs") o.runs = args.count(1, 1000);
    else if (a == "--out") o.out = args.value();
    else if (a == "--jobs") o.jobs = args.count(1, 64);
    else if (a == "--small-gap-max") o.course.small_gap_max = args.number(0, 1);
    else if (a == "--lookahead") o.course.lookahead = args.number(0.01, 10);
    else if (a == "--demote-delay") o.course.demote_delay = args.number(0, 1000);
    else if (a == "--modes") {
      o.modes.clear();
      std::stringstream ss(args.value());
      for (std::string m; std::getline(ss, m, ',');) o.modes.push_back(m);
    } else {
      std::fprintf(stderr, "usage: switching_experiment [--scenario F] [--route F] [--runs N] [--out DIR] "
                           "[--modes detailed,switching] [--jobs 2] [--small-gap-max M] [--lookahead M] "
                           "[--demote-delay S]\n");
      return a == "--help" ? 0 : 2;
    }
  }
  // Before any run: an unknown mode found in the fork loop would leave the modes before it running.
  const auto& levels = sbot::modelLevels();
  for (const auto& mode : o.modes) {
    if (mode == "switching" || std::find(levels.begin(), levels.end(), mode) != levels.end()) continue;
    std::string known = "switching";
    for (const auto& l : levels) known += ", " + l;
    std::fprintf(stderr, "switching_experiment: --modes: unknown mode '%s' (modes: %s)\n", mode.c_str(), known.c_str());
    return 2;
  }
  if (o.modes.empty()) {
    std::fprintf(stderr, "switching_experiment: --modes: no mode given\n");
    return 2;
  }
  if (o.route.empty()) {
    o.route = o.scenario;
    const auto dot = o.route.rfind(".yaml");
    o.route = (dot == std::string::npos ? o.route : o.route.substr(0, dot)) + ".route.yaml";
  }
  sbot_tools::requireOutputDirectory("switching_experiment", "--out", o.out);  // before any run
  try {
    sbot::loadScenario(o.scenario);
    loadRoute(o.route);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "switching_experiment: %s\n", e.what());
    return sbot_tools::kExitBadInput;
  }
  // One child process per mode; at most `jobs` at a time. Exit statuses: sbot_sim/tools/cli_args.h.
  std::vector<std::pair<pid_t, std::string>> running;
  int exit_status = sbot_tools::kExitDone;
  const auto wait_for = [&](const std::pair<pid_t, std::string>& run) {
    int status = 0;
    waitpid(run.first, &status, 0);
    exit_status = sbot_tools::worseExit(
        exit_status, sbot_tools::workerOutcome("switching_experiment", "the run of mode " + run.second, status));
  };
  for (const auto& mode : o.modes) {
    if (static_cast<int>(running.size()) >= std::max(1, o.jobs)) {
      wait_for(running.front());
      running.erase(running.begin());
    }
    const pid_t pid = fork();
    if (pid == 0) {
      try {
        runMode(o, mode);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "switching_experiment (%s): %s\n", mode.c_str(), e.what());
        _exit(1);
      }
      _exit(0);
    }
    running.emplace_back(pid, mode);
  }
  for (const auto& run : running) wait_for(run);
  if (exit_status != sbot_tools::kExitDone) return exit_status;

  std::ostringstream rep;
  std::map<std::string, ModeStats> st;
  for (const auto& mode : o.modes) st[mode] = readSummary(o.out + "/" + mode + "_summary.csv");
  for (const auto& [mode, s] : st) {
    char line[256];
    std::snprintf(line, sizeof(line), "%-9s: %d runs, %d reached the goal, sim %.1f s, wall %.2f s, CPU %.2f s "
                  "(RTM %.2f)\n", mode.c_str(), s.runs, s.reached, s.sim, s.wall, s.cpu, s.wall > 0 ? s.sim / s.wall : 0);
    rep << line;
  }
  if (st.count("detailed") && st.count("switching") && st["detailed"].runs && st["switching"].runs) {
    const ModeStats& d = st["detailed"];
    const ModeStats& w = st["switching"];
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < d.x.size(); ++i) { mx += d.x[i]; my += d.y[i]; }
    mx /= d.x.size();
    my /= d.y.size();
    double spread = 0, worst = 0, mean_err = 0;
    for (std::size_t i = 0; i < d.x.size(); ++i) spread = std::max(spread, std::hypot(d.x[i] - mx, d.y[i] - my));
    for (std::size_t i = 0; i < w.x.size(); ++i) {
      const double e = std::hypot(w.x[i] - mx, w.y[i] - my);
      worst = std::max(worst, e);
      mean_err += e / w.x.size();
    }
    double sx = 0, sy = 0;
    for (std::size_t i = 0; i < w.x.size(); ++i) { sx += w.x[i] / w.x.size(); sy += w.y[i] / w.y.size(); }
    char line[1024];
    std::snprintf(line, sizeof(line),
                  "wall time  detailed / switching = %.2f / %.2f s = %.2fx less\n"
                  "CPU time   detailed / switching = %.2f / %.2f s = %.2fx less (bar: >= 4x, on CPU time: other "
                  "processes do not inflate it)\n"
                  "final position: detailed mean (%.4f, %.4f), spread (max distance to its mean) %.4f m;\n"
                  "  switching mean (%.4f, %.4f): %.4f m from the detailed mean; switched runs' distance to the\n"
                  "  detailed mean: mean %.4f m, worst %.4f m (bar: <= max(0.05, detailed spread) = %.4f m)\n"
                  "switched runs reaching the goal: %d of %d\n",
                  d.wall, w.wall, w.wall > 0 ? d.wall / w.wall : 0, d.cpu, w.cpu, w.cpu > 0 ? d.cpu / w.cpu : 0, mx, my,
                  spread, sx, sy, std::hypot(sx - mx, sy - my), mean_err, worst, std::max(0.05, spread), w.reached,
                  w.runs);
    rep << line;
  }
  std::printf("%s", rep.str().c_str());
  try {
    sbot::writeTextFile(o.out + "/summary.txt", rep.str());
  } catch (const std::exception& e) {  // the summary is on stdout above
    std::fprintf(stderr, "switching_experiment: the summary was not saved (it is printed above): %s\n", e.what());
    return 2;
  }
  return 0;
}
