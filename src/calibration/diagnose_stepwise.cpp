// diagnose(): the stepwise selection of effects by held-out evidence, in its stages: the fold split,
// the baseline (the start model's held-out residuals, and per step its accepted parameters refit
// on each fold), candidate screening and refinement, acceptance with the removal and replacement
// checks (stepwise selection), and the verdict. diagnose.h has the method.
#include "calibration/diagnose.h"
#include "calibration/diagnose_internal.h"

#include "calibration/codec.h"
#include "calibration/progress_bar.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <sstream>

namespace sbot::calib {
namespace {

using detail::fmt;

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

double sumRss(const std::vector<Evaluation>& v) {
  double s = 0;
  for (const auto& e : v) s += e.rss();
  return s;
}

/// One fit task: candidate `effect` (empty = none: the baseline, i.e. the current model's
/// accepted parameters refit on the fold) on fold `fold`, starting from `start` values.
struct Task {
  std::string effect;
  int fold;
  std::vector<double> start;  // candidate parameter start values (empty = null values)
  int iterations;
};

/// The current model without one of its effects, and the accepted parameters' indices in it.
struct Without {
  ModelSpec model;
  int removed = -1;  ///< the effect's index in the current model; -1: it has none of that name
  std::vector<int> idx;
};

class Stepwise {
 public:
  Stepwise(const Dataset& ds, const DiagnoseOptions& opt, WorkerPool& pool) : ds_(ds), opt_(opt), pool_(pool) {}
  DiagnoseResult run();

 private:
  void splitFolds();
  void baseline();
  bool step(int round);
  std::vector<double> refitBaseline(const std::string& tag, DiagnoseRound& rd);
  void rankCandidates(const std::vector<std::string>& todo, const std::string& tag,
                      const std::vector<double>& base_fold_rss, DiagnoseRound& rd);
  void accept(const std::string& tag, DiagnoseRound& rd);
  void removalChecks(const std::string& tag, DiagnoseRound& rd);
  void replacementChecks(const std::string& tag, DiagnoseRound& rd);
  bool tryReplacement(std::size_t a, const std::string& tag, DiagnoseRound& rd);
  void finish();
  void writeVerdict();
  void verdictAccepted(std::ostringstream& v);

  std::vector<FitTask> runTasks(const std::vector<Task>& tasks, const std::string& label);
  std::vector<FitTask> foldFits(const std::string& label, std::size_t n,
                                const std::function<ModelSpec(std::size_t, std::vector<int>&)>& model_of,
                                const std::function<int(std::size_t)>& fold_of);
  CandidateScore score(const std::string& effect, const std::vector<const FitTask*>& per_fold,
                       const std::vector<double>& base_fold_rss, double base_rss) const;
  Evaluation trainEval(const Evaluation& all, int f) const;
  Without without(const std::string& effect) const;
  void adopt(const ModelSpec& m, std::vector<Evaluation> heldout);
  void dropAmbiguity(const std::string& effect);
  void log(const std::string& s) const {
    if (opt_.log) opt_.log(s);
  }

