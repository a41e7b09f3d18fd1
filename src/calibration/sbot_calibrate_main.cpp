// sbot_calibrate: the calibration workbench (docs/calibration.md).
//
//   sbot_calibrate compare  DATASET [--effects FILE] [--out DIR] [--no-plots]
//   sbot_calibrate diagnose DATASET [--effects BASE] [--folds K] [--threshold DBIC] [--candidates a,b]
//                                   [--write-effects FILE]
//   sbot_calibrate fit      DATASET --effect NAME [--effect NAME2 ...] [--effects BASE] --out FILE
//   sbot_calibrate generate --out DIR [--level simple] [--seed N] [--hidden FILE] [--hide name:p=v,...]
//                           [--tilt DEG] [--duration S] [--families a,b] [--repeat N] [--max-runs N]
//   sbot_calibrate sweep    [--out FILE.md] [--seeds N] [--cases a,b] [--level L] [--duration S] [--set name:p=v]
//   sbot_calibrate effects  (list the effects library)
//   common: --jobs N (worker processes, default: all cores), --quiet; compare/diagnose/fit also
//           --solver quickstep|exact (replaces the dataset's world stepper)
// Output places (--out, --write-effects) are created and checked before the work: a fit or a
// diagnosis runs for minutes, and its result must not be lost to an unwritable path at the end.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "calibration/diagnose.h"
#include "calibration/effect_list.h"
#include "calibration/generator.h"
#include "calibration/report.h"
#include "calibration/sweep.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/output_files.h"

using namespace sbot;
using namespace sbot::calib;

namespace {

struct Args {
  std::string cmd;
  std::vector<std::string> positional;
  std::multimap<std::string, std::string> opts;
  std::set<std::string> flags;

  bool has(const std::string& k) const { return opts.count(k) || flags.count(k); }
  std::string get(const std::string& k, const std::string& def = "") const {
    auto it = opts.find(k);
    return it == opts.end() ? def : it->second;
  }
  std::vector<std::string> all(const std::string& k) const {
    std::vector<std::string> v;
    for (auto [a, b] = opts.equal_range(k); a != b; ++a) v.push_back(a->second);
    return v;
  }
  double num(const std::string& k, double def) const {
    if (!opts.count(k)) return def;
    char* end = nullptr;
    const std::string s = get(k);
    const double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end) throw std::invalid_argument("--" + k + " expects a number, got '" + s + "'");
    return v;
  }
};

const std::set<std::string> kFlags{"no-plots", "quiet", "no-align", "torque", "no-tilt", "no-speed", "verbose", "help"};

/// The options each subcommand reads (besides --jobs, --quiet, --help). Anything else is refused:
/// a misspelt option would otherwise be ignored, e.g. `compare --effect F` comparing the nominal model.
const std::map<std::string, std::set<std::string>> kCommandOptions{
    {"compare", {"effects", "level", "solver", "out", "no-plots", "no-align"}},
    {"diagnose", {"effects", "level", "solver", "folds", "threshold", "seed", "candidates", "write-effects", "verbose"}},
    {"fit", {"effect", "effects", "level", "solver", "out"}},
    {"generate", {"out", "level", "solver", "seed", "duration", "tilt", "repeat", "max-runs", "name", "torque",
                  "no-tilt", "no-speed", "families", "hidden", "hide"}},
    {"sweep", {"cases", "set", "seeds", "first-seed", "level", "solver", "duration", "folds", "threshold", "torque",
               "out"}},
    {"effects", {}}};

/// Refuse an option the subcommand does not read (a misspelt one would otherwise be ignored).
void refuseUnknownOption(const std::string& cmd, const std::string& k) {
  auto it = kCommandOptions.find(cmd);
  if (it == kCommandOptions.end()) return;  // unknown command: usage() says so
  if (it->second.count(k) || k == "jobs" || k == "quiet" || k == "help") return;
  std::string accepted;
  for (const auto& o : it->second) accepted += " --" + o;
  throw std::invalid_argument("unknown option --" + k + " for '" + cmd + "' (it takes" +
                              (accepted.empty() ? std::string(" none") : accepted) + ", and --jobs, --quiet)");
}

Args parse(int argc, char** argv) {
  Args a;
  if (argc < 2) return a;
  a.cmd = argv[1];
  for (int i = 2; i < argc; ++i) {
    std::string s = argv[i];
    if (s.rfind("--", 0) == 0) {
      s = s.substr(2);
      const auto eq = s.find('=');
      if (eq != std::string::npos) {
        a.opts.emplace(s.substr(0, eq), s.substr(eq + 1));
      } else if (kFlags.count(s)) {
        a.flags.insert(s);
      } else {
        refuseUnknownOption(a.cmd, s);  // before "needs a value": a trailing misspelt option
        if (i + 1 >= argc) throw std::invalid_argument("--" + s + " needs a value");
        a.opts.emplace(s, argv[++i]);
      }
    } else {
      a.positional.push_back(s);
    }
  }
  return a;
}

