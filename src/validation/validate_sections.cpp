// sbot_validate's report sections: the built-in ones (model facts, Table 4.1's two connected
// s-bots, Table 4.4's real-time multiplier, the compatibility check, Figure 4.4) and a reference
// table of the tables file, each run and written as Markdown (validate_report.h).
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "experiments.h"
#include "mismatch_reasons.h"
#include "reference_tables.h"
#include "sbot_sim/tools/cli_args.h"
#include "sbot_sim/tools/machine.h"
#include "two_sbots_trials.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/terrain.h"
#include "sbot_sim/core/world_config.h"

#include "validate_report.h"

namespace sbot_validate_tool {

v::MismatchReasons reasons;
std::vector<std::string> g_error_cells;

/// The statics of the backward step (step_statics.h) for the Detailed model: where it tips, and the
/// centre of mass the hardware's 15 / 16 mm limit would take.
std::string backwardStepStatics() {
  const v::SideView s = v::sideView("detailed");
  const double hardware_tip = 0.0155;  // [m] passes 15 mm, fails 16 mm
  v::SideView needed = s;
  needed.com_x = v::comXForCornerTip(s, hardware_tip);
  const double turret_shift = (s.com_x - needed.com_x) / v::turretMassShare("detailed");
  const auto cm = [](double m) { return fmt(m * 100, 2); };
  const auto deg = [](double rad) { return fmt(rad * 180 / M_PI, 1); };
  std::ostringstream md;
  md << "*Statics of the backward step* (src/validation/step_statics.h). Reversing, the robot stands nose down on "
        "its centre wheels on the step and its front wheels on the floor; when a front wheel reaches the step's "
        "face its support moves to the corner, behind its axle, and the robot tips onto its gripper if its centre "
        "of mass lies ahead of that corner. Ours: the centre of mass "
     << cm(s.com_x) << " cm ahead of the centre axle and " << cm(s.com_z) << " cm above it (measured at rest); it tips "
        "statically from a " << fmt(v::cornerTipHeight(s) * 1000, 1) << " mm step (the trials follow the statics within about 1 mm; "
        "the gtest StepStatics.PredictsWhere... checks it). The hardware's limit (15 mm passes, 16 mm fails) takes the centre of mass at most "
     << cm(needed.com_x) << " cm ahead of the centre axle at the same height: the turret's own COM "
     << cm(std::abs(turret_shift)) << " cm further " << (turret_shift >= 0 ? "back" : "forward")
     << " than ours (Table 2.3: 4 +- 1 cm ahead of the turret axis); or, as far ahead as ours, at most "
     << cm(v::comZForCornerTip(s, hardware_tip)) << " cm above the centre axle instead of " << cm(s.com_z)
     << " (the centre wheels alone are " << cm(2 * s.centre_radius) << " cm high). With the first the rigid static tip "
        "facing downhill rises from " << deg(v::frontTipSlope(s)) << " to " << deg(v::frontTipSlope(needed))
     << " deg (hardware: \"difficult\" at 20 deg and toppling at 30 deg rear uphill; docs/validation.md, "
        "*Step statics*, has the trials with such a centre of mass).\n\n";
  return md.str();
}

/// Line plot (OpenCV) of Figure 4.4: mean and min-max spread per level over log2(HR).
void plotFig44(const std::string& path, const std::vector<double>& hrs,
               const std::map<std::string, std::vector<std::vector<double>>>& data) {
  const int W = 900, H = 600, L = 90, R = 180, T = 50, B = 70;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  double ymax = 1.6, ymin = 0.0;
  for (const auto& [level, cells] : data)
    for (const auto& v : cells)
      for (double d : v) { ymax = std::max(ymax, d); ymin = std::min(ymin, d); }
  ymax = std::ceil(ymax * 5 + 1e-9) / 5;
  ymin = std::floor(ymin * 5 - 1e-9) / 5;
  auto X = [&](int i) { return L + (W - L - R) * (i + 0.5) / hrs.size(); };
  auto Y = [&](double y) { return T + (H - T - B) * (ymax - y) / (ymax - ymin); };
  cv::rectangle(img, cv::Point(L, T), cv::Point(W - R, H - B), cv::Scalar(0, 0, 0), 1);
  for (int k = 0; ymin + 0.2 * k <= ymax + 1e-9; ++k) {
    const double y = std::round((ymin + 0.2 * k) * 10) / 10 + 0.0;  // + 0.0: no "-0.0" label
    cv::line(img, cv::Point(L, Y(y)), cv::Point(W - R, Y(y)), cv::Scalar(220, 220, 220), 1);
    cv::putText(img, fmt(y, 1), cv::Point(L - 45, Y(y) + 5), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1);
  }
  for (std::size_t i = 0; i < hrs.size(); ++i)
    cv::putText(img, fmt(hrs[i], 0), cv::Point(X(i) - 8, H - B + 22), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1);
  cv::putText(img, "height range HR [cm]", cv::Point(W / 2 - 120, H - 20), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1);
  cv::putText(img, "Fig. 4.4: distance projected on the initial heading after 10 s at 15.24 cm/s [m]",
              cv::Point(L - 60, 30), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1);
  const std::map<std::string, cv::Scalar> colour{{"fast", cv::Scalar(40, 160, 40)}, {"simple", cv::Scalar(200, 120, 0)},
                                                 {"medium", cv::Scalar(0, 140, 255)}, {"detailed", cv::Scalar(0, 0, 200)}};
  int li = 0;
  for (const auto& level : kLevels) {
    auto it = data.find(level);
    if (it == data.end()) continue;
    const cv::Scalar col = colour.at(level);
    const int off = (li - 1.5) * 6;
    cv::Point prev(-1, -1);
    for (std::size_t i = 0; i < hrs.size() && i < it->second.size(); ++i) {
      const auto& v = it->second[i];
      if (v.empty()) continue;
      double mean = 0, lo = 1e9, hi = -1e9;
      for (double d : v) { mean += d; lo = std::min(lo, d); hi = std::max(hi, d); }
      mean /= v.size();
      const cv::Point p(X(i) + off, Y(mean));
      cv::line(img, cv::Point(p.x, Y(lo)), cv::Point(p.x, Y(hi)), col, 1);
      cv::line(img, cv::Point(p.x - 4, Y(lo)), cv::Point(p.x + 4, Y(lo)), col, 1);
      cv::line(img, cv::Point(p.x - 4, Y(hi)), cv::Point(p.x + 4, Y(hi)), col, 1);
      cv::circle(img, p, 4, col, cv::FILLED);
      if (prev.x >= 0) cv::line(img, prev, p, col, 2);
      prev = p;
    }
    cv::line(img, cv::Point(W - R + 20, T + 20 + 25 * li), cv::Point(W - R + 50, T + 20 + 25 * li), col, 2);
    cv::putText(img, level, cv::Point(W - R + 58, T + 25 + 25 * li), cv::FONT_HERSHEY_SIMPLEX, 0.5, col, 1);
    ++li;
  }
  cv::putText(img, "dots: mean", cv::Point(W - R + 20, T + 140), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1);
  cv::putText(img, "bars: min-max", cv::Point(W - R + 20, T + 158), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1);
  if (!cv::imwrite(path, img)) throw sbot::OutputError("cannot write '" + path + "'");
}

/// Table 4.4's "what limits it": the step time of one s-bot per level split by phase
/// (World::enableProfile, sensors timed around their reads), measured by measureRtm.
void writeProfile(std::ostream& md, const std::map<std::string, v::StepCost>& profile) {
  md << "### What limits it: where one step's time goes\n\n"
     << "The same workload, timed by phase (`World::enableProfile`; sensors timed around their reads; "
        "the rest is the loop and the clock reads), " << kRtmRepeats << " runs per level taken in turns with the "
        "RTM runs above, of which the table shows the one whose solver was fastest. collision = broad and narrow phase and the contact "
        "joints built; solver = ODE's quickstep over bodies, joints and contacts; commands = motors and "
        "effects; feedback = wheel loads and torque windows.\n\n"
     << "| level | bodies | contacts per step | solver iterations | us per step | solver | collision | sensors | "
        "commands | feedback | RTM (profiling) | solver alone: RTM ceiling | target |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  auto pct = [](double f) { return fmt(100 * f, 0) + " %"; };
  for (const auto& level : kLevels) {
    if (!profile.count(level)) {  // every profiled run of it failed (sbot_validate said why on stderr)
      md << "| " << level << " | error | | | | | | | | | | | " << rtmTarget(level) << " |\n";
      continue;
    }
    const v::StepCost& c = profile.at(level);
    md << "| " << level << " | " << c.bodies << " | " << fmt(c.contacts_per_step, 1) << " | " << c.iterations << " | "
       << fmt(c.wall_us_per_step, 1) << " | " << pct(c.solver) << " | " << pct(c.collision) << " | " << pct(c.sensors)
       << " | " << pct(c.commands) << " | " << pct(c.feedback) << " | " << fmt(c.rtm, 0) << " | "
       << fmt(c.solverAloneRtm(), 0) << " | " << rtmTarget(level) << " |\n";
  }
  md << "\nThe ceiling is the level's step divided by the solver's wall time per step: the RTM this machine "
        "would reach if sensors, collision detection, commands and feedback took no time. Where it is below "
        "the target, only a cheaper solve (fewer rows or iterations, a faster CPU) can reach the target.\n\n";
}

std::string findHeightmap() {
  const char* env = std::getenv("SBOT_HEIGHTMAP");
  if (env) return env;
#ifdef SWARMBOT3D_SOURCE_DIR
  return std::string(SWARMBOT3D_SOURCE_DIR) + "/config/scenarios/heightmaps/rough_128.png";
#else
  return "";
#endif
}

/// `path` as the report shows it: relative to the package when it lies inside it (the default
/// heightmap), so that a committed report names no machine's build directory.
std::string shownPath(const std::string& path) {
#ifdef SWARMBOT3D_SOURCE_DIR
  const std::string package = std::string(SWARMBOT3D_SOURCE_DIR) + "/";
  if (path.compare(0, package.size(), package) == 0) return path.substr(package.size());
#endif
  return path;
}

/// Progress on stderr, with the seconds since the start.
const std::chrono::steady_clock::time_point g_start = std::chrono::steady_clock::now();
void progress(const std::string& s) {
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - g_start).count();
  std::fflush(stdout);  // the report on stdout first, so that 2>&1 does not cut it with this line
  std::fprintf(stderr, "[sbot_validate %6.0fs] %s\n", t, s.c_str());
}

