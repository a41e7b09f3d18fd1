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
//           --solver quickstep|exact (replaces the dataset's world stepper) and --skip-runs a,b;
//           diagnose/fit/sweep leave out the runs the start model cannot replay until the model they end
//           with can (--keep-chaotic keeps them)
// Output places (--out, --write-effects) are created and checked before the work: a fit or a
// diagnosis runs for minutes, and its result must not be lost to an unwritable path at the end. They
// are checked after the input (dataset, effects, option values), so a refused run creates no folder.
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "calibration/diagnose.h"
#include "calibration/effect_list.h"
#include "calibration/generator.h"
#include "calibration/parallel.h"
#include "calibration/report.h"
#include "calibration/sweep.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/tools/cli_args.h"

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
  /// A finite number (strtod also reads "nan" and "inf", which no option means).
  double num(const std::string& k, double def) const {
    if (!opts.count(k)) return def;
    char* end = nullptr;
    const std::string s = get(k);
    const double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end) throw std::invalid_argument("--" + k + " expects a number, got '" + s + "'");
    if (!std::isfinite(v)) throw std::invalid_argument("--" + k + " expects a finite number, got '" + s + "'");
    return v;
  }
  /// A whole number in [lo, hi] (`why`: what the bound means, may be empty). Not strtod's: "2.5"
  /// folds or a seed beyond 2^63 would be cut silently.
  long long whole(const std::string& k, long long def, long long lo, long long hi, const std::string& why = "") const {
    if (!opts.count(k)) return def;
    const std::string s = get(k);
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    const bool starts = !s.empty() && (std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '-' || s[0] == '+');
    if (starts && end != s.c_str() && !*end && errno != ERANGE && v >= lo && v <= hi) return v;
    const std::string range = hi == INT_MAX ? "of at least " + std::to_string(lo)
                                              : "from " + std::to_string(lo) + " to " + std::to_string(hi);
    throw std::invalid_argument("--" + k + " expects a whole number " + range + (why.empty() ? "" : " (" + why + ")") +
                                ", got '" + s + "'");
  }
};

/// An unknown subcommand: named, then the usage.
struct UnknownCommand : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

const std::set<std::string> kFlags{"no-plots", "quiet",   "no-align",     "torque", "no-tilt",
                                   "no-speed", "verbose", "keep-chaotic", "help"};

/// The options each subcommand reads (besides --jobs, --quiet, --help). Anything else is refused:
/// a misspelt option would otherwise be ignored, e.g. `compare --effect F` comparing the nominal model.
const std::map<std::string, std::set<std::string>> kCommandOptions{
    {"compare", {"effects", "level", "solver", "out", "no-plots", "no-align", "skip-runs"}},
    {"diagnose", {"effects", "level", "solver", "folds", "threshold", "seed", "candidates", "write-effects", "verbose",
                  "skip-runs", "keep-chaotic"}},
    {"fit", {"effect", "effects", "level", "solver", "out", "max-iterations", "skip-runs", "keep-chaotic"}},
    {"generate", {"out", "level", "solver", "seed", "duration", "tilt", "repeat", "max-runs", "name", "torque",
                  "no-tilt", "no-speed", "families", "hidden", "hide"}},
    {"sweep", {"cases", "set", "seeds", "first-seed", "level", "solver", "duration", "folds", "threshold", "torque",
               "keep-chaotic", "out"}},
    {"effects", {}}};

/// Refuse an option the subcommand does not read (a misspelt one would otherwise be ignored).
void refuseUnknownOption(const std::string& cmd, const std::string& k) {
  auto it = kCommandOptions.find(cmd);
  if (it == kCommandOptions.end()) return;  // help (parse() refuses unknown commands)
  if (it->second.count(k) || k == "jobs" || k == "quiet" || k == "help") return;
  std::string accepted;
  for (const auto& o : it->second) accepted += " --" + o;
  throw std::invalid_argument("unknown option --" + k + " for '" + cmd + "' (it takes" +
                              (accepted.empty() ? std::string(" none") : accepted) + ", and --jobs, --quiet)");
}

bool isHelp(const std::string& cmd) { return cmd == "--help" || cmd == "help" || cmd == "-h"; }

