#include "calibration/diagnose.h"

#include "calibration/codec.h"

#include <unistd.h>

#include <cstdlib>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <mutex>
#include <numeric>
#include <random>
#include <sstream>

#include "sbot_sim/core/random_streams.h"

namespace sbot::calib {
namespace {

class ProgressBar {
 public:
  ProgressBar(bool on, std::string label, std::size_t total)
      : on_(on), label_(std::move(label)), total_(total), start_(std::chrono::steady_clock::now()) {
    draw();
  }
  void tick() {
    ++done_;
    draw();
  }
  void finish() {
    if (!on_) return;
    done_ = total_.load();
    draw();
    std::fprintf(stderr, "\n");
  }

 private:
  void draw() {
    if (!on_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t t = std::max<std::size_t>(1, total_), d = std::min<std::size_t>(done_, t);
    const int width = 30;
    const int fill = static_cast<int>(width * d / t);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fprintf(stderr, "\r%-28s [%s%s] %3zu/%zu  %5.1f s", label_.c_str(), std::string(fill, '#').c_str(),
                 std::string(width - fill, '.').c_str(), d, t, secs);
    std::fflush(stderr);
  }
  bool on_;
  std::string label_;
  std::atomic<std::size_t> total_, done_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
};

std::string fmt(double v, int prec = 4) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = a.size();
  if (n < 3) return 0;
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
}

struct FitTask {
  FitResult fit;
  Evaluation heldout;
};
constexpr auto kFitTaskMembers = std::make_tuple(&FitTask::fit, &FitTask::heldout);
void save(Writer& w, const FitTask& x) { saveMembers(w, x, kFitTaskMembers); }
void load(Reader& r, FitTask& x) { loadMembers(r, x, kFitTaskMembers); }

/// Merge per-fold held-out evaluations into one evaluation over all runs.
Evaluation merge(const std::vector<Evaluation>& parts) {
  Evaluation e;
  for (const auto& p : parts)
    for (const auto& r : p.runs) e.runs.push_back(r);
  return e;
}

}  // namespace

std::string unmeasuredChannels(const Dataset& ds, const std::string& name) {
  const EffectInfo& info = EffectRegistry::instance().info(name);
  const std::set<std::string> groups = usableGroups(ds);
  std::string acts_on, measured;
  for (const auto& c : info.channels) {
    if (c == "pose" ? groups.count("position") || groups.count("yaw") : groups.count(c)) return "";
    acts_on += (acts_on.empty() ? "" : ", ") + c;
  }
  for (const auto& g : groups) measured += (measured.empty() ? "" : ", ") + g;
  const std::string dataset = "dataset '" + ds.name + "'";
  return name + " acts on " + acts_on +
         (info.channels.size() > 1 ? ", none of which " + dataset + " measures" : ", which " + dataset + " does not measure") +
         " (it measures " + (measured.empty() ? "nothing the replay simulates" : measured) + ")";
}

std::string missingSurfaces(const Dataset& ds, const std::string& name) {
  if (!EffectRegistry::instance().info(name).open_params || !ds.obstacleSurfaces().empty()) return "";
  return name + " has one parameter per surface, and dataset '" + ds.name + "' has no obstacle with a surface";
}

std::vector<std::string> candidateEffects(const Dataset& ds) {
  std::vector<std::string> out;
  for (const auto& name : EffectRegistry::instance().names())
    if (unmeasuredChannels(ds, name).empty() && missingSurfaces(ds, name).empty()) out.push_back(name);
  return out;
}

EffectConfig candidateConfig(const Dataset& ds, const std::string& name) {
  EffectConfig c{name, {}, {}, ""};
  const EffectInfo& info = EffectRegistry::instance().info(name);
  if (info.open_params)
    for (const auto& surface : ds.obstacleSurfaces()) c.params[surface] = info.params.front().null_value;
  if (name == "ir_gain_offset") {
    // Only sensors with real detections in the data carry information about their gain/offset.
    for (int k = 0; k < 15; ++k) {
      const std::string ch = "ir" + std::to_string(k);
      std::size_t strong = 0;
      for (const auto& r : ds.runs) {
        auto it = r.channels.find(ch);
        if (it == r.channels.end()) continue;
        for (double v : it->second.v) strong += v > 50;
      }
      if (strong >= 10) {
        c.params["gain" + std::to_string(k)] = 1.0;
        c.params["offset" + std::to_string(k)] = 0.0;
      }
    }
  }
  return c;
}

std::vector<std::string> candidateParams(const Dataset& ds, const std::string& name) {
  std::vector<std::string> out;
  const EffectInfo& info = EffectRegistry::instance().info(name);
  const EffectConfig c = candidateConfig(ds, name);
  if (info.open_params || !c.params.empty()) {
    for (const auto& [k, v] : c.params) out.push_back(k);
  } else {
    for (const auto& p : info.params) out.push_back(p.name);
  }
  return out;
}

int foldCount(const Dataset& ds, int folds) { return std::max(1, std::min<int>(folds, static_cast<int>(ds.runs.size()))); }

std::vector<int> assignFolds(const Dataset& ds, int folds, std::uint64_t seed) {
  std::vector<int> fold(ds.runs.size(), 0);
  if (folds < 2) return fold;
  std::map<std::string, std::vector<int>> groups;
  for (std::size_t i = 0; i < ds.runs.size(); ++i) groups[ds.runs[i].group].push_back(static_cast<int>(i));
  std::mt19937_64 rng(stableHash(seed, "folds"));
  int deal = 0;
  for (auto& [g, idx] : groups) {
    std::shuffle(idx.begin(), idx.end(), rng);
    for (int i : idx) fold[i] = deal++ % folds;
  }
  return fold;
}

std::string rejectionReason(const CandidateScore& s, const std::vector<double>& base_fold_rss,
                            const DiagnoseOptions& opt) {
  std::vector<std::string> misses;
  if (!(s.delta_bic > opt.bic_threshold))
    misses.push_back("dBIC " + fmt(s.delta_bic, 4) + " is not above " + fmt(opt.bic_threshold, 4));
  if (!(s.reduction >= opt.min_reduction))
    misses.push_back("the held-out error " +
                     (s.reduction >= 0 ? "falls " + fmt(100 * s.reduction, 3) + " %, less than "
                                       : "rises " + fmt(-100 * s.reduction, 3) + " %, instead of falling >= ") +
                     fmt(100 * opt.min_reduction, 3) + " %");
  if (!s.all_folds_improve) {
    std::string worse;
    int count = 0;
    for (std::size_t f = 0; f < s.fold_rss.size() && f < base_fold_rss.size(); ++f)
      if (!(s.fold_rss[f] < base_fold_rss[f])) worse += (count++ ? ", " : "") + std::to_string(f + 1);
    misses.push_back(count == 0 ? "not every fold improves"
                                : (count == 1 ? "fold " : "folds ") + worse + " not improved");
  }
  std::string out;
  for (const auto& m : misses) out += (out.empty() ? "" : "; ") + m;
  return out;
}

std::string separatingExperiment(const std::string& a0, const std::string& b0) {
  std::string a = std::min(a0, b0), b = std::max(a0, b0);
  static const std::map<std::pair<std::string, std::string>, std::string> table{
      {{"battery_sag", "speed_scale"},
       "repeat the same straight run at the start and at the end of a long session (>= 10 min): sag "
       "changes with time, a wheel radius does not"},
      {{"dead_band", "speed_scale"},
       "straight runs at 5-10 units and at 60-70 units: a dead-band loses a constant speed, a radius "
       "error a constant fraction"},
      {{"latency", "motor_lag"},
       "speed steps with the wheel encoders logged at >= 50 Hz: a delay shifts the step, a lag rounds it"},
      {{"accel_limit", "motor_lag"},
       "speed steps of different sizes (10 and 70 units): a rate limit takes longer for big steps, a lag "
       "takes the same time for every step"},
      {{"accel_limit", "latency"},
       "speed steps of different sizes: a rate limit scales with the step size, a delay does not"},
      {{"track_width", "turn_skid"},
       "spins at three speeds (15, 40, 70 units): a constant turn slip means track width, slip that "
       "grows with the turn rate means skid"},
      {{"motor_asymmetry", "track_width"},
       "long straight runs forward and backward: asymmetry curves straight runs, track width does not"},
      {{"motor_asymmetry", "turn_skid"},
       "long straight runs forward and backward: asymmetry curves straight runs, skid does not"},
      {{"speed_scale", "track_width"}, "straight runs timed over a known distance, then spins: radius scales both"},
      {{"rolling_resistance", "torque_saturation"},
       "constant-speed runs with torque logged, and a push against a wall: resistance raises the running "
       "torque, saturation lowers the stall torque"},
  };
  auto it = table.find({a, b});
  if (it != table.end()) return it->second;
  const EffectRegistry& reg = EffectRegistry::instance();
  std::string ea = reg.has(a) ? reg.info(a).excited_by : a, eb = reg.has(b) ? reg.info(b).excited_by : b;
  return "run both excitations and compare: " + a + " shows in " + ea + "; " + b + " shows in " + eb;
}

std::vector<StructureNote> residualStructure(const Dataset& ds, const Evaluation& ev, const ModelSpec&) {
  std::map<std::string, StructureNote> notes;
  std::map<std::string, std::vector<double>> res;
  std::map<std::string, std::map<std::string, std::vector<double>>> feats;
  std::map<std::string, std::map<std::string, std::pair<double, std::size_t>>> per_run;
  std::map<std::string, std::pair<double, double>> rho;  // group -> (num, den)
  std::map<std::string, double> robust;                   // group -> robust sum of squares
  for (const auto& rr : ev.runs) {
    const Run& run = ds.runs[rr.run];
    const RunPrediction& p = rr.prediction;
    for (std::size_t ci = 0; ci < rr.channels.size(); ++ci) {
      const std::string& c = rr.channels[ci];
      const std::string g = NoiseModel::group(c);
      auto fit = p.features.find(c);
      std::size_t k = 0;  // sample index within the channel
      double prev = 0, sxy = 0, sxx = 0;
      bool have = false;
      for (std::size_t i = 0; i < rr.r.size(); ++i) {
        if (rr.chan[i] != static_cast<int>(ci)) continue;
        const std::size_t idx = k++;
        if (!rr.valid[i]) continue;
        const double r = std::max(-3.0, std::min(3.0, rr.r[i]));  // clipped: outliers do not steer correlations
        res[g].push_back(r);
        robust[g] += huberLoss(rr.r[i], 3.0);
        per_run[g][run.name].first += huberLoss(rr.r[i], 3.0);
        per_run[g][run.name].second += 1;
        if (have) sxy += prev * r;
        sxx += r * r;
        prev = r;
        have = true;
        auto feat = [&](const std::string& name, double v) { feats[g][name].push_back(v); };
        feat("t", rr.t[i]);
        if (fit != p.features.end()) {
          for (const char* f : {"v", "w", "accel", "contact", "distance", "incidence", "yaw"}) {
            auto it = fit->second.find(f);
            const double v = it != fit->second.end() && idx < it->second.size() ? it->second[idx] : 0.0;
            feat(f, std::isfinite(v) ? v : 0.0);
          }
          auto yaw = fit->second.find("yaw");
          const double y = yaw != fit->second.end() && idx < yaw->second.size() ? yaw->second[idx] : 0.0;
          feat("cos_yaw", std::cos(y));
          feat("sin_yaw", std::sin(y));
          auto w = fit->second.find("w");
          feat("|w|", w != fit->second.end() && idx < w->second.size() ? std::abs(w->second[idx]) : 0.0);
          auto v = fit->second.find("v");
          feat("|v|", v != fit->second.end() && idx < v->second.size() ? std::abs(v->second[idx]) : 0.0);
        }
      }
      if (sxx > 0) {
        rho[g].first += sxy / sxx * k;
        rho[g].second += k;
      }
    }
  }
  std::vector<StructureNote> out;
  for (const auto& [g, r] : res) {
    StructureNote n;
    n.group = g;
    n.rms = r.empty() ? 0 : std::sqrt(robust[g] / r.size());
    n.rho1 = rho[g].second > 0 ? rho[g].first / rho[g].second : 0;
    double worst = -1;
    for (const auto& [run, acc] : per_run[g]) {
      const double ms = acc.second ? acc.first / acc.second : 0;
      if (ms > worst) {
        worst = ms;
        n.worst_run = run;
      }
    }
    for (const auto& [f, v] : feats[g]) {
      if (v.size() != r.size()) continue;
      const double c = pearson(r, v);
      if (std::abs(c) > std::abs(n.correlation)) {
        n.correlation = c;
        n.feature = f;
      }
    }
    // Flag: clearly above the noise floor and structured (correlated in time).
    n.flagged = n.rms > 1.5 && (n.rho1 > 0.3 || std::abs(n.correlation) > 0.3 || n.rms > 2.5);
    out.push_back(n);
  }
  return out;
}

DiagnoseResult diagnose(const Dataset& ds, const DiagnoseOptions& opt, WorkerPool& pool) {
  const auto t0 = std::chrono::steady_clock::now();
  const long sims0 = replayCount();
  DiagnoseResult out;
  const int K = foldCount(ds, opt.folds);
  out.fold_of_run = assignFolds(ds, K, opt.seed);
  std::vector<std::vector<int>> train(K), test(K);
  for (std::size_t i = 0; i < ds.runs.size(); ++i) {
    for (int f = 0; f < K; ++f) {
      if (out.fold_of_run[i] == f) test[f].push_back(static_cast<int>(i));
      else train[f].push_back(static_cast<int>(i));
    }
  }
  if (K == 1) train[0] = test[0];  // a single run: in-sample (said so in the verdict)
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };

