// sbot_validate: the seed's validation experiments (chapter 4) run headless on the core, written up
// as a Markdown report that puts every cell of the seed's tables beside ours (plus PNG plots).
//
//   rosrun swarmbot3d sbot_validate --out DIR [--quick] [--trials N] [--jobs 2] [--only LIST]
//
// LIST: comma-separated sections of facts,4.1,4.1pair,4.2,4.3,4.4,4.5,4.6,fig4.4,compat (default: all;
// an unknown name is refused, as is an unreadable --heightmap when fig4.4 is wanted).
// --quick: 3 trials per cell and 4 runs per roughness (minutes instead of tens of minutes).
// Exit status: 0 when every hardware cell of Tables 4.1-4.3 matches, 1 otherwise, 2 on bad usage.
//
//   sbot_validate [--trace] [--index N] --trial KIND LEVEL PARAM    one trial, printed (tuning aid);
//     --trace prints the robot's state every 0.1 s (pose, attitude, wheel load, track speeds,
//     turret angle, gripper tip); --index N runs the cell's trial N (its start
//     perturbation, as in the report; default 0)
// KIND: gap, step, stepb, slope, slopeb, uphill, downhill, rough, rtm, speed (PARAM: m, m, m, deg,
// deg, rad, rad, HR in cm, simulated s, setSpeed units of the compatibility check; ranges in
// trialKinds()).
#include <sys/stat.h>
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
#include "sbot_sim/tools/cli_args.h"
#include "two_sbots_trials.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/terrain.h"
#include "sbot_sim/core/world_config.h"

using sbot::validation::Outcome;
namespace v = sbot::validation;

namespace {

struct Options {
  std::string out = "validation_report";
  bool quick = false;
  int trials = 12;
  int rough_runs = 12;
  int jobs = 2;
  std::set<std::string> only;
  std::string heightmap;
  std::string reasons;  ///< YAML: why cells do not match (default: config/validation/mismatch_reasons.yaml)
};

const std::vector<std::string> kLevels{"fast", "simple", "medium", "detailed"};
/// Every model level: the model facts cover Basic too (the seed's tables do not).
const std::vector<std::string> kAllLevels{"fast", "simple", "basic", "medium", "detailed"};
constexpr int kRtmRepeats = 5;  ///< Table 4.4: runs per RTM figure, the fastest reported
const std::vector<std::string> kSections{"facts", "4.1", "4.1pair", "4.2", "4.3", "4.4", "4.5", "4.6", "fig4.4", "compat"};

std::string fmt(double v, int prec = 2) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

/// A run that threw (runParallel's "error" outcome) has no numbers: its cells say "error", never 0.
bool failed(const Outcome& o) { return o.label == "error"; }
std::string number(const Outcome& o, double v, int prec) { return failed(o) ? "error" : fmt(v, prec); }

/// "pass 11/12" style summary of a cell's outcomes.
std::string summary(const std::vector<Outcome>& os) {
  std::map<std::string, int> c;
  for (const auto& o : os) ++c[o.label];
  std::vector<std::pair<int, std::string>> v;
  for (auto& [k, n] : c) v.push_back({-n, k});
  std::sort(v.begin(), v.end());
  std::string s;
  for (auto& [n, k] : v) s += (s.empty() ? "" : ", ") + k + " " + std::to_string(-n) + "/" + std::to_string(os.size());
  return s;
}

struct Tally {
  int match = 0, total = 0;
  std::string str() const { return std::to_string(match) + "/" + std::to_string(total); }
};

/// The report's reasons for the cells that do not match (mismatch_reasons.h).
v::MismatchReasons reasons;

/// Tallies cell `key` and returns its match column; a mismatch is explained under its table.
std::string mark(const std::string& key, bool ok, Tally& t) {
  ++t.total;
  t.match += ok;
  return reasons.record(key, ok);
}

/// A tallied cell's modal label as the report prints it, and whether the seed (or the hardware)
/// accepts it; every tallied table uses it. A tie (e.g. 6 / 6 of 12) is printed as one and matches
/// only if every tied label is accepted: which of them comes first is only the order of the trials.
struct ModalCell {
  std::string text;
  bool ok = false;
};
ModalCell modalCell(const std::string& expected, const std::vector<Outcome>& outcomes) {
  const std::vector<std::string> labels = v::modalLabels(outcomes);
  ModalCell cell;
  cell.ok = !labels.empty();
  for (std::size_t i = 0; i < labels.size(); ++i) {
    cell.text += (i ? " / " : "") + labels[i];
    cell.ok = cell.ok && v::accepts(expected, labels[i]);
  }
  if (labels.size() > 1) cell.text = "tie: " + cell.text;
  return cell;
}

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
     << " than ours (Table 2.3: 4 +- 1 cm ahead of the turret axis). With it the rigid static tip "
        "facing downhill rises from " << deg(v::frontTipSlope(s)) << " to " << deg(v::frontTipSlope(needed))
     << " deg (hardware: \"difficult\" at 20 deg and toppling at 30 deg rear uphill; src/validation/README.md, "
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
  cv::imwrite(path, img);
}