// ---- built-in sections ---------------------------------------------------------------------------

void writeFacts(std::ostream& md, const Options& o) {
  md << "## Model facts (rest on flat ground, 2 s)\n\n";
  for (const auto& level : kAllLevels) {
    auto r = v::runParallel(1, 1, [&](int) { return Outcome{v::restFacts(level)}; });
    md << "- " << r[0].label << "\n";
  }
  md << "\nStatic tipping angle (servos holding, gravity tilted 1 deg/s until the robot tilts 45 deg off "
        "the slope's normal; rear uphill = it tips over its front, where the turret's forward COM offset puts "
        "the centre of mass; \"slides\": before tipping, it slid 1 cm within a second without tilting). Quickstep's compliance lowers it; 200 "
        "iterations are the converged reference.\n\n"
     << "| level | rear uphill | front uphill | rear uphill, 200 iterations | front uphill, 200 iterations |\n"
        "|---|---|---|---|---|\n";
  for (const auto& level : kAllLevels) {
    auto r = v::runParallel(4, o.jobs, [&](int i) { return v::tippingAngle(level, i % 2 == 0, i < 2 ? 0 : 200); });
    auto deg = [](const Outcome& x) {
      if (failed(x)) return std::string("error");
      if (x.value2 < x.value) return "slides from " + fmt(x.value2, 1) + " deg";
      return x.label == "tipped" ? fmt(x.value, 1) + " deg" : std::string("> 90 deg");
    };
    md << "| " << level << " | " << deg(r[0]) << " | " << deg(r[1]) << " | " << deg(r[2]) << " | " << deg(r[3]) << " |\n";
  }
  md << "\n";
}