  ModelSpec current = opt.base;
  if (current.level.empty()) current.level = ds.robot;
  std::vector<std::string> cands = opt.candidates.empty() ? candidateEffects(ds) : opt.candidates;
  FitOptions fo = opt.fit;

  // Residuals of the starting model on every run (no parameters fitted yet: a plain replay).
  std::vector<Evaluation> cur_fold(K), cur_train(K);
  Evaluation start_all;
  {
    ProgressBar bar(opt.progress, "replaying (current model)", 1);
    start_all = evaluate(ds, current, allRuns(ds), fo.eval, pool);
    for (const auto& rr : start_all.runs) cur_fold[out.fold_of_run[rr.run]].runs.push_back(rr);
    bar.tick();
    bar.finish();
  }
  auto trainEval = [&](const Evaluation& all, int f) {
    Evaluation e;
    for (int i : train[f])
      for (const auto& rr : all.runs)
        if (rr.run == i) e.runs.push_back(rr);
    return e;
  };
  for (int f = 0; f < K; ++f) cur_train[f] = trainEval(start_all, f);
  auto sumRss = [](const std::vector<Evaluation>& v) {
    double s = 0;
    for (const auto& e : v) s += e.rss();
    return s;
  };
  const std::size_t n_heldout = merge(cur_fold).n();
  out.heldout_rms_before = n_heldout ? std::sqrt(sumRss(cur_fold) / n_heldout) : 0;
  out.heldout_before_by_channel = merge(cur_fold).byChannel(fo.eval.huber);
  std::vector<int> accepted_idx;  // indices into current.effects that were accepted here
  std::map<std::string, std::vector<std::string>> runners_up;  // accepted effect -> its step's rivals
  std::map<std::string, std::vector<double>> fold_estimates;    // "effect.param" -> per-fold values