  const Dataset& ds_;
  const DiagnoseOptions& opt_;
  WorkerPool& pool_;
  DiagnoseResult out_;
  int K_ = 1;
  std::vector<std::vector<int>> train_, test_;
  ModelSpec current_;
  std::vector<std::string> cands_;
  FitOptions fo_;
  std::vector<Evaluation> cur_fold_, cur_train_;
  std::size_t n_heldout_ = 0;
  std::vector<int> accepted_idx_;  // indices into current_.effects that were accepted here
  std::map<std::string, std::vector<std::string>> runners_up_;  // accepted effect -> its step's rivals
  std::map<std::string, std::vector<double>> fold_estimates_;    // "effect.param" -> per-fold values
  // Per fold: the current model with its accepted parameters refit on that fold's training runs,
  // and its residuals there (candidates start from it, so a candidate that stays at its null value
  // reproduces the baseline exactly).
  std::vector<ModelSpec> fold_model_;
};

DiagnoseResult Stepwise::run() {
  const auto t0 = std::chrono::steady_clock::now();
  const long sims0 = replayCount();
  splitFolds();
  current_ = opt_.base;
  if (current_.level.empty()) current_.level = ds_.robot;
  cands_ = opt_.candidates.empty() ? candidateEffects(ds_) : opt_.candidates;
  fo_ = opt_.fit;
  baseline();
  fold_model_.assign(K_, current_);
  for (int round = 0; round < opt_.max_effects; ++round)
    if (!step(round)) break;
  finish();
  writeVerdict();
  out_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out_.simulations = static_cast<int>(replayCount() - sims0);
  return std::move(out_);
}

/// The fold split: each run held out in one fold, trained on in the others.
void Stepwise::splitFolds() {
  K_ = foldCount(ds_, opt_.folds);
  out_.fold_of_run = assignFolds(ds_, K_, opt_.seed);
  train_.assign(K_, {});
  test_.assign(K_, {});
  for (std::size_t i = 0; i < ds_.runs.size(); ++i) {
    for (int f = 0; f < K_; ++f) {
      if (out_.fold_of_run[i] == f) test_[f].push_back(static_cast<int>(i));
      else train_[f].push_back(static_cast<int>(i));
    }
  }
  if (K_ == 1) train_[0] = test_[0];  // a single run: in-sample (said so in the verdict)
}

/// Residuals of the starting model on every run (no parameters fitted yet: a plain replay).
void Stepwise::baseline() {
  cur_fold_.assign(K_, {});
  cur_train_.assign(K_, {});
  Evaluation start_all;
  {
    ProgressBar bar(opt_.progress, "replaying (current model)", 1);
    start_all = evaluate(ds_, current_, allRuns(ds_), fo_.eval, pool_);
    for (const auto& rr : start_all.runs) cur_fold_[out_.fold_of_run[rr.run]].runs.push_back(rr);
    bar.tick();
    bar.finish();
  }
  for (int f = 0; f < K_; ++f) cur_train_[f] = trainEval(start_all, f);
  n_heldout_ = merge(cur_fold_).n();
  out_.heldout_rms_before = n_heldout_ ? std::sqrt(sumRss(cur_fold_) / n_heldout_) : 0;
  out_.heldout_before_by_channel = merge(cur_fold_).byChannel(fo_.eval.huber);
}

Evaluation Stepwise::trainEval(const Evaluation& all, int f) const {
  Evaluation e;
  for (int i : train_[f])
    for (const auto& rr : all.runs)
      if (rr.run == i) e.runs.push_back(rr);
  return e;
}

/// One step of the stepwise selection; false when it ends the selection.
bool Stepwise::step(int round) {
  DiagnoseRound rd;
  std::vector<std::string> todo;
  for (const auto& c : cands_) {
    bool present = false;
    for (const auto& e : current_.effects) present |= e.name == c;
    if (!present) todo.push_back(c);
  }
  if (todo.empty()) return false;
  const std::string tag = "step " + std::to_string(round + 1) + ": ";
  const std::vector<double> base_fold_rss = refitBaseline(tag, rd);
  rankCandidates(todo, tag, base_fold_rss, rd);
  if (!rd.ranked.front().passes) {
    out_.rounds.push_back(std::move(rd));
    return false;
  }
  accept(tag, rd);
  removalChecks(tag, rd);
  replacementChecks(tag, rd);
  out_.rounds.push_back(std::move(rd));
  return true;
}

/// Stage 0, the baseline: with accepted effects, their parameters refit on each fold like the
/// candidates' (so a candidate is never credited with a better refit of earlier effects).
/// Returns the baseline's held-out RSS per fold.
std::vector<double> Stepwise::refitBaseline(const std::string& tag, DiagnoseRound& rd) {
  std::vector<Evaluation> base_fold = cur_fold_;
  if (!accepted_idx_.empty()) {
    std::vector<Task> base;
    for (int f = 0; f < K_; ++f) base.push_back({"", f, {}, fo_.max_iterations});
    fold_model_.assign(K_, current_);
    const auto bres = runTasks(base, tag + "refitting the baseline");
    for (int f = 0; f < K_; ++f) {
      base_fold[f] = bres[f].heldout;
      fold_model_[f] = bres[f].fit.model;
      cur_train_[f] = bres[f].fit.evaluation;
    }
  }
  std::vector<double> base_fold_rss;
  for (const auto& e : base_fold) base_fold_rss.push_back(e.rss());
  rd.current_cv_rss = sumRss(base_fold);
  rd.current_fold_rss = base_fold_rss;
  return base_fold_rss;
}

/// Stage A, screening: every candidate, a short fit (opt.screen_iterations) per fold; then the
/// finalists (the best opt.finalists by dBIC) refined with full fits. rd.ranked: every candidate,
/// best first; a screened-only one never passes.
void Stepwise::rankCandidates(const std::vector<std::string>& todo, const std::string& tag,
                              const std::vector<double>& base_fold_rss, DiagnoseRound& rd) {
  std::vector<Task> screen;
  for (const auto& c : todo)
    for (int f = 0; f < K_; ++f) screen.push_back({c, f, {}, opt_.screen_iterations});
  const auto sres = runTasks(screen, tag + "screening " + std::to_string(todo.size()) + " effects");
  std::vector<CandidateScore> screened;
  auto perFold = [&](const std::vector<FitTask>& res, std::size_t c) {
    std::vector<const FitTask*> pf;
    for (int f = 0; f < K_; ++f) pf.push_back(&res[c * K_ + f]);
    return pf;
  };
  for (std::size_t c = 0; c < todo.size(); ++c)
    screened.push_back(score(todo[c], perFold(sres, c), base_fold_rss, rd.current_cv_rss));
  std::vector<Task> refine;
  std::vector<std::size_t> rank(todo.size());
  for (std::size_t i = 0; i < rank.size(); ++i) rank[i] = i;
  std::sort(rank.begin(), rank.end(),
            [&](std::size_t a, std::size_t b) { return screened[a].delta_bic > screened[b].delta_bic; });
  const std::size_t finalists = std::min<std::size_t>(rank.size(), static_cast<std::size_t>(opt_.finalists));
  for (std::size_t q = 0; q < finalists; ++q) {
    // A candidate with a scan_first parameter is refitted from its null value: its full fit scans
    // the whole range and refines (from the screening's coarse point it would scan a sub-range).
    bool scan_first = false;
    for (const auto& p : EffectRegistry::instance().info(todo[rank[q]]).params) scan_first |= p.scan_first;
    for (int f = 0; f < K_; ++f)
      refine.push_back({todo[rank[q]], f,
                        scan_first ? std::vector<double>{} : screened[rank[q]].fold_values[f], fo_.max_iterations});
  }
  const auto rres = runTasks(refine, tag + "refining " + std::to_string(finalists) + " best");
  for (std::size_t q = 0; q < rank.size(); ++q) {
    if (q < finalists) {
      rd.ranked.push_back(score(todo[rank[q]], perFold(rres, q), base_fold_rss, rd.current_cv_rss));
    } else {
      // Screened only: re-scored against the refit baseline, never accepted.
      CandidateScore sc = score(todo[rank[q]], perFold(sres, rank[q]), base_fold_rss, rd.current_cv_rss);
      sc.passes = false;
      rd.ranked.push_back(std::move(sc));
    }
  }
  std::stable_sort(rd.ranked.begin(), rd.ranked.end(),
                   [](const CandidateScore& a, const CandidateScore& b) { return a.delta_bic > b.delta_bic; });
  for (const auto& sc : rd.ranked)
    log("  " + sc.effect + ": dBIC " + fmt(sc.delta_bic, 5) + ", held-out RSS -" + fmt(100 * sc.reduction, 3) +
        " %, folds " + (sc.all_folds_improve ? "all improve" : "mixed"));
}

std::vector<FitTask> Stepwise::runTasks(const std::vector<Task>& tasks, const std::string& label) {
  ProgressBar bar(opt_.progress, label, tasks.size());
  std::vector<std::size_t> order(tasks.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto nparams = [&](std::size_t ti) {
    return tasks[ti].effect.empty() ? 0 : EffectRegistry::instance().info(tasks[ti].effect).params.size();
  };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return nparams(a) > nparams(b); });
  auto res = pool_.map<FitTask>(
      order.size(),
      [&](std::size_t k) {
        const Task& t = tasks[order[k]];
        ModelSpec m = fold_model_[t.fold];
        std::vector<int> free_effects = accepted_idx_;
        if (!t.effect.empty()) {
          EffectConfig ec = candidateConfig(ds_, t.effect);
          const auto names = candidateParams(ds_, t.effect);
          for (std::size_t j = 0; j < t.start.size() && j < names.size(); ++j) ec.params[names[j]] = t.start[j];
          m.effects.push_back(ec);
          free_effects.push_back(static_cast<int>(m.effects.size()) - 1);
        }
        FitOptions f = fo_;
        f.max_iterations = t.iterations;
        f.refine_scan = t.iterations >= fo_.max_iterations;  // screening ranks by the coarse scan
        // The start model equals the current model when the candidate starts at its null value.
        if (t.start.empty()) f.start_evaluation = &cur_train_[t.fold];
        FitTask r;
        r.fit = fitModel(ds_, m, freeParamsOf(m, free_effects), train_[t.fold], f, pool_);
        r.heldout = evaluate(ds_, r.fit.model, test_[t.fold], fo_.eval, pool_);
        return r;
      },
      [&](std::size_t) { bar.tick(); });
  bar.finish();
  std::vector<FitTask> out_tasks(tasks.size());
  for (std::size_t k = 0; k < order.size(); ++k) out_tasks[order[k]] = std::move(res[k]);
  return out_tasks;
}

CandidateScore Stepwise::score(const std::string& effect, const std::vector<const FitTask*>& per_fold,
                               const std::vector<double>& base_fold_rss, double base_rss) const {
  CandidateScore s;
  s.effect = effect;
  s.params = candidateParams(ds_, effect);
  s.all_folds_improve = true;
  std::vector<Evaluation> parts;
  for (int f = 0; f < K_; ++f) {
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
  s.passes = s.delta_bic > opt_.bic_threshold && s.all_folds_improve && s.reduction >= opt_.min_reduction;
  s.heldout = parts;
  return s;
}

std::vector<FitTask> Stepwise::foldFits(const std::string& label, std::size_t n,
                                        const std::function<ModelSpec(std::size_t, std::vector<int>&)>& model_of,
                                        const std::function<int(std::size_t)>& fold_of) {
  ProgressBar bar(opt_.progress, label, n);
  auto res = pool_.map<FitTask>(
      n,
      [&](std::size_t k) {
        std::vector<int> free;
        const ModelSpec m = model_of(k, free);
        const int f = fold_of(k);
        FitTask r;
        r.fit = fitModel(ds_, m, freeParamsOf(m, free), train_[f], fo_, pool_);
        r.heldout = evaluate(ds_, r.fit.model, test_[f], fo_.eval, pool_);
        return r;
      },
      [&](std::size_t) { bar.tick(); });
  bar.finish();
  return res;
}

/// Accept the step's best candidate: its indistinguishable rivals, its per-fold estimates, every
/// accepted parameter refit on all runs from the folds' mean, and its runners-up.
void Stepwise::accept(const std::string& tag, DiagnoseRound& rd) {
  const CandidateScore& best = rd.ranked.front();
  rd.accepted = best.effect;
  // A rival is indistinguishable when the evidence barely separates them, or when its held-out
  // error is within the simulation's resolution of the best's (min_reduction: below that the
  // difference is the replay's chaos, which BIC would count as evidence: on cruise-only data a
  // speed scale and a dead-band swap places from seed to seed with dBIC gaps up to 130).
  for (std::size_t i = 1; i < rd.ranked.size(); ++i) {
    const CandidateScore& rival = rd.ranked[i];
    const bool close_evidence = rival.delta_bic > best.delta_bic - opt_.ambiguity_margin;
    const bool close_error = rival.cv_rss <= (1 + opt_.min_reduction) * best.cv_rss;
    if (rival.passes && (close_evidence || close_error)) rd.indistinguishable.push_back(rival.effect);
  }
  for (const auto& r : rd.indistinguishable) out_.ambiguous.push_back({best.effect, r});
  out_.accepted.push_back(best.effect);
  for (std::size_t j = 0; j < best.params.size(); ++j)
    for (const auto& fv : best.fold_values)
      if (j < fv.size()) fold_estimates_[best.effect + "." + best.params[j]].push_back(fv[j]);

  // Refit every accepted parameter on all runs, from the folds' mean.
  ModelSpec m = current_;
  EffectConfig ec = candidateConfig(ds_, best.effect);
  for (std::size_t j = 0; j < best.params.size(); ++j) {
    double mean = 0;
    for (const auto& fv : best.fold_values) mean += j < fv.size() ? fv[j] : 0;
    ec.params[best.params[j]] = mean / std::max<std::size_t>(1, best.fold_values.size());
  }
  m.effects.push_back(ec);
  accepted_idx_.push_back(static_cast<int>(m.effects.size()) - 1);
  {
    ProgressBar bar2(opt_.progress, tag + "refit on all runs", 1);
    out_.final_fit = fitModel(ds_, m, freeParamsOf(m, accepted_idx_), allRuns(ds_), fo_, pool_);
    bar2.tick();
    bar2.finish();
  }
  current_ = out_.final_fit.model;
  cur_fold_ = best.heldout;
  for (int f = 0; f < K_; ++f) cur_train_[f] = trainEval(out_.final_fit.evaluation, f);
  // Runners-up of this step: the passing finalists, tried again as replacements later.
  std::vector<std::string> rivals;
  for (std::size_t i = 1; i < rd.ranked.size() && rivals.size() < 4; ++i)
    if (rd.ranked[i].delta_bic > opt_.bic_threshold && rd.ranked[i].reduction >= opt_.min_reduction)
      rivals.push_back(rd.ranked[i].effect);
  runners_up_[best.effect] = rivals;
}

Without Stepwise::without(const std::string& effect) const {
  Without w;
  w.model = current_;
  for (std::size_t i = 0; i < w.model.effects.size(); ++i)
    if (w.model.effects[i].name == effect) w.removed = static_cast<int>(i);
  if (w.removed < 0) return w;
  w.model.effects.erase(w.model.effects.begin() + w.removed);
  for (int i : accepted_idx_)
    if (i != w.removed) w.idx.push_back(i > w.removed ? i - 1 : i);
  return w;
}

/// `m` (its accepted parameters accepted_idx_) refit on all runs is the current model, with
/// `heldout` its per-fold held-out residuals.
void Stepwise::adopt(const ModelSpec& m, std::vector<Evaluation> heldout) {
  out_.final_fit = fitModel(ds_, m, freeParamsOf(m, accepted_idx_), allRuns(ds_), fo_, pool_);
  current_ = out_.final_fit.model;
  cur_fold_ = std::move(heldout);
  for (int f = 0; f < K_; ++f) cur_train_[f] = trainEval(out_.final_fit.evaluation, f);
}

void Stepwise::dropAmbiguity(const std::string& effect) {
  out_.ambiguous.erase(std::remove_if(out_.ambiguous.begin(), out_.ambiguous.end(),
                                      [&](const auto& p) { return p.first == effect || p.second == effect; }),
                       out_.ambiguous.end());
}

/// Removal check (backward step): an effect accepted earlier that the new one has made redundant
/// (removing it, all other parameters refit per fold, costs less than the acceptance bar) is dropped.
void Stepwise::removalChecks(const std::string& tag, DiagnoseRound& rd) {
  for (std::size_t a = 0; a + 1 < out_.accepted.size() && out_.accepted.size() > 1;) {
    const std::string old_effect = out_.accepted[a];
    const Without w = without(old_effect);
    if (w.removed < 0) {
      ++a;
      continue;
    }
    const auto rm = foldFits(
        tag + "checking removal of " + old_effect, K_,
        [&](std::size_t, std::vector<int>& free) {
          free = w.idx;
          return w.model;
        },
        [](std::size_t f) { return static_cast<int>(f); });
    std::vector<Evaluation> parts;
    double rss_without = 0;
    for (int f = 0; f < K_; ++f) {
      parts.push_back(rm[f].heldout);
      rss_without += rm[f].heldout.rss();
    }
    const double cur_rss = sumRss(cur_fold_);
    const double k = static_cast<double>(candidateParams(ds_, old_effect).size());
    const double n_eff = merge(cur_fold_).nEffective();
    const double dbic = n_eff * std::log(std::max(1e-300, rss_without) / std::max(1e-300, cur_rss)) -
                        k * std::log(std::max(2.0, n_eff));
    const bool keep = dbic > opt_.bic_threshold && rss_without >= cur_rss * (1 + opt_.min_reduction);
    log("  removal check " + old_effect + ": held-out RSS without it " + fmt(rss_without, 6) + " vs " +
        fmt(cur_rss, 6) + (keep ? " (kept)" : " (removed)"));
    if (keep) {
      ++a;
      continue;
    }
    rd.removed.push_back(old_effect);
    out_.accepted.erase(out_.accepted.begin() + a);
    dropAmbiguity(old_effect);
    accepted_idx_ = w.idx;
    adopt(w.model, parts);
  }
}

/// Replacement check (stepwise with swaps): an effect accepted earlier may have stood in for one
/// that only now, next to the new effect, shows its worth (e.g. a rate limit imitating a delay
/// before the speed error was explained). Try each earlier effect's runners-up in its place, all
/// parameters refit per fold; swap if the held-out error falls clearly.
void Stepwise::replacementChecks(const std::string& tag, DiagnoseRound& rd) {
  for (std::size_t a = 0; a + 1 < out_.accepted.size(); ++a) tryReplacement(a, tag, rd);
}

bool Stepwise::tryReplacement(std::size_t a, const std::string& tag, DiagnoseRound& rd) {
  const std::string old_effect = out_.accepted[a];
  std::vector<std::string> options;
  for (const auto& b : runners_up_[old_effect]) {
    bool present = false;
    for (const auto& e : current_.effects) present |= e.name == b;
    if (!present) options.push_back(b);
  }
  if (options.empty()) return false;
  const Without w = without(old_effect);
  if (w.removed < 0) return false;
  const auto sw = foldFits(
      tag + "checking replacements of " + old_effect, options.size() * K_,
      [&](std::size_t k, std::vector<int>& free) {
        ModelSpec m = w.model;
        m.effects.push_back(candidateConfig(ds_, options[k / K_]));
        free = w.idx;
        free.push_back(static_cast<int>(m.effects.size()) - 1);
        return m;
      },
      [&](std::size_t k) { return static_cast<int>(k % K_); });
  const double cur_rss = sumRss(cur_fold_);
  double best_rss = cur_rss * (1 - opt_.min_reduction);
  int best_option = -1;
  std::vector<Evaluation> best_parts;
  for (std::size_t o = 0; o < options.size(); ++o) {
    std::vector<Evaluation> parts;
    double total = 0;
    for (int f = 0; f < K_; ++f) {
      parts.push_back(sw[o * K_ + f].heldout);
      total += sw[o * K_ + f].heldout.rss();
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
                   options[o].c_str(), sw[o * K_].heldout.rss() + (K_ > 1 ? sw[o * K_ + 1].heldout.rss() : 0), cur_rss);
  if (best_option < 0) return false;
  const std::string new_effect = options[best_option];
  log("  swap: " + old_effect + " -> " + new_effect + " (held-out RSS " + fmt(cur_rss, 6) + " -> " +
      fmt(best_rss, 6) + ")");
  rd.swaps.push_back({old_effect, new_effect});
  out_.accepted[a] = new_effect;
  dropAmbiguity(old_effect);
  ModelSpec m = w.model;
  EffectConfig ec = candidateConfig(ds_, new_effect);
  for (const auto& pname : candidateParams(ds_, new_effect)) {
    double mean = 0;
    for (int f = 0; f < K_; ++f) {
      const FitResult& fr = sw[best_option * K_ + f].fit;
      for (std::size_t q = 0; q < fr.free.size(); ++q)
        if (fr.free[q].effect == static_cast<int>(fr.model.effects.size()) - 1 && fr.free[q].name == pname)
          mean += fr.value[q] / K_;
    }
    ec.params[pname] = mean;
  }
  m.effects.push_back(ec);
  accepted_idx_ = w.idx;
  accepted_idx_.push_back(static_cast<int>(m.effects.size()) - 1);
  adopt(m, best_parts);
  runners_up_[new_effect] = runners_up_[old_effect];
  for (int f = 0; f < K_; ++f) {
    const FitResult& fr = sw[best_option * K_ + f].fit;
    for (std::size_t q = 0; q < fr.free.size(); ++q)
      if (fr.free[q].effect == static_cast<int>(fr.model.effects.size()) - 1)
        fold_estimates_[new_effect + "." + fr.free[q].name].push_back(fr.value[q]);
  }
  return true;
}

/// The final model, its held-out error and the residual structure (all runs, with features).
void Stepwise::finish() {
  out_.final_model = current_;
  out_.heldout_rms_after = n_heldout_ ? std::sqrt(sumRss(cur_fold_) / n_heldout_) : 0;
  out_.heldout_after_by_channel = merge(cur_fold_).byChannel(fo_.eval.huber);
  EvalOptions eo = fo_.eval;
  eo.replay.keep_trace = true;
  const Evaluation fin = evaluate(ds_, current_, allRuns(ds_), eo, pool_);
  out_.structure = residualStructure(ds_, fin, current_);
  for (const auto& s : out_.structure) out_.structure_flagged |= s.flagged;
}

/// The verdict's lines for the accepted effects: values with intervals, steps, removals, swaps,
/// pairs it cannot tell apart.
void Stepwise::verdictAccepted(std::ostringstream& v) {
  const EffectRegistry& reg = EffectRegistry::instance();
  v << "VERDICT: " << out_.accepted.size() << " effect" << (out_.accepted.size() > 1 ? "s" : "")
    << " accepted (held-out evidence dBIC > " << opt_.bic_threshold << ", held-out error down >= "
    << fmt(100 * opt_.min_reduction, 3) << " % and in every fold)\n";
  for (std::size_t j = 0; j < out_.final_fit.free.size(); ++j) {
    const FreeParam& p = out_.final_fit.free[j];
    const std::string& en = out_.final_fit.model.effects[p.effect].name;
    if (std::find(out_.accepted.begin(), out_.accepted.end(), en) == out_.accepted.end()) continue;
    // Interval: the larger of the analytic one ((J'J)^-1 s^2, measurement noise only) and the
    // spread of the per-fold estimates (which also carries the simulation's own sensitivity).
    double se = out_.final_fit.stderr_[j];
    auto fe = fold_estimates_.find(en + "." + p.name);
    if (fe != fold_estimates_.end() && fe->second.size() >= 2) {
      double m = 0, ss = 0;
      for (double x : fe->second) m += x / fe->second.size();
      for (double x : fe->second) ss += (x - m) * (x - m);
      const double sd = std::sqrt(ss / (fe->second.size() - 1));
      se = std::max(se, sd / std::sqrt(static_cast<double>(fe->second.size())));
    }
    out_.interval95.push_back(1.96 * se);
    v << "  " << en << "." << p.name << " = " << fmt(out_.final_fit.value[j], 5) << " +- " << fmt(1.96 * se, 2)
      << " " << p.spec.unit << " (95 % interval; null " << fmt(p.spec.null_value, 4) << ")\n";
  }
  for (std::size_t r = 0; r < out_.rounds.size(); ++r) {
    const auto& rd = out_.rounds[r];
    if (rd.accepted.empty()) continue;
    v << "  step " << r + 1 << ": " << rd.accepted << " (" << reg.info(rd.accepted).title << "), held-out dBIC "
      << fmt(rd.ranked.front().delta_bic, 5) << ", held-out error -" << fmt(100 * rd.ranked.front().reduction, 3)
      << " %\n";
  }
  for (std::size_t r = 0; r < out_.rounds.size(); ++r)
    for (const auto& a : out_.rounds[r].removed)
      v << "  after step " << r + 1 << ": " << a << " removed (redundant next to the later effects)\n";
  for (std::size_t r = 0; r < out_.rounds.size(); ++r)
    for (const auto& [a, b] : out_.rounds[r].swaps)
      v << "  after step " << r + 1 << ": " << a << " replaced by " << b
        << " (it had stood in for it; held-out error lower with " << b << ")\n";
  for (const auto& [a, b] : out_.ambiguous)
    v << "  CANNOT TELL APART: " << a << " and " << b << " explain the data almost equally well.\n"
      << "    experiment that separates them: " << separatingExperiment(a, b) << "\n";
}

/// The verdict: what was accepted (or why nothing), the best rejected candidate, the held-out
/// error before and after, and the residual structure left.
void Stepwise::writeVerdict() {
  std::ostringstream v;
  if (!out_.accepted.empty()) {
    verdictAccepted(v);
  } else {
    const bool at_floor = out_.heldout_rms_before < 1.25 && !out_.structure_flagged;
    if (at_floor) {
      v << "VERDICT: no effect needed: the residual is at the noise floor (held-out normalised RMS "
        << fmt(out_.heldout_rms_before, 3) << ")\n";
    } else {
      v << "VERDICT: no effect in the library explains the residual.\n";
    }
  }
  if (!out_.rounds.empty() && !out_.rounds.back().ranked.empty() && out_.rounds.back().accepted.empty()) {
    const auto& b = out_.rounds.back().ranked.front();
    // A screened-only candidate (not among the finalists refined) misses no rule by its score.
    const std::string why = rejectionReason(b, out_.rounds.back().current_fold_rss, opt_);
    v << "  best rejected candidate: " << b.effect << " (held-out dBIC " << fmt(b.delta_bic, 4) << ", error "
      << (b.reduction >= 0 ? "-" : "+") << fmt(100 * std::abs(b.reduction), 3) << " %): "
      << (why.empty() ? "screened only, not refined" : why) << "\n";
  }
  v << "  held-out normalised RMS: " << fmt(out_.heldout_rms_before, 4) << " -> " << fmt(out_.heldout_rms_after, 4)
    << " (noise floor ~ 1)\n";
  bool any = false;
  for (const auto& s : out_.structure) {
    if (!s.flagged) continue;
    if (!any) v << "  STRUCTURE REMAINS in:\n";
    any = true;
    v << "    " << s.group << ": RMS " << fmt(s.rms, 3) << " x noise, lag-1 autocorrelation " << fmt(s.rho1, 2)
      << ", strongest correlation with " << s.feature << " (r = " << fmt(s.correlation, 2) << "), worst run "
      << s.worst_run << "\n";
  }
  if (!any) v << "  residual structure: none flagged (every channel group near the noise floor or uncorrelated)\n";
  if (K_ == 1) v << "  note: only one run, so the scores are in-sample\n";
  out_.verdict = v.str();
}

}  // namespace

DiagnoseResult diagnose(const Dataset& ds, const DiagnoseOptions& opt, WorkerPool& pool) {
  return Stepwise(ds, opt, pool).run();
}

}  // namespace sbot::calib
