// sbot_bench: how fast the headless core simulates swarms. Not a test: it prints figures.
//
//   sbot_bench [--level simple] [--robots 1,10,100] [--seconds 20] [--step 0.01] [--chains K] [--idle] [--sensors] [--profile]
//   sbot_bench --scenario FILE [--robots N,...] [--seconds 20] [--idle] [--sensors] [--profile]
//
// --chains K: the robots form chains of K connected by static front-gripper links (robot i+1 grips
// robot i; core/swarm/swarm_graph.h), each chain driving one random-walk command, and the swarm graph
// (computeSwarmGraph, as /swarm/graph) is computed at 10 Hz; its cost is part of the timing.
// --scenario FILE: your own world instead of the flat arena: the scenario's terrain, robots, static
// links and effects (core/scenario_world.h, as the simulator node builds it), every robot on the same
// random walk; --robots then overrides its swarm.count, one row per number. Its step and levels are
// the scenario's (--level, --step and --chains are refused with it).
// --idle: the robots stand (setSpeed(0, 0)) instead of walking. They get 3 simulated seconds,
// untimed, to settle and fall asleep (sleeping at rest, on unless the scenario's world turns it
// off); then --seconds are timed, and the row says how many are asleep at the end.
// --sensors: every robot's LED ring lit (red) and, at the simulator node's default 10 Hz, every
// robot's sensors read as a controller subscribed to all of them would: the proximity ring, ground
// and light sensors where its level has them, and the fake camera's blobs (each lit LED group of
// another robot in range costs a line of sight, so this part grows with the square of the robots).
// The row says how many blobs a camera saw on average; --profile gives the sensors' share.
// --profile: also print where the step time goes (World::enableProfile): solver, collision
// detection, motor commands, feedback, and the contact joints per step.
//
// For every robot count it runs, in a fresh child process (so peak memory is that run's own), a
// swarm doing a random walk on a flat arena, and prints the real-time multiplier RTM (simulated s
// per wall s), the wall time per step and the peak resident memory.
//
// Exit status (sbot_sim/tools/cli_args.h): 2 when an option or the scenario is refused, before the
// table header (every robot the file lists is checked, and every world a row will build is built
// once, in a child); 1 when a row's run fails; 3 when a row's run crashed (killed by a signal, named).
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"  // kMaxRobots
#include "sbot_sim/core/scenario_world.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sbot_sim/core/world.h"
#include "sbot_sim/tools/cli_args.h"
#include "sbot_sim/tools/machine.h"