  // One fit task: candidate `effect` (empty = none: the baseline, i.e. the current model's
  // accepted parameters refit on the fold) on fold `fold`, starting from `start` values.
  struct Task {
    std::string effect;
    int fold;
    std::vector<double> start;  // candidate parameter start values (empty = null values)
    int iterations;
  };
  // Per fold: the current model with its accepted parameters refit on that fold's training runs,
  // and its residuals there (candidates start from it, so a candidate that stays at its null value
  // reproduces the baseline exactly).
  std::vector<ModelSpec> fold_model(K, current);
  auto runTasks = [&](const std::vector<Task>& tasks, const std::string& label) {
    ProgressBar bar(opt.progress, label, tasks.size());
    std::vector<std::size_t> order(tasks.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    auto nparams = [&](std::size_t ti) {
      return tasks[ti].effect.empty() ? 0 : EffectRegistry::instance().info(tasks[ti].effect).params.size();
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return nparams(a) > nparams(b); });
    auto res = pool.map<FitTask>(
        order.size(),
        [&](std::size_t k) {
          const Task& t = tasks[order[k]];
          ModelSpec m = fold_model[t.fold];
          std::vector<int> free_effects = accepted_idx;
          if (!t.effect.empty()) {
            EffectConfig ec = candidateConfig(ds, t.effect);
            const auto names = candidateParams(ds, t.effect);
            for (std::size_t j = 0; j < t.start.size() && j < names.size(); ++j) ec.params[names[j]] = t.start[j];
            m.effects.push_back(ec);
            free_effects.push_back(static_cast<int>(m.effects.size()) - 1);
          }
          FitOptions f = fo;
          f.max_iterations = t.iterations;
          f.refine_scan = t.iterations >= fo.max_iterations;  // screening ranks by the coarse scan
          // The start model equals the current model when the candidate starts at its null value.
          if (t.start.empty()) f.start_evaluation = &cur_train[t.fold];
          FitTask r;
          r.fit = fitModel(ds, m, freeParamsOf(m, free_effects), train[t.fold], f, pool);
          r.heldout = evaluate(ds, r.fit.model, test[t.fold], fo.eval, pool);
          return r;
        },
        [&](std::size_t) { bar.tick(); });
    bar.finish();
    std::vector<FitTask> out_tasks(tasks.size());
    for (std::size_t k = 0; k < order.size(); ++k) out_tasks[order[k]] = std::move(res[k]);
    return out_tasks;
  };
  auto score = [&](const std::string& effect, const std::vector<const FitTask*>& per_fold,
                   const std::vector<double>& base_fold_rss, double base_rss) {
    CandidateScore s;
    s.effect = effect;
    s.params = candidateParams(ds, effect);
    s.all_folds_improve = true;
    std::vector<Evaluation> parts;
    for (int f = 0; f < K; ++f) {
      const FitTask& t = *per_fold[f];
      std::vector<double> vals;
      for (std::size_t j = 0; j < t.fit.free.size(); ++j)
        if (t.fit.free[j].effect == static_cast<int>(t.fit.model.effects.size()) - 1) vals.push_back(t.fit.value[j]);
      s.fold_values.push_back(vals);
      s.fold_rss.push_back(t.heldout.rss());
      if (!(t.heldout.rss() < base_fold_rss[f])) s.all_folds_improve = false;
      parts.push_back(t.heldout);
    }
    Evaluation all = merge(parts);
    s.cv_rss = all.rss();
    s.n = all.n();
    s.rho1 = all.rho1();
    s.n_eff = all.nEffective();
    const double k = static_cast<double>(s.params.size());
    s.delta_bic = s.n_eff * std::log(std::max(1e-300, base_rss) / std::max(1e-300, s.cv_rss)) -
                  k * std::log(std::max(2.0, s.n_eff));
    s.reduction = base_rss > 0 ? 1 - s.cv_rss / base_rss : 0;
    s.passes = s.delta_bic > opt.bic_threshold && s.all_folds_improve && s.reduction >= opt.min_reduction;
    s.heldout = parts;
    return s;
  };