Args parse(int argc, char** argv) {
  Args a;
  if (argc < 2) return a;
  a.cmd = argv[1];
  if (!kCommandOptions.count(a.cmd) && !isHelp(a.cmd)) {
    std::string known;
    for (const auto& [c, o] : kCommandOptions) known += (known.empty() ? "" : ", ") + c;
    throw UnknownCommand("unknown command '" + a.cmd + "' (commands: " + known + ")");
  }
  for (int i = 2; i < argc; ++i) {
    std::string s = argv[i];
    if (s.rfind("--", 0) == 0) {
      s = s.substr(2);
      const auto eq = s.find('=');
      if (eq != std::string::npos) {
        if (kFlags.count(s.substr(0, eq)))  // --no-align=false must not turn alignment off
          throw std::invalid_argument("--" + s.substr(0, eq) + " is a flag and takes no value, found '" + argv[i] + "'");
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

/// Refuse unknown options, an option given twice (the first copy would win silently; only --effect
/// adds up) and arguments beyond the DATASET the command takes.
void checkOptions(const Args& a) {
  for (const auto& [k, v] : a.opts) refuseUnknownOption(a.cmd, k);
  for (const auto& k : a.flags) refuseUnknownOption(a.cmd, k);
  for (auto it = a.opts.begin(); it != a.opts.end(); it = a.opts.upper_bound(it->first)) {
    if (it->first == "effect" || a.opts.count(it->first) < 2) continue;
    std::string values;
    for (const auto& v : a.all(it->first)) values += (values.empty() ? "'" : ", '") + v + "'";
    throw std::invalid_argument("--" + it->first + " is given " + std::to_string(a.opts.count(it->first)) +
                                " times (" + values + "): give it once");
  }
  const std::size_t takes = a.cmd == "compare" || a.cmd == "diagnose" || a.cmd == "fit" ? 1 : 0;
  if (a.positional.size() > takes)
    throw std::invalid_argument("unexpected argument '" + a.positional[takes] + "' ('" + a.cmd + "' takes " +
                                (takes ? "one DATASET" : "options only") + ")");
}

/// compare's report directory when --out is not given.
const char* const kDefaultReportDir = "calibration_report";

/// Folders the output checks created, removed again (if still empty) when the run ends in an error.
std::vector<std::string> g_created_dirs;

void removeCreatedDirs() {
  for (auto it = g_created_dirs.rbegin(); it != g_created_dirs.rend(); ++it) ::rmdir(it->c_str());
  g_created_dirs.clear();
}

/// The folders of `dir` (itself included) that do not exist, outermost first.
std::vector<std::string> missingDirs(std::string dir) {
  std::vector<std::string> out;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  while (!dir.empty() && dir != "/" && ::access(dir.c_str(), F_OK) != 0) {
    out.insert(out.begin(), dir);
    const std::size_t slash = dir.find_last_of('/');
    if (slash == std::string::npos) break;
    dir = dir.substr(0, slash);
  }
  return out;
}

std::string parentOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
}

/// Creating a file is the only test that both the permission bits and special filesystems answer
/// truly: root may "write" in /proc by access(2), yet cannot create a file there. An existing file
/// is opened without truncation; a new one (or a probe in a folder) is removed again.
void probeWrite(const std::string& path, bool directory) {
  int fd = -1;
  std::string created;
  if (directory) {
    std::string probe = path + "/.sbot_calibrate_probe_XXXXXX";
    fd = ::mkstemp(&probe[0]);
    if (fd >= 0) created = probe;
  } else if (::access(path.c_str(), F_OK) == 0) {
    fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
  } else {
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd >= 0) created = path;
  }
  if (fd < 0) throw OutputError("cannot write " + std::string(directory ? "in directory '" : "'") + path + "': " + std::strerror(errno));
  ::close(fd);
  if (!created.empty()) ::unlink(created.c_str());
}

/// An output place refused before the work (exit status 2), unlike a write that fails during it.
class OutputPlaceRefused : public OutputError {
 public:
  using OutputError::OutputError;
};

/// The output place `path` of `--option` (a folder, or a file) exists (folders created) and can be
/// written (output_files.h, then probeWrite); else an OutputError that names the option, with the
/// folders this check created removed again.
void checkOutputPlace(const std::string& option, const std::string& path, bool directory) {
  const std::vector<std::string> missing = missingDirs(directory ? path : parentOf(path));
  try {
    if (directory) makeOutputDirectory(path);
    else checkOutputFile(path);
    probeWrite(path, directory);
  } catch (const OutputError& e) {
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) ::rmdir(it->c_str());
    throw OutputPlaceRefused("--" + option + ": " + e.what());
  }
  g_created_dirs.insert(g_created_dirs.end(), missing.begin(), missing.end());
}

/// An output file of `--option` that is one of the dataset's own files (its dataset.yaml, a run's
/// CSV) is refused: `fit --out DATASET/dataset.yaml` replaced the dataset with an effects file.
void refuseDatasetFile(const std::string& option, const std::string& path, const Dataset& ds) {
  char out[PATH_MAX];
  if (!::realpath(path.c_str(), out)) return;  // a new file is nobody's input
  std::vector<std::string> inputs{ds.yaml_path};
  for (const Run& r : ds.runs) inputs.push_back(r.path);
  for (const std::string& input : inputs) {
    char in[PATH_MAX];
    if (::realpath(input.c_str(), in) && std::strcmp(in, out) == 0)
      throw OutputPlaceRefused("--" + option + ": '" + path + "' is the dataset's own " + input +
                        "; write the result elsewhere (the dataset is the measurement)");
  }
}

/// A folder with something in it (a dataset written there would overwrite and mix with its files).
bool isNonEmptyDirectory(const std::string& path) {
  DIR* d = ::opendir(path.c_str());
  if (!d) return false;
  bool empty = true;
  while (const dirent* e = ::readdir(d))
    if (std::strcmp(e->d_name, ".") && std::strcmp(e->d_name, "..")) {
      empty = false;
      break;
    }
  ::closedir(d);
  return !empty;
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
               "  fit      DATASET --effect NAME [--effect NAME2] [--effects BASE] [--max-iterations N] --out FILE\n"
               "  generate --out DIR [--level simple] [--solver quickstep|exact] [--seed N] [--hidden FILE] [--hide name:p=v+name2:p=v]\n"
               "           [--tilt DEG] [--duration S] [--families straight,spin,arc,square,steps,place,approach] [--repeat N]\n"
               "           [--max-runs N] [--name NAME] [--torque] [--no-tilt] [--no-speed]\n"
               "  sweep    [--out FILE.md] [--seeds N] [--cases a,b] [--level L] [--solver S] [--duration S]\n"
               "           [--set name:p=v+name2:p=v]  (another magnitude for the cases that hide those effects) [--keep-chaotic]\n"
               "  effects  list the effects library\n"
               "common options: --jobs N (worker processes; default all cores), --quiet;\n"
               "  compare/diagnose/fit: --solver quickstep|exact replaces the dataset's world stepper,\n"
               "    --skip-runs a,b leaves those runs out; diagnose/fit/sweep leave out the runs the start model does\n"
               "    not reproduce, and solve again with those the model they end with does (named; --keep-chaotic keeps them)\n");
}

