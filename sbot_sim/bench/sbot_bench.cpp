// sbot_bench: how fast the headless core simulates swarms. Not a test: it prints figures.
//
//   sbot_bench [--level simple] [--robots 1,10,100] [--seconds 20] [--step 0.01]
//
// For every robot count it runs, in a fresh child process (so peak memory is that run's own), a
// swarm doing a random walk on a flat arena, and prints the real-time multiplier RTM (simulated s
// per wall s), the wall time per step and the peak resident memory.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world.h"

namespace {

struct Options {
  std::string level = "simple";
  std::vector<int> robots{1, 10, 100};
  double seconds = 20;
  double step = 0;  // 0: the level's recommended step
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) { std::fprintf(stderr, "sbot_bench: %s needs a value\n", a.c_str()); std::exit(2); }
      return argv[++i];
    };
    if (a == "--level") o.level = next();
    else if (a == "--seconds") o.seconds = std::atof(next().c_str());
    else if (a == "--step") o.step = std::atof(next().c_str());
    else if (a == "--robots") {
      o.robots.clear();
      std::stringstream ss(next());
      for (std::string n; std::getline(ss, n, ',');) o.robots.push_back(std::atoi(n.c_str()));
    } else {
      std::fprintf(stderr, "usage: sbot_bench [--level L] [--robots 1,10,100] [--seconds S] [--step DT]\n");
      std::exit(a == "--help" ? 0 : 2);
    }
  }
  return o;
}

void runOne(const Options& o, int n) {
  const sbot::RobotDescription& d = sbot::loadLevel(o.level);
  sbot::WorldConfig c;
  c.step = o.step > 0 ? o.step : d.recommended_step;
  c.gravity = d.gravity;
  c.seed = 1;
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  const double spacing = 0.3;
  const double arena = side * spacing + 1.0;
  for (int k = 0; k < 4; ++k) {
    const double o2 = arena / 2;
    const bool ns = k < 2;
    c.terrain.boxes.push_back({"wall", sbot::Vec3(ns ? 0 : (k == 2 ? o2 : -o2), ns ? (k == 0 ? o2 : -o2) : 0, 0.05),
                               ns ? sbot::Vec3(arena, 0.02, 0.1) : sbot::Vec3(0.02, arena, 0.1), 0, 0, "wall"});
  }
  sbot::World w(c);
  for (int i = 0; i < n; ++i) {
    w.addRobot(d, {(i % side - (side - 1) / 2.0) * spacing, (i / side - (side - 1) / 2.0) * spacing, 0.7 * i},
               "sbot_" + std::to_string(i));
  }
  const int steps = static_cast<int>(o.seconds / c.step);
  const int change_every = static_cast<int>(1.0 / c.step);  // new random command every simulated second
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 0; s < steps; ++s) {
    if (s % change_every == 0) {
      for (sbot::Robot* r : w.robots()) {
        r->setSpeed(static_cast<int>(r->random().uniform("walk", -70, 70)),
                    static_cast<int>(r->random().uniform("walk", -70, 70)));
      }
    }
    w.step();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%-8s %7d %10.1f %12.1f %14.3f %12.1f\n", o.level.c_str(), n, w.time(), w.time() / wall,
              1000.0 * wall / steps, ru.ru_maxrss / 1024.0);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::printf("sbot_bench: headless core, flat arena, random walk, 1 core per run\n");
  std::printf("%-8s %7s %10s %12s %14s %12s\n", "level", "robots", "sim_s", "RTM", "wall_ms/step", "peak_MiB");
  std::fflush(stdout);
  int failures = 0;
  for (int n : o.robots) {
    const pid_t pid = fork();
    if (pid == 0) {
      try {
        runOne(o, n);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "sbot_bench: %s\n", e.what());
        std::_Exit(1);
      }
      std::_Exit(0);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    failures += !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  return failures == 0 ? 0 : 1;
}
