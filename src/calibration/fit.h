// Fitting effect parameters by re-simulation: Levenberg-Marquardt on the normalised residuals with
// finite-difference Jacobians (one column = one re-simulation of every fit run), bounds by clamping,
// and parameter covariance (J'J)^-1 s^2 inflated for residual autocorrelation.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "calibration/evaluation.h"
#include "sbot_sim/core/effects/effect_registry.h"

namespace sbot::calib {

/// One free parameter: model.effects[effect].params[name].
struct FreeParam {
  int effect = -1;
  std::string name;
  ParamSpec spec;
};

struct FitOptions {
  int max_iterations = 10;
  double fd_step = 0.5;          ///< finite-difference step, fraction of ParamSpec::scale (large: the
                                 ///< simulation is slightly chaotic, small steps give noisy slopes)
  double tolerance = 1e-4;       ///< stop when the relative cost decrease is below this
  bool scan_flat = true;         ///< coarse scan when the gradient at the start is flat
  /// Bracket refinement after the coarse scan of a scan_first parameter (fit.cpp). Off for
  /// diagnose's screening fits: with it, a scan_first candidate (torque_saturation) out-ranked a
  /// slowly converging true latency and pushed it out of the finalists (4/10 Simple datasets).
  bool refine_scan = true;
  EvalOptions eval;
  /// Residuals of the start model on the fit runs when already known (saves one re-simulation).
  const Evaluation* start_evaluation = nullptr;
  std::function<void()> on_evaluation;  ///< progress callback (one call per re-simulation batch)
};

struct FitResult {
  ModelSpec model;               ///< with the fitted values
  std::vector<FreeParam> free;
  std::vector<double> value, stderr_;
  Eigen::MatrixXd covariance;
  double rss = 0;                ///< robust normalised RSS at the optimum
  double rss_start = 0;
  std::size_t n = 0;
  double rho1 = 0;               ///< residual lag-1 autocorrelation at the optimum
  int iterations = 0, evaluations = 0;
  bool converged = false;
  Evaluation evaluation;         ///< residuals at the optimum (fit runs)
};

/// Free parameters of every effect in `model`: the parameters its configuration lists, or all its
/// declared parameters when it lists none.
std::vector<FreeParam> freeParamsOf(const ModelSpec& model, const std::vector<int>& effects);

FitResult fitModel(const Dataset& ds, const ModelSpec& start, const std::vector<FreeParam>& free,
                   const std::vector<int>& runs, const FitOptions& opt, WorkerPool& pool);

/// Set model.effects[p.effect].params[p.name] = v for every free parameter.
void applyParams(ModelSpec& model, const std::vector<FreeParam>& free, const std::vector<double>& v);

}  // namespace sbot::calib