/// Table 4.4's "what limits it": the step time of one s-bot per level split by phase
/// (World::enableProfile, sensors timed around their reads). Runs in this process, one level after
/// the other, so the figures are comparable with each other rather than with the RTM column above.
void writeProfile(std::ostream& md, bool quick) {
  const std::map<std::string, double> seconds{{"fast", 1000}, {"simple", 100}, {"medium", 50}, {"detailed", 20}};
  md << "### What limits it: where one step's time goes\n\n"
     << "The same workload, timed by phase (`World::enableProfile`; sensors timed around their reads; "
        "the rest is the loop and the clock reads). collision = broad and narrow phase and the contact "
        "joints built; solver = ODE's quickstep over bodies, joints and contacts; commands = motors and "
        "effects; feedback = wheel loads and torque windows.\n\n"
     << "| level | bodies | contacts per step | solver iterations | us per step | solver | collision | sensors | "
        "commands | feedback | RTM (profiling) |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  auto pct = [](double f) { return fmt(100 * f, 0) + " %"; };
  for (const auto& level : kLevels) {
    const v::StepCost c = v::profileTrial(level, quick ? seconds.at(level) / 3 : seconds.at(level));
    md << "| " << level << " | " << c.bodies << " | " << fmt(c.contacts_per_step, 1) << " | " << c.iterations << " | "
       << fmt(c.wall_us_per_step, 1) << " | " << pct(c.solver) << " | " << pct(c.collision) << " | " << pct(c.sensors)
       << " | " << pct(c.commands) << " | " << pct(c.feedback) << " | " << fmt(c.rtm, 0) << " |\n";
  }
  md << "\n";
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

// The kinds of `--trial`, each with its parameter's unit and the range it accepts (a negative gap or
// a slope past vertical names nothing the experiment can build).
struct TrialKind {
  const char* name;
  const char* unit;
  double min, max;
  std::function<Outcome(const std::string& level, double param, int index)> run;
};

const std::vector<TrialKind>& trialKinds() {
  static const std::vector<TrialKind> kinds = {
      {"gap", "gap width, m", 0.0, 0.3, [](const std::string& l, double p, int i) { return v::gapTrial(l, p, i); }},
      {"step", "step height, m", 0.0, 0.1, [](const std::string& l, double p, int i) { return v::stepTrial(l, p, false, i); }},
      {"stepb", "step height, m", 0.0, 0.1, [](const std::string& l, double p, int i) { return v::stepTrial(l, p, true, i); }},
      {"slope", "slope, deg", 0.0, 89.0,
       [](const std::string& l, double p, int i) { return v::slopeHoldClimbTrial(l, p * M_PI / 180, false, i); }},
      {"slopeb", "slope, deg", 0.0, 89.0,
       [](const std::string& l, double p, int i) { return v::slopeHoldClimbTrial(l, p * M_PI / 180, true, i); }},
      {"uphill", "ramp angle, rad", 0.0, 1.5, [](const std::string& l, double p, int i) { return v::uphillTrial(l, p, i); }},
      {"downhill", "ramp angle, rad", 0.0, 1.5, [](const std::string& l, double p, int i) { return v::downhillTrial(l, p, i); }},
      {"rough", "height range HR, cm", 0.0, 100.0,
       [](const std::string& l, double p, int i) { return v::roughTrial(l, p, i, findHeightmap()); }},
      {"rtm", "simulated time, s", 0.1, 3600.0, [](const std::string& l, double p, int) { return v::rtmTrial(l, p); }},
      {"speed", "setSpeed units", -70.0, 70.0,
       [](const std::string& l, double p, int) { return v::steadySpeedTrial(l, static_cast<int>(std::lround(p))); }},
  };
  return kinds;
}

const TrialKind* findTrialKind(const std::string& name) {
  for (const TrialKind& k : trialKinds())
    if (name == k.name) return &k;
  return nullptr;
}

std::string trialKindNames() {
  std::string names;
  for (const TrialKind& k : trialKinds()) names += (names.empty() ? "" : ", ") + std::string(k.name);
  return names;
}

}  // namespace