namespace {

struct Options {
  std::string level = "simple";
  std::vector<int> robots{1, 10, 100};
  double seconds = 20;
  double step = 0;  // 0: the level's recommended step
  int chains = 0;   // robots per chain, 0 = unconnected
  bool profile = false;
  bool idle = false;  // stand instead of the random walk (after an untimed settling)
  bool sensors = false;  // lit LEDs, every robot's sensors and fake camera read at 10 Hz
  std::string scenario;  // a scenario file instead of the arena ("": the arena)
  bool robots_given = false;
};

constexpr const char* kUsage =
    "usage: sbot_bench [--level L] [--robots 1,10,100] [--seconds S] [--step DT] [--chains K] [--idle] [--sensors] "
    "[--profile]\n"
    "       sbot_bench --scenario FILE [--robots N,...] [--seconds S] [--idle] [--sensors] [--profile]\n";

Options parse(int argc, char** argv) {
  // Values are checked (atoi/atof turned "--robots 0" or "--seconds -1" into a row of nonsense).
  Options o;
  bool arena_options = false;  // --level, --step or --chains: options of the arena only
  sbot_tools::ArgReader args("sbot_bench", argc, argv);
  while (args.more()) {
    const std::string a = args.option();
    arena_options = arena_options || a == "--level" || a == "--step" || a == "--chains";
    if (a == "--scenario") o.scenario = args.value();
    else if (a == "--level") o.level = args.value();
    else if (a == "--seconds") o.seconds = args.number(0.001, 1e6);
    else if (a == "--step") o.step = args.number(sbot::kMinStep, sbot::kMaxStep);
    else if (a == "--chains") o.chains = args.count(0, sbot::kMaxRobots);
    else if (a == "--profile") o.profile = true;
    else if (a == "--idle") o.idle = true;
    else if (a == "--sensors") o.sensors = true;
    else if (a == "--robots") {
      o.robots_given = true;
      o.robots.clear();
      std::stringstream ss(args.value());
      for (std::string n; std::getline(ss, n, ',');)
        o.robots.push_back(sbot_tools::countArg("sbot_bench", "--robots", n, 1, sbot::kMaxRobots));
    } else {
      std::fprintf(stderr, "%s", kUsage);
      std::exit(a == "--help" ? 0 : 2);
    }
  }
  if (!o.scenario.empty() && arena_options) {
    std::fprintf(stderr, "sbot_bench: --level, --step and --chains set up the flat arena; with --scenario the scenario "
                         "sets its levels, step and links\n%s", kUsage);
    std::exit(2);
  }
  if (!o.scenario.empty() && !o.robots_given) o.robots = {-1};  // the scenario's own robots
  return o;
}

/// The flat walled arena with `n` robots of --level on a grid, or in chains of --chains.
std::unique_ptr<sbot::World> arenaWorld(const Options& o, int n) {
  const sbot::RobotDescription& d = sbot::loadLevel(o.level);
  sbot::WorldConfig c;
  c.step = o.step > 0 ? o.step : d.recommended_step;
  c.gravity = d.gravity;
  c.seed = 1;
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  const double spacing = 0.3;
  const int k = std::max(1, o.chains);
  const int nchains = (n + k - 1) / k;
  const int cside = static_cast<int>(std::ceil(std::sqrt(nchains)));
  const double chain_dx = 0.147 * k + 0.3, chain_dy = 0.35;  // chain cells when --chains
  const double arena = o.chains > 0 ? std::max(cside * chain_dx, cside * chain_dy) + 1.0 : side * spacing + 1.0;
  for (int k = 0; k < 4; ++k) {
    const double o2 = arena / 2;
    const bool ns = k < 2;
    c.terrain.boxes.push_back({"wall", sbot::Vec3(ns ? 0 : (k == 2 ? o2 : -o2), ns ? (k == 0 ? o2 : -o2) : 0, 0.05),
                               ns ? sbot::Vec3(arena, 0.02, 0.1) : sbot::Vec3(0.02, arena, 0.1), 0, 0, "wall"});
  }
  auto world = std::make_unique<sbot::World>(c);
  sbot::World& w = *world;
  for (int i = 0; i < n; ++i) {
    if (o.chains > 0) {
      const int c = i / k, j = i % k;  // chain c, member j (j = 0 leads)
      const double cx = (c % cside - (cside - 1) / 2.0) * chain_dx + 0.147 * (k - 1) / 2.0;
      const double cy = (c / cside - (cside - 1) / 2.0) * chain_dy;
      w.addRobot(d, {cx - 0.147 * j, cy, 0}, "sbot_" + std::to_string(i));
      if (j > 0)
        sbot::swarm::createStaticLink(w, {"sbot_" + std::to_string(i), "sbot_" + std::to_string(i - 1),
                                          sbot::swarm::kFrontGripper});
      continue;
    }
    w.addRobot(d, {(i % side - (side - 1) / 2.0) * spacing, (i / side - (side - 1) / 2.0) * spacing, 0.7 * i},
               "sbot_" + std::to_string(i));
  }
  return world;
}

/// The level column of a row: the robots' level, "mixed", or "none" for a scenario without robots.
std::string levelsOf(sbot::World& w) {
  std::string level = "none";
  for (const sbot::Robot* r : w.robots()) {
    const std::string l = r->description().level;
    if (level != "none" && l != level) return "mixed";
    level = l;
  }
  return level;
}

/// [s] user + system CPU time of this process so far.
double cpuSeconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

volatile unsigned g_sensor_sink = 0;

/// --sensors: every robot's suite over one Environment, its LED ring lit so the cameras see it.
class SwarmSensors {
 public:
  explicit SwarmSensors(sbot::World& w) : env_(w) {
    for (sbot::Robot* r : w.robots()) {
      env_.setSameLightColor(r->name(), sbot::sensors::kLedMaxUnits, 0, 0, 0);
      suites_.push_back(std::make_unique<sbot::sensors::SensorSuite>(w, *r, env_));
    }
  }
  /// Every robot reads what its level has, as a controller subscribed to all its sensors does.
  void readAll(double dt) {
    using sbot::sensors::SensorChannel;
    for (auto& s : suites_) {
      s->update(dt);
      for (unsigned v : s->getAllProximitySensors()) sink_ += v;
      if (s->available(SensorChannel::Ground)) for (unsigned v : s->getAllGroundSensors()) sink_ += v;
      if (s->available(SensorChannel::Light)) for (unsigned v : s->getAllLightSensors()) sink_ += v;
      blobs_ += s->getFakeCameraBlobs().size();
      ++reads_;
    }
  }
  double blobsPerRead() const { return reads_ ? static_cast<double>(blobs_) / static_cast<double>(reads_) : 0; }
  unsigned sink() const { return sink_; }