void checkOptions(const Args& a) {
  for (const auto& [k, v] : a.opts) refuseUnknownOption(a.cmd, k);
  for (const auto& k : a.flags) refuseUnknownOption(a.cmd, k);
}

/// compare's report directory when --out is not given.
const char* const kDefaultReportDir = "calibration_report";

/// The command's output places exist and can be written (output_files.h), checked before its work;
/// else an OutputError that names the option.
void checkOutputs(const Args& a) {
  auto check = [&](const std::string& option, bool directory, const std::string& path) {
    try {
      if (directory) makeOutputDirectory(path);
      else checkOutputFile(path);
    } catch (const OutputError& e) {
      throw OutputError("--" + option + ": " + e.what());
    }
  };
  if (a.cmd == "compare") check("out", true, a.get("out", kDefaultReportDir));
  if (a.cmd == "generate" && a.has("out")) check("out", true, a.get("out"));
  if ((a.cmd == "fit" || a.cmd == "sweep") && a.has("out")) check("out", false, a.get("out"));
  if (a.cmd == "diagnose" && a.has("write-effects")) check("write-effects", false, a.get("write-effects"));
}

std::string pct(double v) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(1) << v << " %";
  return o.str();
}

void usage() {
  std::fprintf(stderr,
               "usage: sbot_calibrate <command> ...\n"
               "  compare  DATASET [--effects FILE] [--out DIR] [--no-plots]\n"
               "  diagnose DATASET [--effects BASE] [--folds K] [--threshold DBIC] [--candidates a,b] [--write-effects FILE]\n"
               "  fit      DATASET --effect NAME [--effect NAME2] [--effects BASE] --out FILE\n"
               "  generate --out DIR [--level simple] [--solver quickstep|exact] [--seed N] [--hidden FILE] [--hide name:p=v+name2:p=v]\n"
               "           [--tilt DEG] [--duration S] [--families straight,spin,arc,square,steps,place,approach] [--repeat N]\n"
               "           [--max-runs N] [--name NAME] [--torque] [--no-tilt] [--no-speed]\n"
               "  sweep    [--out FILE.md] [--seeds N] [--cases a,b] [--level L] [--solver S] [--duration S]\n"
               "           [--set name:p=v+name2:p=v]  (another magnitude for the cases that hide those effects)\n"
               "  effects  list the effects library\n"
               "common options: --jobs N (worker processes; default all cores), --quiet;\n"
               "  compare/diagnose/fit: --solver quickstep|exact replaces the dataset's world stepper\n");
}

/// The dataset, with --solver replacing its world's stepper (quickstep | exact): whether a misfit is
/// the model's physics or quickstep's non-convergence, without editing the dataset.
Dataset datasetFor(const Args& a) {
  Dataset ds = loadDataset(a.positional[0]);
  if (a.has("solver")) {
    const std::string s = a.get("solver");
    if (s != "quickstep" && s != "exact") throw std::invalid_argument("--solver expects quickstep or exact, got '" + s + "'");
    ds.world.solver = s;
  }
  return ds;
}

ModelSpec baseModel(const Dataset& ds, const Args& a) {
  ModelSpec m{ds.robot, {}};
  if (a.has("level")) m.level = a.get("level");
  if (a.has("effects")) m.effects = loadEffectsConfig(a.get("effects"));
  return m;
}

int cmdEffects() {
  const EffectRegistry& reg = EffectRegistry::instance();
  for (const auto& n : reg.names()) {
    const EffectInfo& i = reg.info(n);
    std::printf("%-26s %-8s %s\n", n.c_str(), i.path.c_str(), i.title.c_str());
    for (const auto& p : i.params)
      std::printf("    %-14s [%s] null %g, bounds [%g, %g]  %s\n", p.name.c_str(), p.unit.c_str(), p.null_value,
                  p.lower, p.upper, p.description.c_str());
  }
  return 0;
}