/// Table 4.1's two connected s-bots and 4.1.3's two-robot step: limits over a grid of slopes and a
/// procedure of two robots, not cells of one trial kind. Tallies in `hw`.
void writePairRows(std::ostream& md, const Options& o, Tally& hw) {
  progress("Table 4.1: two connected s-bots; 4.1.3 two-robot step (Detailed)");
  const std::vector<double> deg{25, 29, 32, 35, 40, 45, 50, 55, 58, 65, 72};
  // Both friction laws: ours (Coulomb treels on the polystyrene, creeping as everywhere) and the
  // seed's own set-up for this experiment (4.1.1: force limit 1.2 N per contact). See two_sbots_trials.h.
  struct Limits : two_sbots::SlopeLimits {
    std::string detail;
  };
  auto limitsFor = [&](bool seed_friction) {
    auto res = v::runParallel(static_cast<int>(deg.size()) * o.trials, o.jobs, [&](int i) {
      two_sbots::SlopeSetup setup;
      setup.seed_friction = seed_friction;
      const two_sbots::SlopeResult r = two_sbots::pairSlope("detailed", deg[i / o.trials] * M_PI / 180, i % o.trials, setup);
      Outcome out{r.label};
      out.value = r.slide;
      out.value2 = r.efficiency;
      return out;
    });
    std::vector<std::string> modal;
    std::string detail;
    for (std::size_t k = 0; k < deg.size(); ++k) {
      std::vector<Outcome> c(res.begin() + k * o.trials, res.begin() + (k + 1) * o.trials);
      modal.push_back(v::modal(c));
      detail += fmt(deg[k], 0) + " deg: " + summary(c) + "; ";
    }
    return Limits{two_sbots::slopeLimits(deg, modal), detail};
  };
  const Limits ours = limitsFor(false), seed = limitsFor(true);
  auto stableText = [&](const Limits& l) {
    return l.topple > 0 ? fmt(l.upright, 0) + " deg (topples at " + fmt(l.topple, 0) + ", holds without sliding to " +
                              fmt(l.hold, 0) + ")"
                        : "no topple up to " + fmt(deg.back(), 0) + " deg (holds without sliding to " + fmt(l.hold, 0) +
                              ", slides beyond)";
  };
  auto fullOk = [](const Limits& l) { return std::abs(l.full - 29) <= 3; };
  auto stableOk = [](const Limits& l) { return l.topple > 0 && l.upright >= 58 && l.topple <= 72; };
  const bool full_ok = fullOk(ours), stable_ok = stableOk(ours);
  md << "## Table 4.1 - two s-bots connected by the front gripper (Detailed)\n\n"
     << "The holder below grips the robot above it (static front-gripper link, arm level); tilted gravity; "
        "stand 3 s, then climb 8 s at 2.8 cm/s. **Limit of full manoeuvrability**: the steepest slope up to "
        "which the modal label is full (holds, climbs at >= 85 % without rearing); match within 3 deg "
        "(the grid). **Limit of stable position**: the steepest slope on which the pair does not topple; "
        "match if it lies in the seed's 58-72 deg (upright at >= 58, toppling at <= 72). Two friction laws: "
        "ours (Coulomb treels on the seed's polystyrene, mu " << fmt(v::kPolystyreneTrackMu, 1) << ", with the "
        "treels' creep as everywhere; tallied) and the seed's own set-up for this experiment (4.1.1: force "
        "limit 1.2 N per contact point; shown, not tallied).\n\n"
     << "| row | hardware | seed sim | ours (Coulomb mu " << fmt(v::kPolystyreneTrackMu, 1)
     << ") | match | ours (seed friction 1.2 N) | match |\n"
     << "|---|---|---|---|---|---|---|\n"
     << "| limit of full manoeuvrability | 29 deg | 29 deg | " << fmt(ours.full, 0) << " deg | " << mark(kPairFullKey, full_ok, hw)
     << " | " << fmt(seed.full, 0) << " deg | " << (fullOk(seed) ? "match" : "mismatch") << " |\n"
     << "| limit of stable position | 58-72 deg | 58-72 deg | " << stableText(ours) << " | " << mark(kPairStableKey, stable_ok, hw)
     << " | " << stableText(seed) << " | " << (stableOk(seed) ? "match" : "mismatch") << " |\n\n"
     << reasons.explainPending() << "Per slope, Coulomb: " << ours.detail << "\n\nPer slope, seed friction: " << seed.detail << "\n\n"
     << "What separates the two rows is the treels' creep (`treels.creep_stiffness`, sbot_parameters.yaml): "
        "a driven track slips back by the slip ratio (F/N) / C of its speed, so the climb efficiency falls "
        "with the slope (the per-slope efficiencies above), while standing tracks do not creep and the pair "
        "stands to its friction and tipping limits. C was calibrated on the first row (5.3-6.0 all give "
        "29 deg); the polystyrene's mu on the second (tan 58 deg = 1.6 at least; 1.8-2.2 stand upright at "
        "58 deg). Without creep the pair climbed fully to 40 deg on mu 1.0 (which slides from 45 deg); the "
        "seed's force limit lets it climb fully far above 29 deg.\n\n";

  // 4.1.3: two robots reverse up a 32 mm step; one alone topples.
  const double h = 0.032;
  auto steps = v::runParallel(2 * o.trials, o.jobs, [&](int i) {
    const two_sbots::StepResult r = two_sbots::stepBackward("detailed", h, i % o.trials, i >= o.trials, false);
    return Outcome{r.label};
  });
  const std::vector<Outcome> single(steps.begin(), steps.begin() + o.trials), pair(steps.begin() + o.trials, steps.end());
  const ModalCell ms = modalCell("topple", single), mp = modalCell("pass", pair);
  const bool single_ok = ms.ok, pair_ok = mp.ok;
  md << "## 4.1.3 - two-robot step passing, going backwards (Detailed)\n\n"
     << "A 32 mm step on Table 4.3's lab floor (treels mu " << fmt(v::kLabFloorTrackMu, 3) << "); the holder nearest "
        "the step raises its gripper arm 20 deg when its rear reaches the step (braced on the held robot, it tips "
        "forward about its front wheels and its rear rises onto the step), levels it and reverses on, then raises it "
        "to 50 deg to pull the held robot over (phases from ground truth here; the same procedure driven by the "
        "robots' own sensors through sbot.h is sbot_controllers/src/step_climbing.c, rostest "
        "test/two_sbots_step.test, on the simulator's default floor).\n\n"
     << "| step | robots | real s-bots | seed sim | ours | match |\n|---|---|---|---|---|---|\n"
     << "| 32 mm | single s-bot | topple | topple | " << ms.text << " (" << summary(single) << ") | " << mark(kPairStepSingleKey, single_ok, hw)
     << " |\n"
     << "| 32 mm | two connected | pass | pass | " << mp.text << " (" << summary(pair) << ") | " << mark(kPairStepTwoKey, pair_ok, hw)
     << " |\n\n" << reasons.explainPending();
}

