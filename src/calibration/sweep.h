// The statistical evaluation of `diagnose` on synthetic data with known hidden effects: for every
// case (one hidden effect, none, a floor tilt outside the library, two effects) and seed, generate a
// dataset, diagnose it, and check the verdict against the truth. `sbot_calibrate sweep` prints the
// full figures (docs/calibration.md); the test command runs a reduced set.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "calibration/diagnose.h"
#include "calibration/generator.h"

namespace sbot::calib {

struct SweepCase {
  std::string name;                  ///< "speed_scale", "none", "tilt2", "speed_scale+latency"
  std::vector<EffectConfig> hidden;
  double tilt_deg = 0;
  enum class Kind { Single, None, Outside, Pair } kind = Kind::Single;
  std::string level;                 ///< generator level override (empty: the sweep's)
  std::set<std::string> families;    ///< experiment families override (empty: the sweep's)
  bool torque = false;               ///< also measure track torques
};

struct SeedOutcome {
  std::uint64_t seed = 0;
  std::vector<std::string> accepted;
  std::map<std::string, double> estimate, truth;  ///< "effect.param" -> value
  double rms_before = 0, rms_after = 0, floor = 0;  ///< held-out normalised RMS; noise floor (truth model)
  /// The same three pooled over the channels where the starting model fails (its held-out nRMS on the
  /// channel above 1.2x the true model's): the effect's signature, undiluted by channels it leaves alone.
  std::vector<std::string> failing_channels;
  double failing_before = 0, failing_after = 0, failing_floor = 0;
  bool structure_flagged = false;
  double seconds = 0;
  std::string verdict;
  std::vector<std::string> left_out;  ///< runs no diagnosed model could replay, left out (not with keep_chaotic)
  std::vector<std::string> readmitted;  ///< runs the starting model could not replay but a diagnosed one could
  int round = 1, rounds = 1;            ///< the round that stands, of the rounds diagnosed (solveOnReplayableRuns)
};

struct CaseSummary {
  SweepCase c;
  std::vector<SeedOutcome> seeds;
  // fractions over seeds
  double right_first = 0;      ///< single: the hidden effect accepted first
  double params_within = 0;    ///< single: its parameters within +-10 %
  double rmse_halved = 0;      ///< single: held-out RMS fell by >= 50 %
  double at_floor = 0;         ///< held-out RMS ends within 1.2x the noise floor
  double failing_halved = 0;   ///< single/pair: on the failing channels, held-out RMS fell by >= 50 %
  double failing_at_floor = 0; ///< single/pair: on the failing channels, it ends within 1.2x their floor
  double none_accepted = 0;    ///< none / outside: nothing accepted
  double flagged = 0;          ///< outside: residual structure flagged
  double both_found = 0;       ///< pair: both effects accepted
  double mean_seconds = 0;
};

/// The standard cases: every drive effect the generator's experiments can reveal, none, tilt, pairs.
std::vector<SweepCase> standardCases(const std::string& level);

struct SweepOptions {
  std::vector<SweepCase> cases;
  int seeds = 10;
  std::uint64_t first_seed = 1;
  GeneratorOptions gen;          ///< level, duration, families (hidden/seed/tilt set per case)
  DiagnoseOptions diag;
  /// Diagnose every run, also those the starting model does not replay reproducibly (--keep-chaotic).
  /// By default they are left out and re-admitted once a diagnosed model replays them, as diagnose
  /// does (evaluation.h solveOnReplayableRuns); the noise floor is the true model's on the runs kept.
  bool keep_chaotic = false;
  bool progress = false;
};

std::vector<CaseSummary> runSweep(const SweepOptions& opt, WorkerPool& pool);
std::string sweepMarkdown(const std::vector<CaseSummary>& s, const SweepOptions& opt, double seconds);

/// The standard cases of `level` named in `names` (all of them when empty), the hidden effects' parameters
/// replaced by those `magnitudes` (sweep --set) give. Throws std::invalid_argument naming an unknown case
/// (and the known ones), or a magnitude for an effect no selected case hides.
std::vector<SweepCase> selectSweepCases(const std::string& level, const std::vector<std::string>& names,
                                        const std::vector<EffectConfig>& magnitudes);

}  // namespace sbot::calib