/// --solver (the world's stepper), checked.
std::string solverOption(const Args& a, const std::string& def) {
  const std::string s = a.get("solver", def);
  if (s != "quickstep" && s != "exact") throw std::invalid_argument("--solver expects quickstep or exact, got '" + s + "'");
  return s;
}

/// The dataset, with --solver replacing its world's stepper (quickstep | exact): whether a misfit is
/// the model's physics or quickstep's non-convergence, without editing the dataset.
Dataset datasetFor(const Args& a) {
  Dataset ds = loadDataset(a.positional[0]);
  if (a.has("solver")) ds.world.solver = solverOption(a, "");
  if (a.has("skip-runs")) {
    const auto names = splitList(a.get("skip-runs"), ',');
    ds = withoutRuns(ds, std::set<std::string>(names.begin(), names.end()));
  }
  return ds;
}

/// The effects file of --effects, checked against the dataset's surfaces too (effect_list.h).
std::vector<EffectConfig> effectsOption(const Dataset& ds, const Args& a) {
  return loadCheckedEffects(a.get("effects"), ds.obstacleSurfaces());
}

/// The model to start from: --level (default the dataset's) and the --effects file's effects.
ModelSpec baseModel(const Dataset& ds, const Args& a) {
  ModelSpec m{a.get("level", ds.robot), {}};
  loadLevel(m.level);  // an unknown level is named now, not by the first replay
  if (const std::string why = impossiblePlacement(ds, m.level); !why.empty()) throw std::invalid_argument(why);
  if (a.has("effects")) m.effects = effectsOption(ds, a);
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
  const ModelSpec with_effects = baseModel(ds, a);
  const ModelSpec nominal{with_effects.level, {}};
  std::vector<std::pair<std::string, ModelSpec>> variants{{"nominal", nominal}};
  // Waterfall: add the file's effects one by one.
  ModelSpec m = nominal;
  for (const auto& e : with_effects.effects) {
    m.effects.push_back(e);
    variants.push_back({"+" + e.name, m});
  }
  CompareOptions co;
  co.out_dir = a.get("out", kDefaultReportDir);
  co.plots = !a.has("no-plots");
  co.eval.replay.align = !a.has("no-align");
  checkOutputPlace("out", co.out_dir, true);
  const auto sums = writeCompareReport(ds, variants, co, WorkerPool::global());
  std::printf("%-28s %-60s %10s\n", "model", "effects", "nRMS");
  for (const auto& s : sums) std::printf("%-28s %-60s %10.4f\n", s.label.c_str(), s.model.describe().c_str(), s.nrms);
  for (const auto& s : sums)
    if (const std::string chaotic = describeChaoticRuns(ds, s.sensitivity); !chaotic.empty())
      std::printf("note: not reproducible under %s (a start +-%g sigma of the tracker noise away moves the prediction by more "
                  "than %g noise): %s; their residuals are not evidence of a missing effect\n",
                  s.label.c_str(), kStartNudge, kChaoticSensitivity, chaotic.c_str());
  if (sums.size() > 1)
    std::printf("error change (nRMS): %.4f -> %.4f (%s)\n", sums.front().nrms, sums.back().nrms,
                pct(100 * (sums.back().nrms / sums.front().nrms - 1)).c_str());
  std::printf("report: %s/report.md\n", co.out_dir.c_str());
  return 0;
}