RtmRuns measureRtm(const Options& o) {
  RtmRuns runs;
  auto& fastest = runs.fastest;
  auto& slowest = runs.slowest;
  auto& load = runs.load;
  progress("Table 4.4: real-time multiplier");
  getloadavg(load, 3);
  runs.machine = sbot_tools::describeThisMachine();
  // One run at a time (the trials time themselves), the fastest kept. The repeats go round the
  // levels, so each level's runs are spread over the whole measurement (the VM's slow spells last
  // up to a minute: back-to-back repeats fell into the same one).
  for (const auto& level : kLevels) fastest[level] = {v::Outcome{"error"}, v::Outcome{"error"}};
  for (int k = 0; k < kRtmRepeats; ++k) {
    for (const auto& level : kLevels) {
      const double secs = level == "fast" ? 3000 : (level == "detailed" ? 60 : 300);
      for (bool with_sensors : {true, false}) {
        const v::Outcome run = v::runParallel(
            1, 1, [&](int) { return v::rtmTrial(level, o.quick ? secs / 3 : secs, with_sensors); })[0];
        v::Outcome& best = fastest[level][with_sensors ? 0 : 1];
        if (!failed(run) && (failed(best) || run.value > best.value)) best = run;
        if (with_sensors && !failed(run) && (!slowest.count(level) || run.value < slowest[level])) slowest[level] = run.value;
      }
      // Profiled in turn with the RTM runs and as long, so that the ceiling samples the same machine
      // states (shorter profiles, in this process, read up to 40 % slower than the runs beside them).
      try {  // in this process: a failing profile must not take the other sections with it
        const v::StepCost c = v::profileTrial(level, o.quick ? secs / 3 : secs);
        if (!runs.profile.count(level) || c.solverAloneRtm() > runs.profile[level].solverAloneRtm()) runs.profile[level] = c;
      } catch (const std::exception& e) {
        progress("Table 4.4: profiling " + level + " failed: " + e.what());
      }
    }
  }
  return runs;
}