  for (int round = 0; round < opt.max_effects; ++round) {
    DiagnoseRound rd;
    std::vector<std::string> todo;
    for (const auto& c : cands) {
      bool present = false;
      for (const auto& e : current.effects) present |= e.name == c;
      if (!present) todo.push_back(c);
    }
    if (todo.empty()) break;
    const std::string tag = "step " + std::to_string(round + 1) + ": ";

    // Stage 0, the baseline: with accepted effects, their parameters refit on each fold like the
    // candidates' (so a candidate is never credited with a better refit of earlier effects).
    std::vector<Evaluation> base_fold = cur_fold;
    if (!accepted_idx.empty()) {
      std::vector<Task> base;
      for (int f = 0; f < K; ++f) base.push_back({"", f, {}, fo.max_iterations});
      fold_model.assign(K, current);
      const auto bres = runTasks(base, tag + "refitting the baseline");
      for (int f = 0; f < K; ++f) {
        base_fold[f] = bres[f].heldout;
        fold_model[f] = bres[f].fit.model;
        cur_train[f] = bres[f].fit.evaluation;
      }
    }
    std::vector<double> base_fold_rss;
    for (const auto& e : base_fold) base_fold_rss.push_back(e.rss());
    rd.current_cv_rss = sumRss(base_fold);
    rd.current_fold_rss = base_fold_rss;

    // Stage A, screening: every candidate, a short fit (opt.screen_iterations) per fold.
    std::vector<Task> screen;
    for (const auto& c : todo)
      for (int f = 0; f < K; ++f) screen.push_back({c, f, {}, opt.screen_iterations});
    const auto sres = runTasks(screen, tag + "screening " + std::to_string(todo.size()) + " effects");
    std::vector<CandidateScore> screened;
    for (std::size_t c = 0; c < todo.size(); ++c) {
      std::vector<const FitTask*> pf;
      for (int f = 0; f < K; ++f) pf.push_back(&sres[c * K + f]);
      screened.push_back(score(todo[c], pf, base_fold_rss, rd.current_cv_rss));
    }
    std::vector<Task> refine;
    std::vector<std::size_t> rank(todo.size());
    for (std::size_t i = 0; i < rank.size(); ++i) rank[i] = i;
    std::sort(rank.begin(), rank.end(),
              [&](std::size_t a, std::size_t b) { return screened[a].delta_bic > screened[b].delta_bic; });
    const std::size_t finalists = std::min<std::size_t>(rank.size(), static_cast<std::size_t>(opt.finalists));
    for (std::size_t q = 0; q < finalists; ++q) {
      // A candidate with a scan_first parameter is refitted from its null value: its full fit scans
      // the whole range and refines (from the screening's coarse point it would scan a sub-range).
      bool scan_first = false;
      for (const auto& p : EffectRegistry::instance().info(todo[rank[q]]).params) scan_first |= p.scan_first;
      for (int f = 0; f < K; ++f)
        refine.push_back({todo[rank[q]], f,
                          scan_first ? std::vector<double>{} : screened[rank[q]].fold_values[f], fo.max_iterations});
    }
    const auto rres = runTasks(refine, tag + "refining " + std::to_string(finalists) + " best");
    const std::size_t off = 0;
    for (std::size_t q = 0; q < rank.size(); ++q) {
      if (q < finalists) {
        std::vector<const FitTask*> pf;
        for (int f = 0; f < K; ++f) pf.push_back(&rres[off + q * K + f]);
        rd.ranked.push_back(score(todo[rank[q]], pf, base_fold_rss, rd.current_cv_rss));
      } else {
        // Screened only: re-scored against the refit baseline, never accepted.
        std::vector<const FitTask*> pf;
        for (int f = 0; f < K; ++f) pf.push_back(&sres[rank[q] * K + f]);
        CandidateScore sc = score(todo[rank[q]], pf, base_fold_rss, rd.current_cv_rss);
        sc.passes = false;
        rd.ranked.push_back(std::move(sc));
      }
    }
    std::stable_sort(rd.ranked.begin(), rd.ranked.end(),
                     [](const CandidateScore& a, const CandidateScore& b) { return a.delta_bic > b.delta_bic; });
    for (const auto& sc : rd.ranked)
      log("  " + sc.effect + ": dBIC " + fmt(sc.delta_bic, 5) + ", held-out RSS -" + fmt(100 * sc.reduction, 3) +
          " %, folds " + (sc.all_folds_improve ? "all improve" : "mixed"));
    const CandidateScore& best = rd.ranked.front();
    if (!best.passes) {
      out.rounds.push_back(std::move(rd));
      break;
    }
    rd.accepted = best.effect;
    // A rival is indistinguishable when the evidence barely separates them, or when its held-out
    // error is within the simulation's resolution of the best's (min_reduction: below that the
    // difference is the replay's chaos, which BIC would count as evidence: on cruise-only data a
    // speed scale and a dead-band swap places from seed to seed with dBIC gaps up to 130).
    for (std::size_t i = 1; i < rd.ranked.size(); ++i) {
      const CandidateScore& rival = rd.ranked[i];
      const bool close_evidence = rival.delta_bic > best.delta_bic - opt.ambiguity_margin;
      const bool close_error = rival.cv_rss <= (1 + opt.min_reduction) * best.cv_rss;
      if (rival.passes && (close_evidence || close_error)) rd.indistinguishable.push_back(rival.effect);
    }
    for (const auto& r : rd.indistinguishable) out.ambiguous.push_back({best.effect, r});
    out.accepted.push_back(best.effect);
    for (std::size_t j = 0; j < best.params.size(); ++j)
      for (const auto& fv : best.fold_values)
        if (j < fv.size()) fold_estimates[best.effect + "." + best.params[j]].push_back(fv[j]);

    // Refit every accepted parameter on all runs, from the folds' mean.
    ModelSpec m = current;
    EffectConfig ec = candidateConfig(ds, best.effect);
    for (std::size_t j = 0; j < best.params.size(); ++j) {
      double mean = 0;
      for (const auto& fv : best.fold_values) mean += j < fv.size() ? fv[j] : 0;
      ec.params[best.params[j]] = mean / std::max<std::size_t>(1, best.fold_values.size());
    }
    m.effects.push_back(ec);
    accepted_idx.push_back(static_cast<int>(m.effects.size()) - 1);
    {
      ProgressBar bar2(opt.progress, tag + "refit on all runs", 1);
      out.final_fit = fitModel(ds, m, freeParamsOf(m, accepted_idx), allRuns(ds), fo, pool);
      bar2.tick();
      bar2.finish();
    }
    current = out.final_fit.model;
    cur_fold = best.heldout;
    for (int f = 0; f < K; ++f) cur_train[f] = trainEval(out.final_fit.evaluation, f);
    // Runners-up of this step: the passing finalists, tried again as replacements later.
    std::vector<std::string> rivals;
    for (std::size_t i = 1; i < rd.ranked.size() && rivals.size() < 4; ++i)
      if (rd.ranked[i].delta_bic > opt.bic_threshold && rd.ranked[i].reduction >= opt.min_reduction)
        rivals.push_back(rd.ranked[i].effect);
    runners_up[best.effect] = rivals;

    // Removal check (backward step): an effect accepted earlier that the new one has made
    // redundant (removing it, all other parameters refit per fold, costs less than the acceptance
    // bar) is dropped.
    for (std::size_t a = 0; a + 1 < out.accepted.size() && out.accepted.size() > 1;) {
      const std::string old_effect = out.accepted[a];
      ModelSpec without = current;
      int removed = -1;
      for (std::size_t i = 0; i < without.effects.size(); ++i)
        if (without.effects[i].name == old_effect) removed = static_cast<int>(i);
      if (removed < 0) {
        ++a;
        continue;
      }
      without.effects.erase(without.effects.begin() + removed);
      std::vector<int> idx_without;
      for (int i : accepted_idx)
        if (i != removed) idx_without.push_back(i > removed ? i - 1 : i);
      ProgressBar bar4(opt.progress, tag + "checking removal of " + old_effect, K);
      auto rm = pool.map<FitTask>(
          K,
          [&](std::size_t f) {
            FitTask r;
            r.fit = fitModel(ds, without, freeParamsOf(without, idx_without), train[f], fo, pool);
            r.heldout = evaluate(ds, r.fit.model, test[f], fo.eval, pool);
            return r;
          },
          [&](std::size_t) { bar4.tick(); });
      bar4.finish();
      std::vector<Evaluation> parts;
      double rss_without = 0;
      for (int f = 0; f < K; ++f) {
        parts.push_back(rm[f].heldout);
        rss_without += rm[f].heldout.rss();
      }
      const double cur_rss = sumRss(cur_fold);
      const Evaluation merged = merge(parts);
      const double k = static_cast<double>(candidateParams(ds, old_effect).size());
      const double n_eff = merge(cur_fold).nEffective();
      const double dbic = n_eff * std::log(std::max(1e-300, rss_without) / std::max(1e-300, cur_rss)) -
                          k * std::log(std::max(2.0, n_eff));
      const bool keep = dbic > opt.bic_threshold && rss_without >= cur_rss * (1 + opt.min_reduction);
      log("  removal check " + old_effect + ": held-out RSS without it " + fmt(rss_without, 6) + " vs " +
          fmt(cur_rss, 6) + (keep ? " (kept)" : " (removed)"));
      if (keep) {
        ++a;
        continue;
      }
      rd.removed.push_back(old_effect);
      out.accepted.erase(out.accepted.begin() + a);
      out.ambiguous.erase(std::remove_if(out.ambiguous.begin(), out.ambiguous.end(),
                                         [&](const auto& p) { return p.first == old_effect || p.second == old_effect; }),
                          out.ambiguous.end());
      accepted_idx = idx_without;
      out.final_fit = fitModel(ds, without, freeParamsOf(without, accepted_idx), allRuns(ds), fo, pool);
      current = out.final_fit.model;
      cur_fold = parts;
      for (int f = 0; f < K; ++f) cur_train[f] = trainEval(out.final_fit.evaluation, f);
      (void)merged;
    }

    // Replacement check (stepwise with swaps): an effect accepted earlier may have stood in for
    // one that only now, next to the new effect, shows its worth (e.g. a rate limit imitating a
    // delay before the speed error was explained). Try each earlier effect's runners-up in its
    // place, all parameters refit per fold; swap if the held-out error falls clearly.
    for (std::size_t a = 0; a + 1 < out.accepted.size(); ++a) {
      const std::string old_effect = out.accepted[a];
      std::vector<std::string> options;
      for (const auto& b : runners_up[old_effect]) {
        bool present = false;
        for (const auto& e : current.effects) present |= e.name == b;
        if (!present) options.push_back(b);
      }
      if (options.empty()) continue;
      ModelSpec without = current;
      int removed = -1;
      for (std::size_t i = 0; i < without.effects.size(); ++i)
        if (without.effects[i].name == old_effect) removed = static_cast<int>(i);
      if (removed < 0) continue;
      without.effects.erase(without.effects.begin() + removed);
      std::vector<int> idx_without;
      for (int i : accepted_idx)
        if (i != removed) idx_without.push_back(i > removed ? i - 1 : i);
      struct SwapTask {
        std::string effect;
        int fold;
      };
      std::vector<SwapTask> st;
      for (const auto& b : options)
        for (int f = 0; f < K; ++f) st.push_back({b, f});
      ProgressBar bar3(opt.progress, tag + "checking replacements of " + old_effect, st.size());
      auto sw = pool.map<FitTask>(
          st.size(),
          [&](std::size_t k) {
            ModelSpec m = without;
            m.effects.push_back(candidateConfig(ds, st[k].effect));
            std::vector<int> free = idx_without;
            free.push_back(static_cast<int>(m.effects.size()) - 1);
            FitTask r;
            r.fit = fitModel(ds, m, freeParamsOf(m, free), train[st[k].fold], fo, pool);
            r.heldout = evaluate(ds, r.fit.model, test[st[k].fold], fo.eval, pool);
            return r;
          },
          [&](std::size_t) { bar3.tick(); });
      bar3.finish();
      const double cur_rss = sumRss(cur_fold);
      double best_rss = cur_rss * (1 - opt.min_reduction);
      int best_option = -1;
      std::vector<Evaluation> best_parts;
      for (std::size_t o = 0; o < options.size(); ++o) {
        std::vector<Evaluation> parts;
        double total = 0;
        for (int f = 0; f < K; ++f) {
          parts.push_back(sw[o * K + f].heldout);
          total += sw[o * K + f].heldout.rss();
        }
        if (total < best_rss) {
          best_rss = total;
          best_option = static_cast<int>(o);
          best_parts = parts;
        }
      }
      if (std::getenv("SBOT_CALIB_DEBUG"))
        for (std::size_t o = 0; o < options.size(); ++o)
          std::fprintf(stderr, "swap check %s -> %s: held-out %.1f vs current %.1f\n", old_effect.c_str(),
                       options[o].c_str(), sw[o * K].heldout.rss() + (K > 1 ? sw[o * K + 1].heldout.rss() : 0), cur_rss);
      if (best_option < 0) continue;
      const std::string new_effect = options[best_option];
      log("  swap: " + old_effect + " -> " + new_effect + " (held-out RSS " + fmt(cur_rss, 6) + " -> " +
          fmt(best_rss, 6) + ")");
      rd.swaps.push_back({old_effect, new_effect});
      out.accepted[a] = new_effect;
      out.ambiguous.erase(std::remove_if(out.ambiguous.begin(), out.ambiguous.end(),
                                         [&](const auto& p) { return p.first == old_effect || p.second == old_effect; }),
                          out.ambiguous.end());
      ModelSpec m = without;
      EffectConfig ec = candidateConfig(ds, new_effect);
      for (const auto& pname : candidateParams(ds, new_effect)) {
        double mean = 0;
        for (int f = 0; f < K; ++f) {
          const FitResult& fr = sw[best_option * K + f].fit;
          for (std::size_t q = 0; q < fr.free.size(); ++q)
            if (fr.free[q].effect == static_cast<int>(fr.model.effects.size()) - 1 && fr.free[q].name == pname)
              mean += fr.value[q] / K;
        }
        ec.params[pname] = mean;
      }
      m.effects.push_back(ec);
      accepted_idx = idx_without;
      accepted_idx.push_back(static_cast<int>(m.effects.size()) - 1);
      out.final_fit = fitModel(ds, m, freeParamsOf(m, accepted_idx), allRuns(ds), fo, pool);
      current = out.final_fit.model;
      cur_fold = best_parts;
      for (int f = 0; f < K; ++f) cur_train[f] = trainEval(out.final_fit.evaluation, f);
      runners_up[new_effect] = runners_up[old_effect];
      for (int f = 0; f < K; ++f) {
        const FitResult& fr = sw[best_option * K + f].fit;
        for (std::size_t q = 0; q < fr.free.size(); ++q)
          if (fr.free[q].effect == static_cast<int>(fr.model.effects.size()) - 1)
            fold_estimates[new_effect + "." + fr.free[q].name].push_back(fr.value[q]);
      }
    }
    out.rounds.push_back(std::move(rd));
  }
  out.final_model = current;
  out.heldout_rms_after = n_heldout ? std::sqrt(sumRss(cur_fold) / n_heldout) : 0;
  out.heldout_after_by_channel = merge(cur_fold).byChannel(fo.eval.huber);

