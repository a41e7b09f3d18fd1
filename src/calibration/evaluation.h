// Residuals of a model against a dataset: every measured sample becomes one normalised residual
// (measured - predicted) / sigma(channel), passed through a Huber loss so IR outliers cannot dominate.
// Channels can then be combined: a correct model gives a mean square of ~1 (the noise floor).
#pragma once

#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "calibration/dataset.h"
#include "calibration/parallel.h"
#include "calibration/replay.h"

namespace sbot::calib {

struct EvalOptions {
  double huber = 3.0;                 ///< Huber threshold in sigmas (<= 0: plain least squares)
  std::set<std::string> groups;       ///< channel groups to use (empty = every simulated group)
  ReplayOptions replay;
  const WorldConfig* world_override = nullptr;  ///< generator truth (tests only)
};

struct RunResiduals {
  int run = -1;
  std::vector<std::string> channels;  ///< channels used, sorted
  std::vector<int> chan;              ///< per residual: index into channels
  std::vector<double> t;              ///< per residual: time stamp (or placement row)
  std::vector<double> r;              ///< normalised residual (measured - predicted) / sigma (0 where not simulated)
  std::vector<double> raw;            ///< measured - predicted in channel units (yaw wrapped)
  std::vector<char> valid;
  double rss = 0;                     ///< robust sum: sum of huberLoss(r) (= sum r^2 without outliers)
  std::size_t n = 0;
  RunPrediction prediction;           ///< kept when EvalOptions::replay.keep_trace
};

/// Robust sum of squared normalised residuals of one channel and its sample count.
struct ChannelRss {
  double rss = 0;
  std::size_t n = 0;
  double rmsNormalised() const { return n ? std::sqrt(rss / n) : 0.0; }
};

struct Evaluation {
  std::vector<RunResiduals> runs;
  /// Per channel over all runs (channel name -> sums), with the Huber threshold the runs used.
  std::map<std::string, ChannelRss> byChannel(double huber) const;
  double rss() const;
  std::size_t n() const;
  Eigen::VectorXd stacked() const;
  /// IRLS weights of the Huber loss at these residuals (0 for samples that were not simulated).
  Eigen::VectorXd weights(double huber) const;
  /// Mean lag-1 autocorrelation of the residuals within each (run, channel) series, sample-weighted.
  double rho1() const;
  /// Effective number of independent samples n (1 - rho) / (1 + rho) (AR(1) approximation).
  double nEffective() const;
  double rmsNormalised() const { return n() ? std::sqrt(rss() / n()) : 0.0; }
};

/// Huber loss scaled like a square: z^2 inside [-c, c], 2c|z| - c^2 outside.
double huberLoss(double z, double c);

/// Replay `runs` (indices into ds.runs) in parallel and compute their residuals.
Evaluation evaluate(const Dataset& ds, const ModelSpec& model, const std::vector<int>& runs, const EvalOptions& opt,
                    WorkerPool& pool);
RunResiduals residualsOf(const Dataset& ds, int run_index, const RunPrediction& p, const EvalOptions& opt);

/// Channel groups the current build can simulate and the dataset measures.
std::set<std::string> usableGroups(const Dataset& ds);

std::vector<int> allRuns(const Dataset& ds);

/// How reproducible a drive run's replay is. The run is replayed twice more, from starts moved by
/// +kStartNudge and -kStartNudge sigma of the tracker's noise (x, y and yaw together), and each of
/// those predictions is compared with the first in the channels' noise scales; the run's
/// sensitivity is the larger of the two (a tipping threshold may lie on one side of the start only). The measured start is only known to that noise, so a replay that
/// the data can test must not depend on where within it the start lies. A model whose motion
/// depends smoothly on its start moves its prediction by far less than the noise (each replay's
/// start-pose alignment absorbs the nudge: Simple's default runs move by at most 0.55); a chaotic
/// one, such as a Fast robot tipping over in a turn at 1/50 g or a spin whose heading hangs on
/// which contacts come first, moves it by up to the whole signal. Its residuals then show where the
/// trajectory happened to go, not which physics is missing, and no effect can fit them.
struct ReplaySensitivity {
  int run = -1;                 ///< index into ds.runs
  double nrms = 0;              ///< RMS of (nudged - first prediction) / sigma over every channel, worse side
  std::string worst_channel;    ///< the channel that moved most
  double worst_nrms = 0;        ///< its RMS in noise units
};
/// The start moves by this many sigma of the tracker's noise. A much smaller nudge (0.01) misses a
/// robot near a tipping threshold (a Fast arc that the true model replays at nRMS 34 reads 0.4).
constexpr double kStartNudge = 1.0;
constexpr double kChaoticSensitivity = 1.0;  ///< above: the start moved the prediction more than the noise

/// The sensitivity of every drive run (place runs have no dynamics to diverge), with the replay
/// options of `opt` (alignment, hidden world): the largest over the nudges `sides` (in units of
/// kStartNudge; both ways by default, a single side to see what each contributes).
std::vector<ReplaySensitivity> replaySensitivity(const Dataset& ds, const ModelSpec& model, const EvalOptions& opt,
                                                 WorkerPool& pool, const std::vector<double>& sides = {1.0, -1.0});

/// The runs above kChaoticSensitivity, most sensitive first, e.g. "arc_left 21 (yaw 40)"; empty if none.
std::string describeChaoticRuns(const Dataset& ds, const std::vector<ReplaySensitivity>& s);

/// A dataset split by replaySensitivity: what a fit can use, and the runs it cannot.
struct ReplayableRuns {
  Dataset dataset;                    ///< ds without the chaotic runs (ds whole if every run is chaotic)
  std::vector<std::string> left_out;  ///< the chaotic runs taken out of `dataset`, in dataset order
  std::string chaotic;                ///< describeChaoticRuns of every chaotic run; empty if none
  bool all_chaotic = false;           ///< every run is: nothing would be left to fit, so `dataset` keeps them
};
/// The runs `model` replays reproducibly from its own start (what diagnose, fit and sweep fit by
/// default; their --keep-chaotic keeps every run).
ReplayableRuns replayableRuns(const Dataset& ds, const ModelSpec& model, const EvalOptions& opt, WorkerPool& pool);

/// The line that says which runs `split` leaves out (or keeps: `kept_on_request` is --keep-chaotic);
/// empty when every run is reproducible.
std::string describeSplit(const ReplayableRuns& split, bool kept_on_request);

/// The runs a fit or a diagnosis ends on (solveOnReplayableRuns).
struct ReplayableRounds {
  Dataset dataset;                      ///< the runs the last round solved on
  std::vector<std::string> left_out;    ///< the runs left out of the last round, in dataset order
  std::vector<std::string> readmitted;  ///< the runs re-admitted after round 1, in dataset order
  int round = 1;                        ///< the round whose result stands (1-based)
  int rounds = 1;                       ///< rounds solved
  std::string note;                     ///< why a later round was not kept ("" if the last one stands)
};
constexpr int kMaxReplayableRounds = 3;
/// Solve (fit, diagnose) on the runs a model replays reproducibly. Round 1: the runs `start` replays
/// (replayableRuns; every run if `keep_chaotic` or if none is). A solved model can replay a run the
/// start model could not (halved lateral track friction makes a Medium's fast spins skid evenly, and
/// those spins show the effect best), so while the model a round ends with replays some of the runs
/// left out, they are re-admitted and `solve` runs again, from `start`, on the larger set (at most
/// kMaxReplayableRounds rounds). A round that loses an effect the round before found does not stand:
/// its runs were reproducible at the earlier values only (`note` says so). `solve(runs, message)`
/// returns the model it ends with; `message` says which runs were left out or re-admitted ("" when
/// nothing was). The caller keeps each round's result and uses round `round`'s.
ReplayableRounds solveOnReplayableRuns(const Dataset& ds, const ModelSpec& start, const EvalOptions& opt,
                                       bool keep_chaotic, WorkerPool& pool,
                                       const std::function<ModelSpec(const Dataset& runs, const std::string& message)>& solve);

}  // namespace sbot::calib