void writeRtm(std::ostream& md, const Options& o, const RtmRuns& runs) {
  const auto& fastest = runs.fastest;
  const auto& slowest = runs.slowest;
  const auto& load = runs.load;
  md << "## Table 4.4 - efficiency (RTM, one s-bot, flat ground, its level's sensors read every step)\n\n"
     << "Measured before the suite's other experiments, one process at a time (the seed: dual 3.06 GHz Xeon). "
        "Target: 10x the seed. A random "
        "walk (new setSpeed every simulated second); sensors: the whole proximity ring every step, plus "
        "ground and light sensors where the level has them (SensorSuite). The last column is the same "
        "run without any sensor reads. Each RTM is the best of " << kRtmRepeats << " runs, taken in turns with the "
        "other levels' (another process on the machine can only slow a run down, and this VM's slow spells "
        "last up to a minute); the slowest of the " << kRtmRepeats << " shows how steady the machine was. Machine: " << runs.machine
     << " (RTMs scale with the processor: other machines' figures are in "
        "docs/benchmarks.md); load average when measured: " << fmt(load[0])
     << " (above ~1, other processes share the CPU and these RTMs are pessimistic).\n\n"
     << "| level | step | solver iterations | seed RTM | target (10x) | ours RTM | slowest run | wall ms/step | target met | physics only RTM |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& level : kLevels) {
    const v::Outcome& r = fastest.at(level)[0];
    const v::Outcome& p = fastest.at(level)[1];
    const double target = rtmTarget(level);
    const int needs = sbot::loadLevel(level).solver_iterations;  // 0: the world default
    const std::string it = needs > 0 ? std::to_string(needs) : std::to_string(sbot::WorldConfig().solver_iterations) + " (default)";
    md << "| " << level << " | " << sbot::loadLevel(level).recommended_step * 1000 << " ms | " << it << " | " << kSeedRtm.at(level)
       << " | " << target << " | " << number(r, r.value, 0) << " | "
       << (slowest.count(level) ? fmt(slowest.at(level), 0) : std::string("error")) << " | " << number(r, r.value2, 4) << " | "
       << (failed(r) ? "error" : r.value >= target ? "yes" : "**no**") << " | " << number(p, p.value, 0) << " |\n";
  }
  md << "\n";
  writeProfile(md, runs.profile);
}