/// Candidate effects named by --candidates, each once and each one the dataset can show.
std::vector<std::string> namedCandidates(const Dataset& ds, const Args& a) {
  std::vector<std::string> out;
  for (const auto& n : splitList(a.get("candidates"), ',')) {
    requireEffect(n, "--candidates");
    if (std::find(out.begin(), out.end(), n) != out.end())
      throw std::invalid_argument("--candidates names " + n + " twice");
    for (const std::string& why : {unmeasuredChannels(ds, n), missingSurfaces(ds, n)})
      if (!why.empty()) throw std::invalid_argument("--candidates: " + why + ": it cannot be screened");
    out.push_back(n);
  }
  if (out.empty()) throw std::invalid_argument("--candidates names no effect");
  return out;
}

/// Says which library effects the automatic candidate list leaves out, and why.
void printSkippedCandidates(const Dataset& ds) {
  const std::vector<std::string> cands = candidateEffects(ds);
  std::map<std::string, std::string> by_channels;  // "ir, ground" -> "ir_incidence, ir_ambient"
  for (const auto& n : EffectRegistry::instance().names()) {
    if (std::find(cands.begin(), cands.end(), n) != cands.end()) continue;
    if (const std::string why = missingSurfaces(ds, n); !why.empty() && unmeasuredChannels(ds, n).empty()) {
      std::printf("note: not screened: %s\n", why.c_str());
      continue;
    }
    std::string channels;
    for (const auto& c : EffectRegistry::instance().info(n).channels) channels += (channels.empty() ? "" : ", ") + c;
    by_channels[channels] += (by_channels[channels].empty() ? "" : ", ") + n;
  }
  if (by_channels.empty()) return;
  std::string list;
  for (const auto& [channels, effects] : by_channels) list += (list.empty() ? "" : "; ") + effects + " (" + channels + ")";
  std::printf("note: not screened, the dataset measures none of the channels they act on: %s\n", list.c_str());
}