int cmdCompare(const Args& a) {
  if (a.positional.empty()) throw std::invalid_argument("compare needs a DATASET");
  const Dataset ds = datasetFor(a);
  ModelSpec nominal{a.has("level") ? a.get("level") : ds.robot, {}};
  std::vector<std::pair<std::string, ModelSpec>> variants{{"nominal", nominal}};
  if (a.has("effects")) {
    const auto effs = loadEffectsConfig(a.get("effects"));
    // Waterfall: add the file's effects one by one.
    ModelSpec m = nominal;
    for (std::size_t i = 0; i < effs.size(); ++i) {
      m.effects.push_back(effs[i]);
      variants.push_back({"+" + effs[i].name, m});
    }
  }
  CompareOptions co;
  co.out_dir = a.get("out", kDefaultReportDir);
  co.plots = !a.has("no-plots");
  co.eval.replay.align = !a.has("no-align");
  const auto sums = writeCompareReport(ds, variants, co, WorkerPool::global());
  std::printf("%-28s %-60s %10s\n", "model", "effects", "nRMS");
  for (const auto& s : sums) std::printf("%-28s %-60s %10.4f\n", s.label.c_str(), s.model.describe().c_str(), s.nrms);
  if (sums.size() > 1)
    std::printf("error change (nRMS): %.4f -> %.4f (%s)\n", sums.front().nrms, sums.back().nrms,
                pct(100 * (sums.back().nrms / sums.front().nrms - 1)).c_str());
  std::printf("report: %s/report.md\n", co.out_dir.c_str());
  return 0;
}

int cmdDiagnose(const Args& a) {
  if (a.positional.empty()) throw std::invalid_argument("diagnose needs a DATASET");
  const Dataset ds = datasetFor(a);
  DiagnoseOptions o;
  o.base = baseModel(ds, a);
  o.folds = static_cast<int>(a.num("folds", 2));
  o.bic_threshold = a.num("threshold", 10);
  o.seed = static_cast<std::uint64_t>(a.num("seed", 1));
  if (a.has("candidates")) o.candidates = splitList(a.get("candidates"), ',');
  o.progress = !a.has("quiet");
  if (a.has("verbose")) o.log = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
  WorkerPool& pool = WorkerPool::global();
  std::printf("diagnose %s: %zu runs, %zu samples, level %s, %d folds, %d worker processes\n", ds.name.c_str(), ds.runs.size(),
              ds.sampleCount(), o.base.level.c_str(), o.folds, pool.size());
  const DiagnoseResult r = diagnose(ds, o, pool);
  for (std::size_t i = 0; i < r.rounds.size(); ++i) {
    const auto& rd = r.rounds[i];
    std::printf("\nstep %zu: candidates ranked by held-out evidence (current held-out RSS %.1f)\n", i + 1,
                rd.current_cv_rss);
    std::printf("  %-26s %12s %10s %8s %6s  %s\n", "effect", "dBIC", "error", "rho1", "folds", "fold estimates");
    for (const auto& s : rd.ranked) {
      std::ostringstream fv;
      for (std::size_t f = 0; f < s.fold_values.size(); ++f) {
        fv << (f ? " | " : "");
        for (std::size_t j = 0; j < s.fold_values[f].size(); ++j)
          fv << (j ? "," : "") << std::setprecision(4) << s.fold_values[f][j];
      }
      std::printf("  %-26s %12.1f %10s %8.2f %6s  %s%s\n", s.effect.c_str(), s.delta_bic,
                  pct(-100 * s.reduction).c_str(), s.rho1, s.all_folds_improve ? "all" : "mixed", fv.str().c_str(),
                  s.effect == rd.accepted ? "   <- accepted" : "");
    }
  }
  std::printf("\n%s", r.verdict.c_str());
  std::printf("diagnose took %.1f s wall, %d run simulations, %d worker processes\n", r.seconds, r.simulations, pool.size());
  if (a.has("write-effects") && !r.accepted.empty()) {
    std::vector<EffectConfig> cfg = r.final_model.effects;
    for (auto& c : cfg)
      for (std::size_t j = 0; j < r.final_fit.free.size(); ++j)
        if (r.final_fit.model.effects[r.final_fit.free[j].effect].name == c.name)
          c.stderr_[r.final_fit.free[j].name] = r.final_fit.stderr_[j];
    writeEffectsFile(a.get("write-effects"), cfg, "accepted by sbot_calibrate diagnose " + ds.yaml_path);
    std::printf("effects written to %s\n", a.get("write-effects").c_str());
  }
  return 0;
}