/// Seed 2.1.3: the levels are compatible when the same command gives the same steady speed (the
/// issue's band: within 3 % of the Detailed model) and two connected s-bots stand the same distance
/// apart (the Fast model at its half scale). Every level of the file's vocabulary, Basic too.
void writeCompat(std::ostream& md, const Options& o) {
  progress("2.1.3: steady speed, connected pair and spin rate per level");
  constexpr double kBand = 0.03;  // the compatibility band, relative to Detailed
  const int n = static_cast<int>(kAllLevels.size());
  constexpr int kSpinUnits = 30;
  auto r = v::runParallel(3 * n, o.jobs, [&](int i) {
    if (i < n) return v::steadySpeedTrial(kAllLevels[i], 50);
    if (i < 2 * n) return v::connectedPairTrial(kAllLevels[i - n]);
    return v::spinRateTrial(kAllLevels[i - 2 * n], kSpinUnits);
  });
  const int ref = static_cast<int>(std::find(kAllLevels.begin(), kAllLevels.end(), "detailed") - kAllLevels.begin());
  md << "## Compatibility (seed 2.1.3)\n\n"
     << "Steady speed at setSpeed(50,50) = 14.0 cm/s on flat ground, and two s-bots of the level connected by "
        "the front gripper (static link): their centre-to-centre distance standing 1 s and after reversing "
        "together 2 s at 30 units; the half-size Fast pair is also shown at full scale. Compatible: speed within "
        "3 % of the Detailed model's, and the same distance.\n\n"
     << "| level | speed [cm/s] | vs Detailed | speed within 3 % | pair distance [cm], standing / reversing | "
        "at full scale | vs Detailed |\n|---|---|---|---|---|---|---|\n";
  for (int i = 0; i < n; ++i) {
    const Outcome& speed = r[i];
    const Outcome& pair = r[n + i];
    const double scale = v::lengthScale(kAllLevels[i]);
    const bool speed_known = !failed(speed) && !failed(r[ref]);
    const double rel = speed_known ? speed.value / r[ref].value - 1 : 0;
    md << "| " << kAllLevels[i] << " | " << number(speed, speed.value * 100, 2) << " | "
       << (speed_known ? percent(rel) : "error") << " | "
       << (speed_known ? (std::abs(rel) <= kBand ? "yes" : "**no**") : "error") << " | "
       << number(pair, pair.value * 100, 2) << " / " << number(pair, pair.value2 * 100, 2) << " | "
       << number(pair, pair.value2 / scale * 100, 2) << " | "
       << (failed(pair) || failed(r[n + ref]) ? "error" : percent(pair.value2 / scale / r[n + ref].value2 - 1))
       << " |\n";
  }
  md << "\nTurning, shown and not a criterion (the issue's band is on speed; 2.1.3 asks for \"a similar "
        "behaviour when a particular robot command is issued\"): spin rate on the spot at setSpeed("
     << kSpinUnits << ", -" << kSpinUnits << "), 3 s after 1 s, beside 2 v / b, the rate of the centre wheels "
        "rolling without slip (b = `Robot::trackWidth`, what cmd_vel assumes). Below 100 %, the wheels skid: "
        "Medium's and Detailed's front and rear wheels, 4 cm ahead of and behind the centre ones, are dragged "
        "sideways in a spin, and how much they hold back depends on their contacts. vs Detailed: the Fast "
        "robot's rate at full scale (halved).\n\n"
     << "| level | spin rate [rad/s] | 2 v / b [rad/s] | of 2 v / b | vs Detailed |\n|---|---|---|---|---|\n";
  for (int i = 0; i < n; ++i) {
    const Outcome& spin = r[2 * n + i];
    const Outcome& ref_spin = r[2 * n + ref];
    md << "| " << kAllLevels[i] << " | " << number(spin, spin.value, 2) << " | " << number(spin, spin.value2, 2)
       << " | " << (failed(spin) ? "error" : fmt(100 * spin.value / spin.value2, 0) + " %") << " | "
       << (failed(spin) || failed(ref_spin) ? "error"
                                            : percent(spin.value * v::lengthScale(kAllLevels[i]) / ref_spin.value - 1))
       << " |\n";
  }
  md << "\n";
}