int cmdDiagnose(const Args& a) {
  if (a.positional.empty()) throw std::invalid_argument("diagnose needs a DATASET");
  DiagnoseOptions o;
  const Dataset measured = datasetFor(a);
  o.base = baseModel(measured, a);
  o.folds = static_cast<int>(a.whole("folds", 2, 2, INT_MAX, "each fold's runs are scored by a fit on the others"));
  o.bic_threshold = a.num("threshold", 10);
  o.seed = static_cast<std::uint64_t>(a.whole("seed", 1, 0, LLONG_MAX));
  if (a.has("candidates")) o.candidates = namedCandidates(measured, a);
  o.progress = !a.has("quiet");
  if (a.has("verbose")) o.log = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
  if (a.has("write-effects")) {
    refuseDatasetFile("write-effects", a.get("write-effects"), measured);
    checkOutputPlace("write-effects", a.get("write-effects"), false);
  }
  WorkerPool& pool = WorkerPool::global();
  // On the runs the start model replays reproducibly, and again with those the diagnosed model
  // replays too (evaluation.h, solveOnReplayableRuns).
  std::vector<DiagnoseResult> results;  // per round
  const auto t0 = std::chrono::steady_clock::now();
  const ReplayableRounds rounds = solveOnReplayableRuns(measured, o.base, o.fit.eval, a.has("keep-chaotic"), pool,
                                                        [&](const Dataset& ds, const std::string& message) {
    if (!message.empty()) std::printf("%s\n", message.c_str());
    // The runs left must still measure what the named candidates act on.
    if (a.has("candidates") && ds.runs.size() < measured.runs.size()) o.candidates = namedCandidates(ds, a);
    const int folds = foldCount(ds, o.folds);
    std::printf("diagnose %s: %zu runs, %zu samples, level %s, %d fold%s, %d worker process%s\n", ds.name.c_str(),
                ds.runs.size(), ds.sampleCount(), o.base.level.c_str(), folds, folds == 1 ? "" : "s", pool.size(),
                pool.size() == 1 ? "" : "es");
    if (folds < o.folds)
      std::printf("note: --folds %d, but a fold holds out whole runs and the dataset has %zu run%s: %d fold%s\n", o.folds,
                  ds.runs.size(), ds.runs.size() == 1 ? "" : "s", folds, folds == 1 ? " (scores in-sample)" : "s");
    if (o.candidates.empty() && results.empty()) printSkippedCandidates(ds);  // the runs added measure the same channels
    results.push_back(diagnose(ds, o, pool));
    return results.back().final_model;
  });
  if (!rounds.note.empty()) std::printf("%s\n", rounds.note.c_str());
  const Dataset& ds = rounds.dataset;
  const DiagnoseResult& r = results.at(rounds.round - 1);
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
  if (!rounds.left_out.empty()) {
    // The verdict is on the runs kept: what only the runs left out show was not looked at, and
    // those may be the runs that show the missing effect best (a Fast latency shows in its spins).
    std::string names;
    for (const auto& n : rounds.left_out) names += (names.empty() ? "" : ", ") + n;
    std::printf("  on %zu of %zu runs: %s %s left out as not reproducible, and what only they show is not in this "
                "verdict; read their plots (compare) or see what a fit to them finds (--keep-chaotic)\n",
                ds.runs.size(), measured.runs.size(), names.c_str(), rounds.left_out.size() == 1 ? "was" : "were");
  }
  std::printf("diagnose took %.1f s wall, %d run simulations, %d worker process%s", r.seconds, r.simulations, pool.size(),
              pool.size() == 1 ? "" : "es");
  if (results.size() > 1)
    std::printf(" (round %d; %.1f s for all %zu rounds)", rounds.round,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), results.size());
  std::printf("\n");
  if (a.has("write-effects")) {
    // Also with nothing accepted: the file then holds the model diagnose ends with (the nominal one,
    // or --effects' base), so that the next step (compare --effects FILE) works either way.
    std::vector<EffectConfig> cfg = r.final_model.effects;
    for (auto& c : cfg)
      for (std::size_t j = 0; j < r.final_fit.free.size(); ++j)
        if (r.final_fit.model.effects[r.final_fit.free[j].effect].name == c.name)
          c.stderr_[r.final_fit.free[j].name] = r.final_fit.stderr_[j];
    writeEffectsFile(a.get("write-effects"), cfg, "accepted by sbot_calibrate diagnose " + ds.yaml_path);
    if (!r.accepted.empty()) std::printf("effects written to %s\n", a.get("write-effects").c_str());
    else if (cfg.empty()) std::printf("no effect accepted: %s written with no effects (the nominal model)\n", a.get("write-effects").c_str());
    else std::printf("no effect accepted: %s written with the --effects base model only\n", a.get("write-effects").c_str());
  }
  return 0;
}