 private:
  sbot::sensors::Environment env_;
  std::vector<std::unique_ptr<sbot::sensors::SensorSuite>> suites_;
  unsigned sink_ = 0;
  std::size_t blobs_ = 0, reads_ = 0;
};

/// One row: `n` robots (--scenario: its swarm.count overridden, or its own robots for n < 0) on a
/// random walk (or standing, --idle) for --seconds, in this process.
void runOne(const Options& o, int n) {
  const bool scenario = !o.scenario.empty();
  std::unique_ptr<sbot::World> world =
      scenario ? sbot::buildScenarioWorld(sbot::loadScenario(o.scenario, n)) : arenaWorld(o, n);
  sbot::World& w = *world;
  const sbot::WorldConfig& c = w.config();
  const int k = std::max(1, o.chains);
  const bool graph = o.chains > 0 || !w.connections().list().empty();
  const int graph_every = std::max(1, static_cast<int>(std::lround(0.1 / c.step)));  // 10 Hz
  std::size_t components = 0;
  const int steps = static_cast<int>(o.seconds / c.step);
  const int change_every = static_cast<int>(1.0 / c.step);  // new random command every simulated second
  constexpr double kIdleSettle = 3.0;  // [s] standing robots are all asleep well within it (core_test_rest)
  if (o.idle) w.stepN(static_cast<int>(kIdleSettle / c.step));
  std::unique_ptr<SwarmSensors> sensors = o.sensors ? std::make_unique<SwarmSensors>(w) : nullptr;
  const int read_every = std::max(1, static_cast<int>(std::lround(0.1 / c.step)));  // 10 Hz, the node's default
  double sensing_s = 0;
  w.enableProfile(o.profile);
  const double cpu0 = cpuSeconds();  // the settling (--idle) is not timed
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 0; s < steps; ++s) {
    if (!o.idle && s % change_every == 0) {
      const std::vector<sbot::Robot*> robots = w.robots();
      for (std::size_t i = 0; i < robots.size(); ++i) {
        sbot::Robot* r = robots[i];
        if (o.chains > 0 && i % k != 0) continue;  // a chain drives its leader's command
        const int left = static_cast<int>(r->random().uniform("walk", -70, 70));
        const int right = static_cast<int>(r->random().uniform("walk", -70, 70));
        for (std::size_t m = i; m < robots.size() && (m == i || (o.chains > 0 && m % k != 0)); ++m)
          robots[m]->setSpeed(left, right);
      }
    }
    w.step();
    if (graph && s % graph_every == 0) components = sbot::swarm::computeSwarmGraph(w).components;
    if (sensors && s % read_every == 0) {
      const auto r0 = std::chrono::steady_clock::now();
      sensors->readAll(read_every * c.step);
      sensing_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double timed_s = steps * c.step;
  std::printf("%-8s %7zu %10.1f %12.1f %14.3f %12.1f", levelsOf(w).c_str(), w.robotCount(), timed_s, timed_s / wall,
              1000.0 * wall / steps, ru.ru_maxrss / 1024.0);
  if (o.idle) {
    int asleep = 0;
    for (const sbot::Robot* r : w.robots()) asleep += r->asleep();
    std::printf("   idle, %d asleep at the end (after %.0f s untimed to settle)", asleep, kIdleSettle);
  }
  if (sensors) {
    std::printf("   sensors and fake camera read at 10 Hz, LEDs lit, %.1f blobs per camera read", sensors->blobsPerRead());
    g_sensor_sink = sensors->sink();  // keeps the reads from being optimised away
  }
  if (o.chains > 0) {
    // CPU-time RTM too: on a shared machine the wall clock includes waiting for a core.
    const double cpu = cpuSeconds() - cpu0;
    std::printf("   chains of %d, %zu components at the end, RTM by CPU time %.1f", k, components, timed_s / cpu);
  }
  if (o.profile) {
    const sbot::World::StepProfile& p = w.profile();
    std::printf("   solver %.0f %%, collision %.0f %%, commands %.0f %%, feedback %.0f %%, %.1f contacts/step",
                100 * p.solver_s / wall, 100 * p.collision_s / wall, 100 * p.commands_s / wall,
                100 * p.feedback_s / wall, static_cast<double>(p.contacts) / static_cast<double>(p.steps));
    if (sensors) std::printf(", sensors %.0f %%", 100 * sensing_s / wall);
  }
  std::printf("\n");
  std::fflush(stdout);
}

/// Runs `work` in a child process and returns its wait status: the child exits 0, or, when `work`
/// throws, prints `sbot_bench: <prefix><what()>` and exits `refusal`. Each row (and the scenario
/// check) runs in its own process so that its peak memory is its own.
template <typename Work>
int statusOfChild(Work work, const char* prefix, int refusal) {
  const pid_t pid = fork();
  if (pid == 0) {
    try {
      work();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sbot_bench: %s%s\n", prefix, e.what());
      std::_Exit(refusal);
    }
    std::_Exit(0);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  if (o.scenario.empty()) {
    sbot_tools::requireLevel("sbot_bench", "--level", o.level);
    std::printf("sbot_bench: headless core, flat arena, %s%s, 1 core per run\n", o.idle ? "idle" : "random walk",
                o.sensors ? ", sensors" : "");
  } else {
    // Checked here, before any row, so that a malformed file (or a count it cannot take) is refused
    // once with exit status 2: every robot the file lists (also those a --robots count leaves out),
    // and every world a row will build, built in a child so that the rows' peak memory stays their own.
    const int status = statusOfChild(
        [&] {
          sbot::loadScenario(o.scenario, -1);
          for (int n : o.robots) sbot::buildScenarioWorld(sbot::loadScenario(o.scenario, n));
        },
        "--scenario: ", sbot_tools::kExitBadInput);
    if (WIFEXITED(status) && WEXITSTATUS(status) == sbot_tools::kExitBadInput) return sbot_tools::kExitBadInput;
    if (const int outcome = sbot_tools::workerOutcome("sbot_bench", "checking the scenario", status)) return outcome;
    std::printf("sbot_bench: headless core, scenario %s, %s, 1 core per run\n", o.scenario.c_str(),
                o.idle ? "idle" : "random walk");
  }
  // Every figure below depends on the processor: name it (sbot_sim/tools/machine.h).
  std::printf("sbot_bench: machine: %s\n", sbot_tools::describeThisMachine().c_str());
  std::printf("%-8s %7s %10s %12s %14s %12s\n", "level", "robots", "sim_s", "RTM", "wall_ms/step", "peak_MiB");
  std::fflush(stdout);
  int exit_status = sbot_tools::kExitDone;
  for (int n : o.robots) {
    const int status = statusOfChild([&] { runOne(o, n); }, "", sbot_tools::kExitFailure);
    // A run that dies must not leave its row silently missing.
    const std::string what = n < 0 ? std::string("the run of the scenario's robots") : "the run with " + std::to_string(n) + " robots";
    const int outcome = sbot_tools::workerOutcome("sbot_bench", what, status);
    if (outcome != sbot_tools::kExitDone) std::fprintf(stderr, "sbot_bench: no row for %s\n", what.c_str());
    exit_status = sbot_tools::worseExit(exit_status, outcome);
  }
  return exit_status;
}