/// Figure 4.4 against what the seed says of it (4.2.2, a figure without numbers: shown, not
/// tallied). A level holds its course at an HR while its mean distance is at least 90 % of its own
/// at HR 1; "minimally rough" is HR 2-4. `data[level][h]`: the distances of every run at hrs[h].
void writeFig44Reading(std::ostream& md, const std::vector<double>& hrs,
                       const std::map<std::string, std::vector<std::vector<double>>>& data, int runs) {
  struct Stats { double mean = 0, sd = 0; bool ok = false; };
  auto stats = [&](const std::string& level, std::size_t h) {
    Stats s;
    const auto it = data.find(level);
    if (it == data.end() || h >= it->second.size()) return s;
    const std::vector<double>& v = it->second[h];
    if (v.size() < static_cast<std::size_t>(runs) || v.empty()) return s;
    for (double d : v) s.mean += d / v.size();
    for (double d : v) s.sd += (d - s.mean) * (d - s.mean) / std::max<std::size_t>(1, v.size() - 1);
    s.sd = std::sqrt(s.sd);
    s.ok = true;
    return s;
  };
  constexpr double kHeld = 0.9, kMinimallyRough = 4, kFollowMargin = 0.05;  // [-], [cm HR], [m]
  md << "\nAgainst the seed's reading (4.2.2: \"the rough terrain motion of the Medium model closely follows "
        "the behaviour of the Detailed s-bot model\"; \"both Simple and Fast models quickly fail to retain "
        "linear motion even on minimally rough terrains\"; a figure without numbers, so shown, not tallied). "
        "A level holds its course at an HR while its mean distance is at least 90 % of its own at HR 1; "
        "minimally rough is HR 2-4; Medium follows Detailed where their means differ by at most the larger "
        "spread plus 5 cm.\n\n| level | holds its course up to | the seed says | match |\n|---|---|---|---|\n";
  for (const std::string& level : kLevels) {
    const Stats flat = stats(level, 0);
    double held = 0;  // the last HR of the unbroken run from HR 1
    bool complete = flat.ok;
    for (std::size_t h = 0; h < hrs.size() && complete; ++h) {
      const Stats s = stats(level, h);
      if (!s.ok) { complete = false; break; }
      if (s.mean < kHeld * flat.mean) break;
      held = hrs[h];
    }
    const std::string holds = !complete ? "error in a run" : held >= hrs.back() ? "HR " + fmt(hrs.back(), 0) + " (all)"
                                                                              : "HR " + fmt(held, 0);
    std::string says, match;
    if (level == "fast" || level == "simple") {
      says = "loses it on minimally rough terrain";
      match = !complete ? "error" : reasons.record(fig44Key(level), held < kMinimallyRough);
    } else if (level == "medium") {
      says = "follows the Detailed model";
      std::string apart;
      for (std::size_t h = 0; h < hrs.size(); ++h) {
        const Stats m = stats("medium", h), d = stats("detailed", h);
        if (!m.ok || !d.ok) { apart = "error"; break; }
        if (std::fabs(m.mean - d.mean) > std::max(m.sd, d.sd) + kFollowMargin)
          apart += (apart.empty() ? "" : ", ") + ("HR " + fmt(hrs[h], 0));
      }
      match = apart == "error" ? "error" : reasons.record(fig44Key(level), apart.empty()) + (apart.empty() ? "" : " (apart at " + apart + ")");
    } else {
      says = "replicates the real robot (the reference)";
      match = "-";
    }
    md << "| " << level << " | " << holds << " | " << says << " | " << match << " |\n";
  }
  md << "\n" << reasons.explainPending();
}

void writeFig44(std::ostream& md, const Options& o) {
  progress("Figure 4.4: rough terrain");
  const std::vector<double> hrs{1, 2, 4, 8, 16, 32};
  const int runs = o.rough_runs;
  auto res = v::runParallel(static_cast<int>(kLevels.size() * hrs.size()) * runs, o.jobs, [&](int i) {
    const int cell = i / runs;
    return v::roughTrial(kLevels[cell / hrs.size()], hrs[cell % hrs.size()], i % runs, o.heightmap);
  });
  std::map<std::string, std::vector<std::vector<double>>> data;
  md << "## Figure 4.4 - straight motion on rough terrain\n\n"
     << "Random heading, and a random start from which the ideal path stays 15 cm inside the height field, "
        "on a 5 x 5 m height field (Fast: 2.5 x 2.5 m and half the height range, "
        "as the seed halves its terrain) from `" << shownPath(o.heightmap) << "`, 10 s at 15.24 cm/s; distance projected "
        "on the initial heading (ideal 1.52 m). HR is the terrain's height range in cm (the seed's simulator "
        "worked in CGS units: its tables give lengths in cm, forces in dyne; HR 1 'almost flat' to 32 'very "
        "rough', 4.2.2). " << runs << " runs per point.\n\n"
     << "![Figure 4.4](fig4_4.png)\n\n| level | HR 1 | HR 2 | HR 4 | HR 8 | HR 16 | HR 32 |\n|---|---|---|---|---|---|---|\n";
  for (std::size_t l = 0; l < kLevels.size(); ++l) {
    md << "| " << kLevels[l];
    for (std::size_t h = 0; h < hrs.size(); ++h) {
      std::vector<double> v;
      const int cell = l * hrs.size() + h;
      for (int t = 0; t < runs; ++t)
        if (res[cell * runs + t].label != "error") v.push_back(res[cell * runs + t].value);
      if (v.size() < static_cast<std::size_t>(runs)) {  // a failed run has no distance: say so, never 0
        md << " | error in " << runs - v.size() << " of " << runs << " runs";
        data[kLevels[l]].push_back(v);
        continue;
      }
      double mean = 0, sd = 0;
      for (double d : v) mean += d / v.size();
      for (double d : v) sd += (d - mean) * (d - mean) / std::max<std::size_t>(1, v.size() - 1);
      md << " | " << fmt(mean) << " +- " << fmt(std::sqrt(sd));
      data[kLevels[l]].push_back(v);
    }
    md << " |\n";
  }
  try {  // the numbers above are the result; a plot that cannot be saved is said, not fatal
    plotFig44(o.out + "/fig4_4.png", hrs, data);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sbot_validate: Figure 4.4's plot: %s\n", e.what());
    md << "\n(The plot could not be saved: " << e.what() << ".)\n";
  }
  writeFig44Reading(md, hrs, data, runs);
}

/// The paragraphs a table can name under `after`.
std::string builtInParagraph(const std::string& name) {
  if (name == "backward_step_statics") return backwardStepStatics();
  throw std::logic_error("no built-in paragraph '" + name + "'");  // the loader refuses such names
}