int cmdFit(const Args& a) {
  if (a.positional.empty()) throw std::invalid_argument("fit needs a DATASET");
  const auto names = a.all("effect");
  if (names.empty()) throw std::invalid_argument("fit needs --effect NAME");
  if (!a.has("out")) throw std::invalid_argument("fit needs --out FILE (the effects file to write)");
  const Dataset ds = datasetFor(a);
  ModelSpec m = baseModel(ds, a);
  std::vector<int> idx;
  for (const auto& n0 : names)
    for (const auto& n : splitList(n0, ',')) {
      EffectRegistry::instance().info(n);  // throws on unknown
      bool found = false;
      for (std::size_t i = 0; i < m.effects.size(); ++i)
        if (m.effects[i].name == n) {
          idx.push_back(static_cast<int>(i));
          found = true;
        }
      if (!found) {
        m.effects.push_back({n, {}, {}, ""});
        idx.push_back(static_cast<int>(m.effects.size()) - 1);
      }
    }
  FitOptions fo;
  WorkerPool& pool = WorkerPool::global();
  std::size_t evals = 0;
  const bool quiet = a.has("quiet");
  fo.on_evaluation = [&] {
    ++evals;
    if (!quiet) std::fprintf(stderr, "\rfitting: %zu re-simulation batches", evals);
  };
  const auto t0 = std::chrono::steady_clock::now();
  const FitResult r = fitModel(ds, m, freeParamsOf(m, idx), allRuns(ds), fo, pool);
  if (!quiet) std::fprintf(stderr, "\n");
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("fit on %zu runs (%zu samples), %d iterations, %d batches, %.1f s%s\n", ds.runs.size(), r.n, r.iterations,
              r.evaluations, secs, r.converged ? "" : " (iteration limit)");
  std::vector<EffectConfig> cfg = r.model.effects;
  for (std::size_t j = 0; j < r.free.size(); ++j) {
    const FreeParam& p = r.free[j];
    std::printf("  %s.%s = %.6g +- %.2g %s (95 %%)\n", r.model.effects[p.effect].name.c_str(), p.name.c_str(),
                r.value[j], 1.96 * r.stderr_[j], p.spec.unit.c_str());
    cfg[p.effect].stderr_[p.name] = r.stderr_[j];
    cfg[p.effect].note = "fitted by sbot_calibrate fit on " + ds.name;
  }
  std::printf("normalised RMS: %.4f -> %.4f\n", std::sqrt(r.rss_start / std::max<std::size_t>(1, r.n)),
              std::sqrt(r.rss / std::max<std::size_t>(1, r.n)));
  writeEffectsFile(a.get("out"), cfg, "sbot_calibrate fit " + ds.yaml_path);
  std::printf("effects written to %s\n", a.get("out").c_str());
  return 0;
}

int cmdGenerate(const Args& a) {
  if (!a.has("out")) throw std::invalid_argument("generate needs --out DIR");
  GeneratorOptions g;
  g.level = a.get("level", "simple");
  g.solver = a.get("solver", "quickstep");
  g.seed = static_cast<std::uint64_t>(a.num("seed", 1));
  g.duration = a.num("duration", 8);
  g.tilt_deg = a.num("tilt", 0);
  g.repeat = static_cast<int>(a.num("repeat", 1));
  g.max_runs = static_cast<std::size_t>(a.num("max-runs", 0));
  g.name = a.get("name", "synthetic");
  g.measure_torque = a.has("torque");
  g.measure_tilt = !a.has("no-tilt");
  g.measure_speed = !a.has("no-speed");
  if (a.has("families"))
    for (const auto& f : splitList(a.get("families"), ',')) g.experiments.insert(f);
  if (a.has("hidden")) g.hidden = loadEffectsConfig(a.get("hidden"));
  if (a.has("hide"))
    for (const auto& e : parseEffectList(a.get("hide"), "--hide")) g.hidden.push_back(e);
  const Dataset ds = generateDataset(g, WorkerPool::global());
  writeDataset(ds, a.get("out"));
  std::printf("wrote %s: %zu runs, %zu samples (level %s, seed %llu)\n", a.get("out").c_str(), ds.runs.size(),
              ds.sampleCount(), g.level.c_str(), static_cast<unsigned long long>(g.seed));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Args a = parse(argc, argv);
    if (a.cmd.empty() || a.cmd == "--help" || a.cmd == "help" || a.has("help")) {
      usage();
      return a.cmd.empty() ? 2 : 0;
    }
    checkOptions(a);
    checkOutputs(a);
    if (a.has("jobs")) WorkerPool::setGlobalSize(static_cast<int>(a.num("jobs", 0)));
    if (a.cmd == "effects") return cmdEffects();
    if (a.cmd == "compare") return cmdCompare(a);
    if (a.cmd == "diagnose") return cmdDiagnose(a);
    if (a.cmd == "fit") return cmdFit(a);
    if (a.cmd == "generate") return cmdGenerate(a);
    if (a.cmd == "sweep") return runSweepCommand(a.opts, a.flags);
    usage();
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sbot_calibrate: %s\n", e.what());
    return 1;
  }
}
