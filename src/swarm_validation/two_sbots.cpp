// two_sbots: the seed's two-connected-s-bot validation rows, headless on the core library.
//
//   Table 4.1 (4.1.1) two s-bots connected by the front gripper of the second on a slope: the pair
//     stands 3 s (motors holding) and then climbs 8 s at 2.8 cm/s. Seed: 'limit full' (full
//     manoeuvrability) at 29 deg, 'limit stable' (limit of stable position) at 58-72 deg.
//   4.1.3 two s-bots connected by the front gripper go backwards up a 32 mm step: the first (the
//     holder, nearest the step) lifts itself with its gripper arm (elevation downward) when its rear
//     reaches the step, drives onto it and pulls the second over (raising the arm to lift it). A
//     single s-bot going backwards topples / fails at 32 mm.
//
//   two_sbots [--level detailed] [--trials 3] [--angles 10,20,...] [--steps 0.015,0.024,0.032]
//             [--seed-friction]   (slope rows with the seed's force-limited 1.2 N friction, see
//                                  two_sbots_trials.h; the step rows are unaffected)
//             [--track-mu MU]     (slope rows with Coulomb treels of coefficient MU instead of the
//                                  polystyrene's 2.0, validation::kPolystyreneTrackMu)
//             [--rear-uphill]     (slope rows facing downhill, climbing in reverse)
//
// The connection is the static front-gripper link (core/swarm/swarm_graph.h createStaticLink: fixed
// joint, gripper_tip to the held robot's turret, 0.147 m apart); the holder's arm is driven by the
// front gripper module (core/actuators/gripper.h) where the level has one. Step phases use ground
// truth (the seed's robot used its rear ground sensor to detect the step).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "experiments.h"
#include "two_sbots_trials.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/tools/cli_args.h"

namespace {

using namespace two_sbots;

/// A comma-separated list of numbers in [min, max] for `option`.
std::vector<double> parseList(const std::string& option, const std::string& s, double min, double max) {
  std::vector<double> v;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');) v.push_back(sbot_tools::numberArg("two_sbots", option, x, min, max));
  if (v.empty()) sbot_tools::numberArg("two_sbots", option, "", min, max);  // refuses the empty list
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  if (!sbot::validation::studyKnobsOk("two_sbots")) return 2;
  std::string level = "detailed";
  int trials = 3;
  std::vector<double> angles{10, 20, 25, 29, 32, 35, 40, 45, 50, 55, 58, 65, 72};
  std::vector<double> steps{0.015, 0.024, 0.032};
  bool verbose = false;
  SlopeSetup setup;
  sbot_tools::ArgReader args("two_sbots", argc, argv);
  while (args.more()) {
    const std::string a = args.option();
    if (a == "--level") level = args.value();
    else if (a == "--trials") trials = args.count(1, 1000);
    else if (a == "--angles") angles = parseList(a, args.value(), 0, 90);    // [deg]
    else if (a == "--steps") steps = parseList(a, args.value(), 0, 0.2);     // [m]
    else if (a == "--verbose") verbose = true;
    else if (a == "--seed-friction") setup.seed_friction = true;
    else if (a == "--rear-uphill") setup.rear_uphill = true;
    else if (a == "--track-mu") setup.track_mu = args.number(1e-6, 100);
    else {
      std::fprintf(stderr, "usage: two_sbots [--level L] [--trials N] [--angles deg,...] [--steps m,...] [--verbose] "
                           "[--seed-friction | --track-mu MU] [--rear-uphill]\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (setup.seed_friction && setup.track_mu > 0) {
    std::fprintf(stderr, "two_sbots: --seed-friction and --track-mu choose the friction law two ways; give one\n");
    return 2;
  }
  sbot_tools::requireLevel("two_sbots", "--level " + level + " (or $SBOT_DESCRIPTION_DIR)", level);  // the default too
  const std::string friction = setup.seed_friction ? "seed (force limit 1.2 N per contact)"
                               : "Coulomb (treels mu " + std::to_string(setup.track_mu > 0 ? setup.track_mu : sbot::validation::kPolystyreneTrackMu).substr(0, 4) + ")";
  std::printf("two_sbots: level %s, %d trials per cell, friction %s, %s\n\n", level.c_str(), trials, friction.c_str(),
              setup.rear_uphill ? "rear uphill (climbing in reverse)" : "front uphill");
  std::printf("Table 4.1 slope (stand 3 s, climb 8 s at 2.8 cm/s); label per trial (slide [mm], climb efficiency)\n");
  std::printf("%6s  %-60s %-60s\n", "deg", "single s-bot", "two s-bots connected");
  std::vector<std::string> modal[2];  // per slope: single s-bot, pair
  for (double deg : angles) {
    std::string cells[2];
    for (int pair = 0; pair < 2; ++pair) {
      std::vector<sbot::validation::Outcome> trial_labels;
      for (int k = 0; k < trials; ++k) {
        SlopeSetup s = setup;
        s.pair = pair == 1;
        const SlopeResult r = pairSlope(level, deg * M_PI / 180, k, s);
        char buf[96];
        std::snprintf(buf, sizeof(buf), "%s(%.0f,%.2f) ", r.label.c_str(), r.slide * 1000, r.efficiency);
        cells[pair] += buf;
        trial_labels.push_back({r.label});
      }
      modal[pair].push_back(sbot::validation::modal(trial_labels));
    }
    std::printf("%6.0f  %-60s %-60s\n", deg, cells[0].c_str(), cells[1].c_str());
    std::fflush(stdout);
  }
  const SlopeLimits single = slopeLimits(angles, modal[0]), two = slopeLimits(angles, modal[1]);
  std::printf("\ntwo s-bots connected (modal of %d): limit of full manoeuvrability %.0f deg (seed 29); standing "
              "without sliding (> 1 cm in 3 s) up to %.0f deg; upright up to %.0f deg%s (seed 'limit of stable "
              "position' 58-72 deg); a single s-bot upright up to %.0f deg\n\n",
              trials, two.full, two.hold, two.upright, two.topple > 0 ? "" : " (never toppled)", single.upright);

  std::printf("4.1.3 step, going backwards (40 s limit)\n");
  for (double h : steps) {
    for (int pair = 0; pair < 2; ++pair) {
      std::string line;
      for (int k = 0; k < trials; ++k) {
        const StepResult r = stepBackward(level, h, k, pair == 1, verbose && pair == 1);
        char buf[128];
        std::snprintf(buf, sizeof(buf), "%s(x %.2f z %.3f%s) ", r.label.c_str(), r.x_holder, r.z_holder,
                      pair ? ("; held x " + std::to_string(r.x_held).substr(0, 5)).c_str() : "");
        line += buf;
      }
      std::printf("  %2.0f mm %-22s %s\n", h * 1000, pair ? "two s-bots connected" : "single s-bot", line.c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}