// ---- a reference table ---------------------------------------------------------------------------

/// Runs every cell of `t` (and its companion experiment) o.trials times and writes the table: the
/// references, our modal label with the distribution, match / mismatch (tallied in the table's
/// group), the companion's modal label and the mean measured value where the table asks for them.
void writeTable(std::ostream& md, const v::ReferenceTable& t, const Options& o, std::map<std::string, Tally>& tallies) {
  progress(t.title);
  const int cells = static_cast<int>(t.cells.size());
  const int kinds = t.companion.empty() ? 1 : 2;  // run 0: the cells' experiments, run 1: the companion
  const std::vector<Outcome> res = v::runParallel(kinds * cells * o.trials, o.jobs, [&](int i) {
    const int run = i / (cells * o.trials), cell = (i / o.trials) % cells;
    const v::ReferenceCell& c = t.cells[cell];
    return v::findExperimentKind(run == 0 ? c.experiment : t.companion)->run(c.level, c.param, i % o.trials, v::Drive{c.speed_units, c.track_mu});
  });
  auto outcomes = [&](int run, int cell) {
    const auto first = res.begin() + (run * cells + cell) * o.trials;
    return std::vector<Outcome>(first, first + o.trials);
  };
  auto meanValue = [&](const std::vector<Outcome>& os) {
    double sum = 0;
    int n = 0;
    for (const Outcome& x : os)
      if (!failed(x)) { sum += x.value; ++n; }
    return n ? t.value.text(sum / n) : std::string("error");
  };
  const bool tallied = !t.group.empty(), levels = t.severalLevels(), speeds = t.otherSpeeds();
  // Rows must not differ only in what the table does not show: cells' variants without a
  // variant_header, and floors of their own (track_mu), get a column when they differ.
  const bool variants = !t.variant_header.empty() || t.severalVariants(), floors = t.severalFloors();
  md << "## " << t.title << " (modal of " << o.trials << ")\n\n";
  if (!t.about.empty()) md << t.about << "\n\n";
  if (std::any_of(t.cells.begin(), t.cells.end(), [](const v::ReferenceCell& c) { return c.level == "fast"; }))
    md << "The half-size Fast robot meets gaps, steps and run-ups halved, as its terrain is halved in 4.2.2 (a 6 cm "
          "gap is longer than the Fast robot): its cells' parameters are the full-size values.\n\n";
  std::vector<std::string> columns{t.param.header};
  if (variants) columns.push_back(t.variant_header.empty() ? "variant" : t.variant_header);
  if (levels) columns.push_back("level");
  if (speeds) columns.push_back("speed [cm/s]");
  if (floors) columns.push_back("treels mu");
  columns.insert(columns.end(), t.references.begin(), t.references.end());
  columns.push_back(t.ours_header);
  if (tallied) columns.push_back("match");
  if (!t.companion.empty()) columns.push_back(t.companion_header);
  if (!t.value.header.empty()) columns.push_back(t.value.header);
  for (const std::string& c : columns) md << "| " << c << " ";
  md << "|\n";
  for (std::size_t k = 0; k < columns.size(); ++k) md << "|---";
  md << "|\n";
  Tally table;
  for (int k = 0; k < cells; ++k) {
    const v::ReferenceCell& c = t.cells[k];
    const std::vector<Outcome> ours = outcomes(0, k);
    const ModalCell m = modalCell(c.references.front().accepts, ours);
    if (std::any_of(ours.begin(), ours.end(), failed)) g_error_cells.push_back(t.key(c));
    md << "| " << t.paramText(c);
    if (variants) md << " | " << c.variant;
    if (levels) md << " | " << c.level;
    if (speeds) md << " | " << fmt(v::Drive{c.speed_units}.speed(sbot::loadLevel(c.level)) * 100, 2);
    if (floors) md << " | " << (c.track_mu > 0 ? fmt(c.track_mu, 3) : std::string("the experiment's"));
    for (const v::ReferenceValue& r : c.references) md << " | " << r.text;
    md << " | " << m.text << " (" << summary(ours) << ")";
    if (tallied) {
      md << " | " << markRun(t.key(c), m.ok, m.ran, tallies[t.group]);
      ++table.total;
      table.match += m.ok;
    }
    if (!t.companion.empty()) md << " | " << modalCell("", outcomes(1, k)).text << " (" << summary(outcomes(1, k)) << ")";
    if (!t.value.header.empty())
      md << " | " << meanValue(ours) << (t.companion.empty() ? "" : " / " + meanValue(outcomes(1, k)));
    md << " |\n";
  }
  md << "\n";
  if (tallied) md << "Table " << t.id << ": " << table.str() << " cells match.\n\n";
  md << reasons.explainPending();
  for (const std::string& p : t.after) md << builtInParagraph(p);
}

}  // namespace sbot_validate_tool