int cmdFit(const Args& a) {
  if (a.positional.empty()) throw std::invalid_argument("fit needs a DATASET");
  std::vector<std::string> names;
  for (const auto& given : a.all("effect"))
    for (const auto& n : splitList(given, ',')) {
      requireEffect(n, "--effect");
      if (std::find(names.begin(), names.end(), n) != names.end())
        throw std::invalid_argument("--effect " + n + " is given twice");
      names.push_back(n);
    }
  if (names.empty()) throw std::invalid_argument("fit needs --effect NAME");
  if (!a.has("out")) throw std::invalid_argument("fit needs --out FILE (the effects file to write)");
  const Dataset measured = datasetFor(a);
  ModelSpec m = baseModel(measured, a);
  const ModelSpec start = m;
  std::vector<int> idx;
  for (const auto& n : names) {
    if (const std::string why = unmeasuredChannels(measured, n); !why.empty())
      throw std::invalid_argument("--effect: " + why + ": there is nothing to fit it to");
    int at = -1;
    for (std::size_t i = 0; i < m.effects.size(); ++i)
      if (m.effects[i].name == n) at = static_cast<int>(i);
    if (at < 0) {
      // As diagnose does: per-surface parameters for the surfaces of the dataset's obstacles.
      m.effects.push_back(EffectRegistry::instance().info(n).open_params ? candidateConfig(measured, n)
                                                                         : EffectConfig{n, {}, {}, ""});
      at = static_cast<int>(m.effects.size()) - 1;
    }
    if (freeParamsOf(m, {at}).empty())
      throw std::invalid_argument("--effect: " + n + " has one parameter per surface, and neither the dataset's obstacles "
                                  "nor an --effects file name a surface: list those to fit in an --effects BASE file, e.g. "
                                  "effects: [{name: " + n + ", params: {white_paper: 1, black_card: 1}}]");
    idx.push_back(at);
  }
  FitOptions fo;
  fo.max_iterations = static_cast<int>(a.whole("max-iterations", fo.max_iterations, 1, 1000, "Levenberg-Marquardt iterations"));
  refuseDatasetFile("out", a.get("out"), measured);
  checkOutputPlace("out", a.get("out"), false);
  WorkerPool& pool = WorkerPool::global();
  std::size_t evals = 0;
  const bool quiet = a.has("quiet");
  fo.on_evaluation = [&] {
    ++evals;
    if (!quiet) std::fprintf(stderr, "\rfitting: %zu re-simulation batches", evals);
  };
  // On the runs the start model replays reproducibly, and again, from the start, with those the
  // fitted model replays too (evaluation.h, solveOnReplayableRuns). A fit keeps its effects in every
  // round, so its last round stands.
  Dataset ds;
  FitResult r;
  solveOnReplayableRuns(measured, start, EvalOptions(), a.has("keep-chaotic"), pool,
                        [&](const Dataset& runs, const std::string& message) {
    if (!message.empty()) std::printf("%s\n", message.c_str());
    ds = runs;
    for (const auto& n : names)
      if (const std::string why = unmeasuredChannels(ds, n); !why.empty())
        throw std::invalid_argument("--effect: " + why + " in the runs left: there is nothing to fit it to");
    evals = 0;
    const auto t0 = std::chrono::steady_clock::now();
    r = fitModel(ds, m, freeParamsOf(m, idx), allRuns(ds), fo, pool);
    if (!quiet) std::fprintf(stderr, "\n");
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("fit on %zu runs (%zu samples), %d iterations, %d batches, %.1f s%s\n", ds.runs.size(), r.n, r.iterations,
                r.evaluations, secs, r.converged ? "" : " (iteration limit)");
    return r.model;
  });
  // A fit stopped by its iteration limit is not at a minimum: the curvature there gives an interval
  // about a point the data do not single out (accel_limit 2.103 +- 0.002 for a true 2.0). Its values
  // are written, as a start for another fit, but with no interval.
  std::vector<EffectConfig> cfg = r.model.effects;
  for (std::size_t j = 0; j < r.free.size(); ++j) {
    const FreeParam& p = r.free[j];
    if (r.converged) {
      std::printf("  %s.%s = %.6g +- %.2g %s (95 %%)\n", r.model.effects[p.effect].name.c_str(), p.name.c_str(),
                  r.value[j], 1.96 * r.stderr_[j], p.spec.unit.c_str());
      cfg[p.effect].stderr_[p.name] = r.stderr_[j];
      cfg[p.effect].note = "fitted by sbot_calibrate fit on " + ds.name;
    } else {
      std::printf("  %s.%s = %.6g %s (no interval: not converged)\n", r.model.effects[p.effect].name.c_str(),
                  p.name.c_str(), r.value[j], p.spec.unit.c_str());
      cfg[p.effect].stderr_.erase(p.name);
      cfg[p.effect].note = "not converged: sbot_calibrate fit on " + ds.name + " stopped at its iteration limit (" +
                           std::to_string(fo.max_iterations) + ")";
    }
  }
  if (!r.converged)
    std::fprintf(stderr,
                 "sbot_calibrate: warning: the fit stopped at its iteration limit (%d) before converging: the values "
                 "are written without intervals; fit again from them (--effects %s) or with more --max-iterations\n",
                 fo.max_iterations, a.get("out").c_str());
  std::printf("normalised RMS: %.4f -> %.4f", std::sqrt(r.rss_start / std::max<std::size_t>(1, r.n)),
              std::sqrt(r.rss / std::max<std::size_t>(1, r.n)));
  if (ds.runs.size() == measured.runs.size()) {
    std::printf("\n");
  } else {
    // The runs left out as chaotic count in compare's figure: say both, or the fit's figure reads
    // as a promise compare does not keep (2.25 -> 2.20 here, 6.02 -> 5.24 in compare, Fast).
    const Evaluation before = evaluate(measured, start, allRuns(measured), EvalOptions(), pool);
    const Evaluation after = evaluate(measured, r.model, allRuns(measured), EvalOptions(), pool);
    std::printf(" on the %zu runs fitted; %.4f -> %.4f on all %zu runs (what compare reports)\n", ds.runs.size(),
                before.rmsNormalised(), after.rmsNormalised(), measured.runs.size());
  }
  writeEffectsFile(a.get("out"), cfg, "sbot_calibrate fit " + ds.yaml_path);
  std::printf("effects written to %s\n", a.get("out").c_str());
  return 0;
}