int main(int argc, char** argv) {
  if (!v::studyKnobsOk("sbot_validate")) return 2;
  Options o;
  bool trace = false;
  int index = 0;  // --index: which trial of a cell --trial runs (its start perturbation)
  sbot_tools::ArgReader args("sbot_validate", argc, argv);
  while (args.more()) {
    const std::string a = args.option();
    if (a == "--out") o.out = args.value();
    else if (a == "--quick") o.quick = true;
    else if (a == "--trials") o.trials = args.count(1, 1000);
    else if (a == "--jobs") o.jobs = args.count(1, 64);
    else if (a == "--heightmap") o.heightmap = args.value();
    else if (a == "--reasons") o.reasons = args.value();
    else if (a == "--trace") trace = true;  // with --trial (before it): the robot's state every 0.1 s
    else if (a == "--index") index = args.count(0, 999);  // with --trial (before it): the cell's trial N
    else if (a == "--trial") {  // --trial KIND LEVEL PARAM: one trial, printed (tuning aid)
      const std::string kind = args.value(), level = args.value();
      const TrialKind* k = findTrialKind(kind);
      if (!k) {
        std::fprintf(stderr, "sbot_validate: --trial expects %s, found '%s'\n", trialKindNames().c_str(), kind.c_str());
        return 2;
      }
      sbot_tools::requireLevel("sbot_validate", "--trial " + kind + " " + level, level);
      const double p = sbot_tools::numberArg(args.tool(), "--trial " + kind + " " + level + " (" + k->unit + ")",
                                             args.value(), k->min, k->max);
      v::setTrace(trace);
      const Outcome r = k->run(level, p, index);
      std::printf("%s %s %g: %s %g %g\n", kind.c_str(), level.c_str(), p, r.label.c_str(), r.value, r.value2);
      return 0;
    }
    else if (a == "--only") {
      std::stringstream ss(args.value());
      for (std::string s; std::getline(ss, s, ',');) o.only.insert(s);
    } else {
      std::fprintf(stderr, "usage: sbot_validate --out DIR [--quick] [--trials N] [--jobs N] [--heightmap PNG] [--reasons YAML]\n"
                           "                     [--only facts,4.1,4.1pair,4.2,4.3,4.4,4.5,4.6,fig4.4,compat]\n"
                           "       sbot_validate [--trace] [--index N] --trial KIND LEVEL PARAM\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (trace) {  // a whole report's trials would interleave their traces from the worker processes
    std::fprintf(stderr, "sbot_validate: --trace goes with --trial (before it): one trial, traced\n");
    return 2;
  }
  if (o.quick) { o.trials = std::min(o.trials, 3); o.rough_runs = 4; }
  o.rough_runs = std::max(o.rough_runs, o.quick ? 4 : 12);
  if (o.heightmap.empty()) o.heightmap = findHeightmap();
  for (const std::string& s : o.only) {  // a misspelt section would leave an empty report
    if (std::find(kSections.begin(), kSections.end(), s) == kSections.end()) {
      std::string known;
      for (const std::string& k : kSections) known += (known.empty() ? "" : ", ") + k;
      std::fprintf(stderr, "sbot_validate: --only: unknown section '%s' (sections: %s)\n", s.c_str(), known.c_str());
      return 2;
    }
  }
  auto want = [&](const std::string& s) { return o.only.empty() || o.only.count(s); };
  if (want("fig4.4")) {  // before any work: every rough-terrain run would fail on it
    sbot::TerrainConfig t;
    t.type = sbot::TerrainConfig::Type::Rough;
    t.heightmap_image = o.heightmap;
    try {
      sbot::makeHeightMap(t);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sbot_validate: --heightmap (or $SBOT_HEIGHTMAP): %s\n", e.what());
      return 2;
    }
  }
  try {  // before any work: a report whose mismatches cannot be explained is not written
    reasons = o.reasons.empty() ? v::MismatchReasons::load(std::string(SWARMBOT3D_SOURCE_DIR) + "/" + v::kMismatchReasonsFile,
                                                            v::kMismatchReasonsFile)
                                : v::MismatchReasons::load(o.reasons);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sbot_validate: --reasons: %s\n", e.what());
    return 2;
  }
  for (const std::string& level : kAllLevels)  // before any work: every trial of that level would fail on it
    sbot_tools::requireLevel("sbot_validate", "model description of level '" + level + "' (or $SBOT_DESCRIPTION_DIR)", level);
  mkdir(o.out.c_str(), 0755);
  const auto t_start = std::chrono::steady_clock::now();
  auto log = [&](const std::string& s) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    std::fprintf(stderr, "[sbot_validate %6.0fs] %s\n", t, s.c_str());
  };

  // Table 4.4's runs come first, on a machine not yet busy with the suite's two workers (after
  // them this VM ran the same binary 10-15 % slower for a minute or more); printed in its place.
  std::map<std::string, std::array<v::Outcome, 2>> fastest;  // per level: [with sensors, physics only]
  std::map<std::string, double> slowest;  // per level, with sensors: how steady the machine was
  double load[3] = {0, 0, 0};  // load average before the runs
  if (want("4.4")) {
    log("Table 4.4: real-time multiplier");
    getloadavg(load, 3);
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
      }
    }
  }

  std::ostringstream md;
  md << "# swarmbot3d validation report\n\n"
     << "Generated by `sbot_validate` (src/validation/) on the headless core. Every cell: the seed's value, "
        "ours (modal label and the distribution over the trials), match / mismatch. A tie (e.g. 6 / 6 of 12) "
        "is printed as \"tie: a / b\" and matches only if the seed (or the hardware) accepts every tied label, "
        "in every tallied table. "
     << "Trials per cell: " << o.trials << (o.quick ? " (--quick)" : "") << ". Speed in gap and slope experiments: "
     << "2.8 cm/s (10 API units) as in 4.2.3. Each trial is a fresh World with small seeded perturbations "
        "of the start pose (heading +-3 deg, lateral +-1 cm, distance +-5 mm). Worlds use each level's "
        "recommended step, gravity and quickstep iterations (sidecar `solver_iterations`: Medium 25, "
        "Detailed 40, others the world default 20). The front gripper's servos hold elevation 0 (as the powered real "
        "gripper does); the side arm is held folded by the core.\n\n";
  if (want("facts")) {
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
  Tally hw, t45, t46;
  bool hw_all = true;

  // ---- Table 4.1 ------------------------------------------------------------------------------
  if (want("4.1")) {
    log("Table 4.1: slopes");
    const std::vector<double> deg{10, 20, 30};
    const std::vector<std::string> hardware{"full", "difficult", "topple b/w"};
    const std::vector<std::string> seed_sim{"full", "full", "topple b/w"};
    md << "## Table 4.1 - single s-bot on a slope (Detailed)\n\n"
       << "Placed on the slope (tilted gravity; the seed's polystyrene, treels mu "
       << fmt(v::kPolystyreneTrackMu, 1) << ", see the next section), motors holding for 3 s, then climbing 8 s at 2.8 cm/s. "
          "full: holds (< 1 cm slide) and climbs at >= 85 % of the commanded speed without rearing up; "
          "difficult: climbs but slower or rearing > 8 deg; slide: slides down; topple b/w: tilts > 45 deg "
          "off the slope normal.\n\n"
       << "Orientation: **rear uphill** (the robot climbs in reverse, gripper and the turret's forward COM offset "
          "downhill) is the matching condition; **front uphill** is shown as well. The seed does not say "
          "which way its robot faced; with the front uphill the COM offset makes the robot far more "
          "stable, and the seed's own Table 4.6 has the Detailed model climb 0.7 rad (40 deg) front first, "
          "which is only consistent with a 30 deg topple if Table 4.1 was run rear uphill.\n\n"
       << "| slope | hardware | seed sim | ours, rear uphill | match (hw) | ours, front uphill | climb efficiency rear/front |\n"
       << "|---|---|---|---|---|---|---|\n";
    const int n = static_cast<int>(deg.size()) * 2 * o.trials;
    auto res = v::runParallel(n, o.jobs, [&](int i) {
      const int cell = i / o.trials, t = i % o.trials;
      return v::slopeHoldClimbTrial("detailed", deg[cell / 2] * M_PI / 180, cell % 2 == 0, t);
    });
    for (std::size_t k = 0; k < deg.size(); ++k) {
      std::vector<Outcome> back(res.begin() + (2 * k) * o.trials, res.begin() + (2 * k + 1) * o.trials);
      std::vector<Outcome> front(res.begin() + (2 * k + 1) * o.trials, res.begin() + (2 * k + 2) * o.trials);
      const ModalCell mb = modalCell(hardware[k], back);
      const std::string mf = modalCell("", front).text;  // shown, not tallied
      const bool ok = mb.ok;
      hw_all &= ok;
      double eb = 0, ef = 0;
      for (auto& x : back) eb += x.value / back.size();
      for (auto& x : front) ef += x.value / front.size();
      md << "| " << deg[k] << " deg | " << hardware[k] << " | " << seed_sim[k] << " | " << mb.text << " (" << summary(back)
         << ") | " << mark("4.1 " + fmt(deg[k], 0) + " deg rear uphill", ok, hw) << " | " << mf << " (" << summary(front) << ") | " << fmt(eb) << " / " << fmt(ef) << " |\n";
    }
    md << "\n" << reasons.explainPending() << "The two-s-bot rows of Table 4.1 and the two-robot step of 4.1.3 are in the next section.\n\n";
  }

  // ---- Table 4.1, two connected s-bots, and 4.1.3 two-robot step --------------------------------
  if (want("4.1pair")) {
    log("Table 4.1: two connected s-bots; 4.1.3 two-robot step (Detailed)");
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
    hw_all &= full_ok && stable_ok;
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
       << "| limit of full manoeuvrability | 29 deg | 29 deg | " << fmt(ours.full, 0) << " deg | " << mark("4.1 pair limit of full manoeuvrability", full_ok, hw)
       << " | " << fmt(seed.full, 0) << " deg | " << (fullOk(seed) ? "match" : "mismatch") << " |\n"
       << "| limit of stable position | 58-72 deg | 58-72 deg | " << stableText(ours) << " | " << mark("4.1 pair limit of stable position", stable_ok, hw)
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
    hw_all &= single_ok && pair_ok;
    md << "## 4.1.3 - two-robot step passing, going backwards (Detailed)\n\n"
       << "A 32 mm step; the holder nearest the step lowers its gripper arm when its rear reaches the step and "
          "pulls the held robot over (phases from ground truth here; the same procedure driven by the robots' "
          "own sensors through sbot.h is sbot_controllers/src/step_climbing.c, rostest test/two_sbots_step.test).\n\n"
       << "| step | robots | real s-bots | seed sim | ours | match |\n|---|---|---|---|---|---|\n"
       << "| 32 mm | single s-bot | topple | topple | " << ms.text << " (" << summary(single) << ") | " << mark("4.1.3 32 mm single s-bot", single_ok, hw)
       << " |\n"
       << "| 32 mm | two connected | pass | pass | " << mp.text << " (" << summary(pair) << ") | " << mark("4.1.3 32 mm two connected", pair_ok, hw)
       << " |\n\n" << reasons.explainPending();
  }

  // ---- Table 4.2 ------------------------------------------------------------------------------
  if (want("4.2")) {
    log("Table 4.2: gaps (Detailed)");
    const std::vector<double> gaps{0.030, 0.045, 0.055};
    const std::vector<std::string> expect{"pass", "pass", "fall inside"};
    md << "## Table 4.2 - gap passing, Detailed model\n\n"
       << "Two 10 cm high platforms, the robot starts 7.5 cm before the edge and drives at 2.8 cm/s. pass: "
          "its base is 9 cm beyond the far edge at platform height, the robot upright (< 20 deg); fall inside: its "
          "base dropped > 2 cm (nose first into the gap counts here, not as a topple); stuck: neither. The hardware's "
          "\"fall inside\" is \"failing to overcome it\" (the table's caption), so it accepts both.\n\n"
       << "| gap | hardware | seed sim | ours | match |\n|---|---|---|---|---|\n";
    auto res = v::runParallel(static_cast<int>(gaps.size()) * o.trials, o.jobs, [&](int i) {
      Outcome r = v::gapTrial("detailed", gaps[i / o.trials], i % o.trials);
      if (r.label == "stuck" && r.value2 > 0.02) r.label = "fall inside";
      return r;
    });
    for (std::size_t k = 0; k < gaps.size(); ++k) {
      std::vector<Outcome> c(res.begin() + k * o.trials, res.begin() + (k + 1) * o.trials);
      const ModalCell m = modalCell(expect[k], c);
      const bool ok = m.ok;
      hw_all &= ok;
      md << "| " << fmt(gaps[k] * 1000, 0) << " mm | " << expect[k] << " | " << expect[k] << " | " << m.text << " ("
         << summary(c) << ") | " << mark("4.2 " + fmt(gaps[k] * 1000, 0) + " mm", ok, hw) << " |\n";
    }
    md << "\n" << reasons.explainPending();
  }

  // ---- Table 4.3 ------------------------------------------------------------------------------
  if (want("4.3")) {
    log("Table 4.3: steps (Detailed)");
    const std::vector<double> h{0.010, 0.015, 0.016, 0.023, 0.024};
    md << "## Table 4.3 - step climbing, single s-bot (Detailed)\n\n"
       << "The robot starts 7.5 cm before a step and drives into it at 2.8 cm/s, front first (forward) or "
          "rear first (backward). pass: base 9 cm onto the step at step height, the robot upright (< 20 deg); "
          "topple: tilted > 45 deg at any time (reversing into a step our robot tips onto its held gripper; "
          "see the README).\n\n"
       << "| step | direction | real s-bot | seed sim | ours | match |\n|---|---|---|---|---|---|\n";
    auto res = v::runParallel(static_cast<int>(h.size()) * 2 * o.trials, o.jobs, [&](int i) {
      const int cell = i / o.trials;
      return v::stepTrial("detailed", h[cell / 2], cell % 2 == 0, i % o.trials);
    });
    for (std::size_t k = 0; k < h.size(); ++k) {
      for (int b = 0; b < 2; ++b) {
        const bool backward = b == 0;
        const int cell = 2 * k + b;
        std::vector<Outcome> c(res.begin() + cell * o.trials, res.begin() + (cell + 1) * o.trials);
        const double mm = h[k] * 1000;
        const std::string expect = backward ? (mm <= 15.5 ? "pass" : "fail") : (mm <= 23.5 ? "pass" : "fail");
        const ModalCell m = modalCell(expect, c);
        const bool ok = m.ok;
        hw_all &= ok;
        md << "| " << fmt(mm, 0) << " mm | " << (backward ? "backward" : "forward") << " | " << expect << " | "
           << expect << " | " << m.text << " (" << summary(c) << ") | "
           << mark("4.3 " + fmt(mm, 0) + " mm " + (backward ? "backward" : "forward"), ok, hw) << " |\n";
      }
    }
    md << "\n" << reasons.explainPending() << backwardStepStatics();
  }

  // ---- Table 4.4 ------------------------------------------------------------------------------
  if (want("4.4")) {
    const std::map<std::string, double> seed{{"fast", 950}, {"simple", 94}, {"medium", 31}, {"detailed", 3}};
    md << "## Table 4.4 - efficiency (RTM, one s-bot, flat ground, its level's sensors read every step)\n\n"
       << "Measured before the suite's other experiments, one process at a time (the seed: dual 3.06 GHz Xeon). "
          "Target: 10x the seed. A random "
          "walk (new setSpeed every simulated second); sensors: the whole proximity ring every step, plus "
          "ground and light sensors where the level has them (SensorSuite). The last column is the same "
          "run without any sensor reads. Each RTM is the best of " << kRtmRepeats << " runs, taken in turns with the "
          "other levels' (another process on the machine can only slow a run down, and this VM's slow spells "
          "last up to a minute); the slowest of the " << kRtmRepeats << " shows how steady the machine was. Machine load average when measured: " << fmt(load[0]) << " on "
       << sysconf(_SC_NPROCESSORS_ONLN) << " cores (above ~1, other processes share the CPU and these RTMs are "
          "pessimistic).\n\n"
       << "| level | step | solver iterations | seed RTM | target (10x) | ours RTM | slowest run | wall ms/step | target met | physics only RTM |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& level : kLevels) {
      const v::Outcome& r = fastest.at(level)[0];
      const v::Outcome& p = fastest.at(level)[1];
      const double target = 10 * seed.at(level);
      const int needs = sbot::loadLevel(level).solver_iterations;  // 0: the world default
      const std::string it = needs > 0 ? std::to_string(needs) : std::to_string(sbot::WorldConfig().solver_iterations) + " (default)";
      md << "| " << level << " | " << sbot::loadLevel(level).recommended_step * 1000 << " ms | " << it << " | " << seed.at(level)
         << " | " << target << " | " << number(r, r.value, 0) << " | "
         << (slowest.count(level) ? fmt(slowest.at(level), 0) : std::string("error")) << " | " << number(r, r.value2, 4) << " | "
         << (failed(r) ? "error" : r.value >= target ? "yes" : "**no**") << " | " << number(p, p.value, 0) << " |\n";
    }
    md << "\n";
    writeProfile(md, o.quick);
  }

  // ---- Compatibility (2.1.3) -------------------------------------------------------------------
  if (want("compat")) {
    log("2.1.3: steady speed per level");
    md << "## Compatibility (seed 2.1.3) - steady speed at setSpeed(50,50) = 14.0 cm/s on flat ground\n\n"
       << "| level | speed [cm/s] | vs Detailed |\n|---|---|---|\n";
    auto r = v::runParallel(static_cast<int>(kLevels.size()), o.jobs, [&](int i) { return v::steadySpeedTrial(kLevels[i], 50); });
    const double ref = r.back().value;
    for (std::size_t i = 0; i < kLevels.size(); ++i)
      md << "| " << kLevels[i] << " | " << number(r[i], r[i].value * 100, 2) << " | "
         << (failed(r.back()) ? "error" : number(r[i], 100 * (r[i].value / ref - 1), 1) + " %") << " |\n";
    md << "\n";
  }

  // ---- Figure 4.4 -----------------------------------------------------------------------------
  if (want("fig4.4")) {
    log("Figure 4.4: rough terrain");
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
          "as the seed halves its terrain) from `" << o.heightmap << "`, 10 s at 15.24 cm/s; distance projected "
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
    plotFig44(o.out + "/fig4_4.png", hrs, data);
    md << "\nSeed's reading: Medium follows Detailed; Simple and Fast lose their course on minimally rough "
          "terrain (mean distance falls from HR 2 on).\n\n";
  }

  // ---- Table 4.5 ------------------------------------------------------------------------------
  if (want("4.5")) {
    log("Table 4.5: gaps per level");
    const std::vector<double> gaps{0.030, 0.040, 0.045, 0.050, 0.057, 0.060, 0.065};
    const std::map<std::string, std::vector<std::string>> seed{
        {"fast", {"pass", "pass", "pass", "pass", "pass", "pass", "stuck"}},
        {"simple", {"pass", "pass", "pass|stuck", "stuck", "stuck", "stuck", "stuck"}},
        {"medium", {"pass", "pass", "pass|stuck", "stuck", "stuck", "stuck", "stuck"}},
        {"detailed", {"pass", "pass", "pass", "pass", "pass|stuck", "pass|stuck", "pass|stuck"}}};
    const std::map<std::string, std::vector<std::string>> seed_text{
        {"fast", {"pass", "pass", "pass", "pass", "pass", "pass", "stuck"}},
        {"simple", {"pass", "pass", "pass 70% / stuck 30%", "stuck", "stuck", "stuck", "stuck"}},
        {"medium", {"pass", "pass", "pass 90% / stuck 10%", "stuck", "stuck", "stuck", "stuck"}},
        {"detailed", {"pass", "pass", "pass", "pass", "pass 50% / stuck 50%", "as 5.7", "as 5.7"}}};
    const int n = static_cast<int>(kLevels.size() * gaps.size()) * o.trials;
    auto res = v::runParallel(n, o.jobs, [&](int i) {
      const int cell = i / o.trials;
      Outcome r = v::gapTrial(kLevels[cell / gaps.size()], gaps[cell % gaps.size()], i % o.trials);
      if (r.label == "stuck" && r.value2 > 0.02 * (kLevels[cell / gaps.size()] == "fast" ? 0.5 : 1.0)) r.label = "fall inside";
      return r;
    });
    md << "## Table 4.5 - gap passing per level at 2.8 cm/s (modal of " << o.trials << ")\n\n"
       << "Seed \"stuck\" is matched by ours \"stuck\" or \"fall inside\"; mixed seed cells accept either label; "
       << "a tie between two labels matches only if the seed accepts both. "
       << "The half-size Fast robot crosses each gap halved (its terrain is halved as in 4.2.2; a 6 cm gap is longer "
       << "than the Fast robot).\n\n"
       << "| gap | level | seed | ours | match |\n|---|---|---|---|---|\n";
    for (std::size_t g = 0; g < gaps.size(); ++g) {
      for (std::size_t l = 0; l < kLevels.size(); ++l) {
        const int cell = l * gaps.size() + g;
        std::vector<Outcome> c(res.begin() + cell * o.trials, res.begin() + (cell + 1) * o.trials);
        const ModalCell m = modalCell(seed.at(kLevels[l])[g], c);
        md << "| " << fmt(gaps[g] * 100, 1) << " cm | " << kLevels[l] << " | " << seed_text.at(kLevels[l])[g] << " | " << m.text
           << " (" << summary(c) << ") | " << mark("4.5 " + fmt(gaps[g] * 100, 1) + " cm " + kLevels[l], m.ok, t45) << " |\n";
      }
    }
    md << "\nTable 4.5: " << t45.str() << " cells match.\n\n" << reasons.explainPending();
  }

  // ---- Table 4.6 ------------------------------------------------------------------------------
  if (want("4.6")) {
    log("Table 4.6: uphill / downhill per level");
    const std::vector<double> ang{0.02, 0.04, 0.20, 0.70, 0.80, 0.90, 1.00};
    const std::map<std::string, std::vector<std::string>> seed{
        {"fast", {"climb", "climb", "c/c", "c/c", "topple", "topple", "stuck"}},
        {"simple", {"climb", "stuck|c/c", "stuck", "stuck", "stuck", "stuck", "stuck"}},
        {"medium", {"climb", "climb", "climb", "climb", "slipping", "slide back", "topple"}},
        {"detailed", {"climb", "climb", "climb", "climb", "slipping", "topple", "topple"}}};
    const int n = static_cast<int>(kLevels.size() * ang.size()) * o.trials;
    auto res = v::runParallel(n, o.jobs, [&](int i) {
      const int cell = i / o.trials;
      return v::uphillTrial(kLevels[cell / ang.size()], ang[cell % ang.size()], i % o.trials);
    });
    md << "## Table 4.6 - uphill slope per level at 2.8 cm/s (modal of " << o.trials << ")\n\n"
       << "The robot starts 12 cm before the foot of a ramp. climb: 25 cm up the slope; topple: over "
          "backwards (tilted > 75 deg off the normal of the ramp or floor under its base); slide back: got > 3 cm up and lost > 3 cm again; c/c: at the foot (< 5 cm up) with its "
          "heading changed > 20 deg, still travelling (>= 25 % of the commanded distance over the last 2 s); "
          "slipping: short of 25 cm with its tracks turning (encoders >= 50 % of the command over the last 2 s) "
          "while the driven wheels carry >= 25 % of the weight; stuck: short of 25 cm otherwise (tracks stalled, "
          "or spinning free with the robot hung up on its chassis or casters). A tie between two labels matches only "
          "if the seed accepts both.\n\n"
       << "| angle | level | seed | ours | match |\n|---|---|---|---|---|\n";
    for (std::size_t a = 0; a < ang.size(); ++a) {
      for (std::size_t l = 0; l < kLevels.size(); ++l) {
        const int cell = l * ang.size() + a;
        std::vector<Outcome> c(res.begin() + cell * o.trials, res.begin() + (cell + 1) * o.trials);
        const ModalCell m = modalCell(seed.at(kLevels[l])[a], c);
        std::string st = seed.at(kLevels[l])[a];
        if (st == "stuck|c/c") st = "stuck 60% / c/c 40%";
        md << "| " << fmt(ang[a]) << " rad | " << kLevels[l] << " | " << st << " | " << m.text << " (" << summary(c) << ") | "
           << mark("4.6 " + fmt(ang[a]) + " rad " + kLevels[l], m.ok, t46) << " |\n";
      }
    }
    md << "\nTable 4.6 uphill: " << t46.str() << " cells match.\n\n" << reasons.explainPending();
    log("4.2.4: downhill");
    const std::vector<double> down{0.3, 0.4, 0.5, 0.6, 0.8};  // 0.4: where below "about 0.5" a level stops
    const int dn = std::max(3, o.trials / 2);
    auto dres = v::runParallel(static_cast<int>(kLevels.size() * down.size()) * dn, o.jobs, [&](int i) {
      const int cell = i / dn;
      return v::downhillTrial(kLevels[cell / down.size()], down[cell % down.size()], i % dn);
    });
    md << "### Downhill (4.2.4: all models manage up to about 0.5 rad, steeper slopes topple forward)\n\n"
       << "The robot starts 10 cm before the edge of a plateau and drives down a 40 cm ramp at 2.8 cm/s. "
          "pass: 10 cm beyond the ramp's foot, upright (< 17 deg); topple: over (> 100 deg off vertical), or "
          "tilted > 45 deg off the normal of the surface under its base (onto its nose or gripper); c/c: short of "
          "the goal, upright, its heading turned > 20 deg (slewed across the ramp); stuck: otherwise. Not tallied: "
          "the seed gives no table.\n\n"
       << "| angle | seed | fast | simple | medium | detailed |\n|---|---|---|---|---|---|\n";
    for (std::size_t a = 0; a < down.size(); ++a) {
      md << "| " << fmt(down[a]) << " rad | " << (down[a] <= 0.5 ? "pass" : "topple (forward)");
      for (std::size_t l = 0; l < kLevels.size(); ++l) {
        const int cell = l * down.size() + a;
        std::vector<Outcome> c(dres.begin() + cell * dn, dres.begin() + (cell + 1) * dn);
        md << " | " << v::modal(c) << " (" << summary(c) << ")";
      }
      md << " |\n";
    }
    md << "\n";
  }

  md << "## Summary\n\n- Hardware cells of Tables 4.1-4.3 matched: " << hw.str() << "\n";
  if (t45.total) md << "- Table 4.5 cells matched: " << t45.str() << "\n";
  if (t46.total) md << "- Table 4.6 cells matched: " << t46.str() << "\n";
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  md << "- Wall time: " << fmt(total, 0) << " s on " << o.jobs << " processes\n";
  auto cells = [](const std::vector<std::string>& keys) {
    std::string s;
    for (const std::string& k : keys) s += (s.empty() ? "" : "; ") + k;
    return s;
  };
  if (!reasons.unexplained().empty())
    md << "- Mismatches not explained yet (new since the analysis): " << cells(reasons.unexplained()) << "\n";
  if (!reasons.stale().empty())
    md << "- Recorded reasons whose cell now matches (remove them from `" << reasons.source()
       << "`): " << cells(reasons.stale()) << "\n";
  md << "\nEach mismatch is explained under its table (from `" << reasons.source() << "`); the full analysis, "
        "with what was tried, is *Why cells do not match* in `src/validation/README.md`.\n";
  std::ofstream(o.out + "/report.md") << md.str();
  log("wrote " + o.out + "/report.md (hardware " + hw.str() + ", 4.5 " + t45.str() + ", 4.6 " + t46.str() + ")");
  std::printf("%s", md.str().c_str());
  return hw_all ? 0 : 1;
}