  // Residual structure of the final model (all runs, with features).
  EvalOptions eo = fo.eval;
  eo.replay.keep_trace = true;
  const Evaluation fin = evaluate(ds, current, allRuns(ds), eo, pool);
  out.structure = residualStructure(ds, fin, current);
  for (const auto& s : out.structure) out.structure_flagged |= s.flagged;

  // Verdict.
  std::ostringstream v;
  const EffectRegistry& reg = EffectRegistry::instance();
  if (!out.accepted.empty()) {
    v << "VERDICT: " << out.accepted.size() << " effect" << (out.accepted.size() > 1 ? "s" : "")
      << " accepted (held-out evidence dBIC > " << opt.bic_threshold << ", held-out error down >= "
      << fmt(100 * opt.min_reduction, 3) << " % and in every fold)\n";
    for (std::size_t j = 0; j < out.final_fit.free.size(); ++j) {
      const FreeParam& p = out.final_fit.free[j];
      const std::string& en = out.final_fit.model.effects[p.effect].name;
      if (std::find(out.accepted.begin(), out.accepted.end(), en) == out.accepted.end()) continue;
      // Interval: the larger of the analytic one ((J'J)^-1 s^2, measurement noise only) and the
      // spread of the per-fold estimates (which also carries the simulation's own sensitivity).
      double se = out.final_fit.stderr_[j];
      auto fe = fold_estimates.find(en + "." + p.name);
      if (fe != fold_estimates.end() && fe->second.size() >= 2) {
        double m = 0, ss = 0;
        for (double x : fe->second) m += x / fe->second.size();
        for (double x : fe->second) ss += (x - m) * (x - m);
        const double sd = std::sqrt(ss / (fe->second.size() - 1));
        se = std::max(se, sd / std::sqrt(static_cast<double>(fe->second.size())));
      }
      out.interval95.push_back(1.96 * se);
      v << "  " << en << "." << p.name << " = " << fmt(out.final_fit.value[j], 5) << " +- " << fmt(1.96 * se, 2)
        << " " << p.spec.unit << " (95 % interval; null " << fmt(p.spec.null_value, 4) << ")\n";
    }
    for (std::size_t r = 0; r < out.rounds.size(); ++r) {
      const auto& rd = out.rounds[r];
      if (rd.accepted.empty()) continue;
      v << "  step " << r + 1 << ": " << rd.accepted << " (" << reg.info(rd.accepted).title << "), held-out dBIC "
        << fmt(rd.ranked.front().delta_bic, 5) << ", held-out error -" << fmt(100 * rd.ranked.front().reduction, 3)
        << " %\n";
    }
    for (std::size_t r = 0; r < out.rounds.size(); ++r)
      for (const auto& a : out.rounds[r].removed)
        v << "  after step " << r + 1 << ": " << a << " removed (redundant next to the later effects)\n";
    for (std::size_t r = 0; r < out.rounds.size(); ++r)
      for (const auto& [a, b] : out.rounds[r].swaps)
        v << "  after step " << r + 1 << ": " << a << " replaced by " << b
          << " (it had stood in for it; held-out error lower with " << b << ")\n";
    for (const auto& [a, b] : out.ambiguous)
      v << "  CANNOT TELL APART: " << a << " and " << b << " explain the data almost equally well.\n"
        << "    experiment that separates them: " << separatingExperiment(a, b) << "\n";
  } else {
    const bool at_floor = out.heldout_rms_before < 1.25 && !out.structure_flagged;
    if (at_floor) {
      v << "VERDICT: no effect needed: the residual is at the noise floor (held-out normalised RMS "
        << fmt(out.heldout_rms_before, 3) << ")\n";
    } else {
      v << "VERDICT: no effect in the library explains the residual.\n";
    }
  }
  if (!out.rounds.empty() && !out.rounds.back().ranked.empty() && out.rounds.back().accepted.empty()) {
    const auto& b = out.rounds.back().ranked.front();
    // A screened-only candidate (not among the finalists refined) misses no rule by its score.
    const std::string why = rejectionReason(b, out.rounds.back().current_fold_rss, opt);
    v << "  best rejected candidate: " << b.effect << " (held-out dBIC " << fmt(b.delta_bic, 4) << ", error "
      << (b.reduction >= 0 ? "-" : "+") << fmt(100 * std::abs(b.reduction), 3) << " %): "
      << (why.empty() ? "screened only, not refined" : why) << "\n";
  }
  v << "  held-out normalised RMS: " << fmt(out.heldout_rms_before, 4) << " -> " << fmt(out.heldout_rms_after, 4)
    << " (noise floor ~ 1)\n";
  bool any = false;
  for (const auto& s : out.structure) {
    if (!s.flagged) continue;
    if (!any) v << "  STRUCTURE REMAINS in:\n";
    any = true;
    v << "    " << s.group << ": RMS " << fmt(s.rms, 3) << " x noise, lag-1 autocorrelation " << fmt(s.rho1, 2)
      << ", strongest correlation with " << s.feature << " (r = " << fmt(s.correlation, 2) << "), worst run "
      << s.worst_run << "\n";
  }
  if (!any) v << "  residual structure: none flagged (every channel group near the noise floor or uncorrelated)\n";
  if (K == 1) v << "  note: only one run, so the scores are in-sample\n";
  out.verdict = v.str();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.simulations = static_cast<int>(replayCount() - sims0);
  return out;
}

}  // namespace sbot::calib