int cmdGenerate(const Args& a) {
  if (!a.has("out")) throw std::invalid_argument("generate needs --out DIR");
  GeneratorOptions g;
  g.level = a.get("level", "simple");
  g.solver = solverOption(a, "quickstep");
  g.seed = static_cast<std::uint64_t>(a.whole("seed", 1, 0, LLONG_MAX));
  g.duration = a.num("duration", 8);
  g.tilt_deg = a.num("tilt", 0);
  g.repeat = static_cast<int>(a.whole("repeat", 1, 1, INT_MAX));
  g.max_runs = static_cast<std::size_t>(a.whole("max-runs", 0, 0, INT_MAX, "0: all"));
  g.name = a.get("name", "synthetic");
  g.measure_torque = a.has("torque");
  g.measure_tilt = !a.has("no-tilt");
  g.measure_speed = !a.has("no-speed");
  if (a.has("families"))
    for (const auto& f : splitList(a.get("families"), ',')) g.experiments.insert(f);
  loadLevel(g.level);
  checkGeneratorOptions(g);
  if (a.has("hidden")) g.hidden = loadCheckedEffects(a.get("hidden"));
  if (a.has("hide"))
    for (const auto& e : parseEffectList(a.get("hide"), "--hide")) g.hidden.push_back(e);
  // A dataset folder may hold real measurements: writing into it would overwrite its dataset.yaml
  // and leave its other runs' files beside the new ones.
  if (isNonEmptyDirectory(a.get("out")))
    throw std::invalid_argument("--out " + a.get("out") + " is a folder that is not empty (a dataset written there would " +
                                "overwrite its files and mix with the rest): remove it or choose another folder");
  checkOutputPlace("out", a.get("out"), true);
  GeneratedTruth truth;
  const Dataset ds = generateDataset(g, WorkerPool::global(), &truth);
  writeDataset(ds, a.get("out"));
  std::printf("wrote %s: %zu runs, %zu samples (level %s, seed %llu)\n", a.get("out").c_str(), ds.runs.size(),
              ds.sampleCount(), g.level.c_str(), static_cast<unsigned long long>(g.seed));
  // Runs that even the true model cannot replay (evaluation.h): a dataset full of them tests nothing.
  EvalOptions eo;
  eo.world_override = &truth.world;
  eo.replay.tilt = truth.tilt_deg * M_PI / 180;
  eo.replay.tilt_direction = truth.tilt_direction;
  const ModelSpec true_model{g.level, truth.hidden};
  if (const std::string chaotic = describeChaoticRuns(ds, replaySensitivity(ds, true_model, eo, WorkerPool::global()));
      !chaotic.empty())
    std::printf("note: the true model itself does not reproduce these runs (a start +-%g sigma of the tracker noise away "
                "moves them by more than %g noise): %s; leave them out (--families) to test effects on this level\n",
                kStartNudge, kChaoticSensitivity, chaotic.c_str());
  return 0;
}

