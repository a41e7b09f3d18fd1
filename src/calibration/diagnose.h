// Which physical effect is missing? Forward stepwise selection over the effects library:
//   for every candidate effect, fit its parameters by re-simulation on the training runs of each
//   fold (k-fold split by run, never by sample), score the fitted model on the held-out runs, and
//   rank the candidates by the held-out BIC gain
//       dBIC = n_eff ln(RSS_cur / RSS_cand) - k ln(n_eff)
//   (RSS: held-out robust normalised residual sum of squares; n_eff: samples corrected for the
//   residuals' lag-1 autocorrelation, so structured misfit does not count as independent evidence).
//   Accept the best if dBIC > threshold and every fold improves; refit all accepted effects on all
//   runs (parameters +- 95 % intervals); repeat until no candidate passes.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "calibration/fit.h"

namespace sbot::calib {

struct DiagnoseOptions {
  int folds = 2;
  double bic_threshold = 10;      ///< "very strong" evidence (Kass & Raftery)
  /// Minimum held-out RSS reduction for acceptance. The simulation is slightly chaotic: the same
  /// model with parameters a hair apart differs by 1-2 % in held-out RSS, so smaller gains are noise.
  double min_reduction = 0.05;
  /// Candidates within this dBIC of the best, or whose held-out RSS is within min_reduction of the
  /// best's, are "indistinguishable" (reported with the experiment that would separate them).
  double ambiguity_margin = 6;
  int max_effects = 4;
  int screen_iterations = 2;      ///< LM iterations when screening every candidate
  int finalists = 3;              ///< candidates refined to convergence per step
  std::vector<std::string> candidates;  ///< default: every library effect whose channels are measured
  ModelSpec base;                 ///< starting model (effects already known, e.g. from --effects)
  FitOptions fit;
  std::uint64_t seed = 1;         ///< fold assignment
  bool progress = false;          ///< progress bar on stderr
  std::function<void(const std::string&)> log;  ///< verbose lines (optional)
};

struct CandidateScore {
  std::string effect;
  std::vector<std::string> params;
  std::vector<std::vector<double>> fold_values;  ///< per fold: fitted values of the candidate's params
  double cv_rss = 0;            ///< held-out robust RSS (sum over folds)
  std::size_t n = 0;
  double n_eff = 0;
  double rho1 = 0;
  double delta_bic = 0;
  double reduction = 0;         ///< 1 - cv_rss / cv_rss_current
  bool all_folds_improve = false;
  bool passes = false;
  std::vector<double> fold_rss; ///< held-out RSS per fold
  std::vector<Evaluation> heldout;  ///< held-out residuals per fold
};

struct DiagnoseRound {
  double current_cv_rss = 0;
  std::vector<double> current_fold_rss;
  std::vector<CandidateScore> ranked;   ///< best first
  std::string accepted;                 ///< empty when none passed
  std::vector<std::string> indistinguishable;  ///< passing candidates within the margin of the best
  std::vector<std::pair<std::string, std::string>> swaps;  ///< (replaced, replacement) after this step
  std::vector<std::string> removed;     ///< earlier effects dropped as redundant after this step
};

struct StructureNote {
  std::string group;            ///< channel group
  double rms = 0;               ///< normalised RMS (noise floor ~ 1)
  double rho1 = 0;              ///< lag-1 autocorrelation
  std::string worst_run;
  std::string feature;          ///< residual feature with the strongest correlation
  double correlation = 0;
  bool flagged = false;
};

struct DiagnoseResult {
  std::vector<int> fold_of_run;
  std::vector<DiagnoseRound> rounds;
  std::vector<std::string> accepted;
  ModelSpec final_model;
  FitResult final_fit;          ///< all accepted parameters refit on all runs
  /// 95 % half-widths of the accepted parameters (verdict order): max of the analytic interval and
  /// the spread of the per-fold estimates.
  std::vector<double> interval95;
  double heldout_rms_before = 0, heldout_rms_after = 0;  ///< normalised held-out RMS
  std::map<std::string, ChannelRss> heldout_before_by_channel, heldout_after_by_channel;  ///< the same, per channel
  std::vector<StructureNote> structure;   ///< of the final model's residuals
  bool structure_flagged = false;
  std::vector<std::pair<std::string, std::string>> ambiguous;  ///< (accepted, rival)
  std::string verdict;          ///< human-readable, several lines
  double seconds = 0;
  int simulations = 0;
};

DiagnoseResult diagnose(const Dataset& ds, const DiagnoseOptions& opt, WorkerPool& pool);

/// Library effects a dataset can reveal (their channels are measured and simulated).
std::vector<std::string> candidateEffects(const Dataset& ds);

/// "" when `ds` measures (and the replay simulates) a channel the effect acts on; else why not, e.g.
/// "ir_incidence acts on ir, which dataset 'x' does not measure (it measures position, yaw)". Fitting
/// such an effect leaves it at its start with a meaningless interval.
std::string unmeasuredChannels(const Dataset& ds, const std::string& effect);
/// "" unless the effect's parameters are per surface (ir_reflectance) and `ds` has no obstacle with
/// a surface label to give it one (candidateConfig would give it no parameter).
std::string missingSurfaces(const Dataset& ds, const std::string& effect);

/// The configuration a candidate effect starts from (open-parameter effects get one parameter per
/// obstacle surface of the dataset) and the names of its free parameters, in fit order.
EffectConfig candidateConfig(const Dataset& ds, const std::string& name);
std::vector<std::string> candidateParams(const Dataset& ds, const std::string& name);

/// The folds diagnose uses for `folds` requested: at most one per run (one run: 1, in-sample).
int foldCount(const Dataset& ds, int folds);

/// Split runs into folds: runs of each experiment group are dealt round-robin (shuffled by seed),
/// so every fold sees every kind of experiment when there are enough runs.
std::vector<int> assignFolds(const Dataset& ds, int folds, std::uint64_t seed);

/// Which of the acceptance rules a candidate misses (for the verdict's "best rejected candidate"),
/// each in words: "dBIC 3.2 is not above 10", "the held-out error falls 4.8 %, less
/// than 5 %", "fold 2 not improved" (against `base_fold_rss`, the current model's held-out RSS
/// per fold). Empty when it passes them all.
std::string rejectionReason(const CandidateScore& s, const std::vector<double>& base_fold_rss,
                            const DiagnoseOptions& opt);

/// The experiment that separates two effects (for "cannot tell apart" verdicts).
std::string separatingExperiment(const std::string& a, const std::string& b);

/// Residual structure of an evaluation per channel group (for verdicts and reports).
std::vector<StructureNote> residualStructure(const Dataset& ds, const Evaluation& ev, const ModelSpec& model);

}  // namespace sbot::calib