int cmdSweep(const Args& a) {
  SweepOptions o;
  o.gen.level = a.get("level", "simple");
  loadLevel(o.gen.level);
  o.gen.solver = solverOption(a, "quickstep");
  o.gen.duration = a.num("duration", 8);
  o.gen.measure_torque = a.has("torque");
  checkGeneratorOptions(o.gen);
  o.seeds = static_cast<int>(a.whole("seeds", 10, 1, 10000, "synthetic datasets per case"));
  o.first_seed = static_cast<std::uint64_t>(a.whole("first-seed", 1, 0, LLONG_MAX));
  o.diag.folds = static_cast<int>(a.whole("folds", 2, 2, INT_MAX, "each fold's runs are scored by a fit on the others"));
  o.diag.bic_threshold = a.num("threshold", 10);
  o.keep_chaotic = a.has("keep-chaotic");
  o.progress = !a.has("quiet");
  std::vector<std::string> names;
  if (a.has("cases")) {
    names = splitList(a.get("cases"), ',');
    if (names.empty()) throw std::invalid_argument("--cases expects a list of sweep case names, got ''");
  }
  o.cases = selectSweepCases(o.gen.level, names, a.has("set") ? parseEffectList(a.get("set"), "--set") : std::vector<EffectConfig>{});
  if (a.has("out")) checkOutputPlace("out", a.get("out"), false);
  const auto t0 = std::chrono::steady_clock::now();
  const auto res = runSweep(o, WorkerPool::global());
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string md = sweepMarkdown(res, o, secs);
  std::printf("%s", md.c_str());
  if (a.has("out")) writeTextFile(a.get("out"), md);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Args a = parse(argc, argv);
    if (a.cmd.empty() || isHelp(a.cmd) || a.has("help")) {
      usage();
      return a.cmd.empty() ? 2 : 0;
    }
    checkOptions(a);
    if (a.has("jobs")) WorkerPool::setGlobalSize(static_cast<int>(a.whole("jobs", 0, 1, INT_MAX, "worker processes")));
    if (a.cmd == "effects") return cmdEffects();
    if (a.cmd == "compare") return cmdCompare(a);
    if (a.cmd == "diagnose") return cmdDiagnose(a);
    if (a.cmd == "fit") return cmdFit(a);
    if (a.cmd == "generate") return cmdGenerate(a);
    return cmdSweep(a);
  } catch (const UnknownCommand& e) {
    std::fprintf(stderr, "sbot_calibrate: %s\n", e.what());
    usage();
    return 2;
  } catch (const std::exception& e) {
    removeCreatedDirs();  // a refused or failed run leaves no empty folder behind
    std::fprintf(stderr, "sbot_calibrate: %s\n", e.what());
    // Exit statuses as every tool's (sbot_sim/tools/cli_args.h): 2 a refused option, output place or
    // input file (all checked before the work), 3 a crashed worker, 1 any other failure.
    if (dynamic_cast<const WorkerCrashed*>(&e)) return sbot_tools::kExitCrash;
    if (dynamic_cast<const std::invalid_argument*>(&e) || dynamic_cast<const OutputPlaceRefused*>(&e) ||
        dynamic_cast<const sbot::ConfigError*>(&e))
      return sbot_tools::kExitBadInput;
    return sbot_tools::kExitFailure;
  }
}
