#include "calibration/fit.h"

#include "calibration/codec.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>

namespace sbot::calib {
namespace {

/// Evaluate several models on the same runs as one parallel batch.
std::vector<Evaluation> batch(const Dataset& ds, const std::vector<ModelSpec>& models, const std::vector<int>& runs,
                              const EvalOptions& opt, WorkerPool& pool) {
  std::vector<Evaluation> out(models.size());
  for (auto& e : out) e.runs.resize(runs.size());
  std::vector<std::pair<std::size_t, std::size_t>> jobs;
  for (std::size_t m = 0; m < models.size(); ++m)
    for (std::size_t r = 0; r < runs.size(); ++r) jobs.push_back({m, r});
  std::stable_sort(jobs.begin(), jobs.end(), [&](const auto& a, const auto& b) {
    return ds.runs[runs[a.second]].t_end > ds.runs[runs[b.second]].t_end;
  });
  ReplayOptions ro = opt.replay;
  ro.world_override = opt.world_override;
  ro.keep_trace = false;
  auto res = pool.map<RunResiduals>(jobs.size(), [&](std::size_t k) {
    const auto [m, r] = jobs[k];
    RunPrediction p = replayRun(ds, ds.runs[runs[r]], models[m], ro);
    return residualsOf(ds, runs[r], p, opt);
  });
  for (std::size_t k = 0; k < jobs.size(); ++k) out[jobs[k].first].runs[jobs[k].second] = std::move(res[k]);
  return out;
}

double clampTo(const ParamSpec& s, double v) { return std::max(s.lower, std::min(s.upper, v)); }

}  // namespace

void applyParams(ModelSpec& model, const std::vector<FreeParam>& free, const std::vector<double>& v) {
  for (std::size_t j = 0; j < free.size(); ++j) model.effects[free[j].effect].params[free[j].name] = v[j];
}

std::vector<FreeParam> freeParamsOf(const ModelSpec& model, const std::vector<int>& effects) {
  std::vector<FreeParam> out;
  const EffectRegistry& reg = EffectRegistry::instance();
  for (int e : effects) {
    const EffectInfo& info = reg.info(model.effects[e].name);
    if (info.open_params || !model.effects[e].params.empty()) {
      // The parameters the configuration lists (open parameters, or a chosen subset).
      for (const auto& [k, v] : model.effects[e].params) {
        const ParamSpec* spec = info.specFor(k);
        if (!spec) continue;
        FreeParam p{e, k, *spec};
        p.spec.name = k;
        out.push_back(p);
      }
    } else {
      for (const auto& s : info.params) out.push_back({e, s.name, s});
    }
  }
  return out;
}

namespace {

/// fitModel's state: the parameter vector, the residuals and cost there, the Jacobian and the
/// Levenberg-Marquardt damping, with one method per stage.
class Fitter {
 public:
  Fitter(const Dataset& ds, const ModelSpec& start, const std::vector<FreeParam>& free, const std::vector<int>& runs,
         const FitOptions& opt, WorkerPool& pool)
      : ds_(ds), start_(start), free_(free), runs_(runs), opt_(opt), pool_(pool), k_(free.size()) {}
  FitResult run();

 private:
  void startAt();
  void jacobian(int it);
  void scanFlat();
  void refineByParabola(std::size_t j, double spacing);
  bool dampedStep(int it);
  void covariance();

  ModelSpec modelAt(const std::vector<double>& th) const {
    ModelSpec m = start_;
    applyParams(m, free_, th);
    return m;
  }
  std::vector<Evaluation> eval(const std::vector<ModelSpec>& models) {
    auto ev = batch(ds_, models, runs_, opt_.eval, pool_);
    ++res_.evaluations;
    if (opt_.on_evaluation) opt_.on_evaluation();
    return ev;
  }
  /// Finite-difference step of parameter j at th: forward, backward at the upper bound.
  double fdStep(std::size_t j, const std::vector<double>& th) const {
    const ParamSpec& s = free_[j].spec;
    const double h = opt_.fd_step * s.scale;
    return th[j] + h > s.upper ? -h : h;
  }

  const Dataset& ds_;
  const ModelSpec& start_;
  const std::vector<FreeParam>& free_;
  const std::vector<int>& runs_;
  const FitOptions& opt_;
  WorkerPool& pool_;
  const std::size_t k_;
  FitResult res_;
  std::vector<double> theta_;
  Evaluation cur_;
  double cost_ = 0;
  Eigen::MatrixXd J_;
  double lambda_ = 1e-3;
};

FitResult Fitter::run() {
  res_.free = free_;
  startAt();
  for (int it = 0; it < opt_.max_iterations && k_ > 0; ++it) {
    res_.iterations = it + 1;
    jacobian(it);
    if (!dampedStep(it)) {
      res_.converged = true;
      break;
    }
  }
  covariance();
  res_.evaluation = std::move(cur_);
  return std::move(res_);
}

/// theta at the start model's values (clamped into bounds; null values where it has none), and
/// its residuals (opt.start_evaluation when given).
void Fitter::startAt() {
  theta_.resize(k_);
  for (std::size_t j = 0; j < k_; ++j) {
    auto it = start_.effects[free_[j].effect].params.find(free_[j].name);
    theta_[j] = clampTo(free_[j].spec, it == start_.effects[free_[j].effect].params.end() ? free_[j].spec.null_value
                                                                                          : it->second);
  }
  if (opt_.start_evaluation && opt_.start_evaluation->runs.size() == runs_.size()) {
    cur_ = *opt_.start_evaluation;
  } else {
    cur_ = eval({modelAt(theta_)})[0];
  }
  cost_ = cur_.rss();
  res_.rss_start = cost_;
}

/// The Jacobian by forward differences (backward at the upper bound), all columns in one batch;
/// at the first iteration, the coarse scan of flat or scan_first parameters.
void Fitter::jacobian(int it) {
  std::vector<ModelSpec> probes;
  std::vector<double> h(k_);
  for (std::size_t j = 0; j < k_; ++j) {
    h[j] = fdStep(j, theta_);
    std::vector<double> th = theta_;
    th[j] += h[j];
    probes.push_back(modelAt(th));
  }
  const auto cols = eval(probes);
  const Eigen::VectorXd r0 = cur_.stacked();
  J_.resize(r0.size(), k_);
  for (std::size_t j = 0; j < k_; ++j) J_.col(j) = (cols[j].stacked() - r0) / h[j];
  if (it == 0 && opt_.scan_flat) scanFlat();
}

/// Flat start (e.g. a saturation that never binds at its null value) or a parameter marked
/// scan_first (ParamSpec): coarse scan once.
void Fitter::scanFlat() {
  for (std::size_t j = 0; j < k_; ++j) {
    const bool flat = J_.col(j).norm() * free_[j].spec.scale <= 1e-3 * std::max(1.0, std::sqrt(cost_));
    if (!flat && !free_[j].spec.scan_first) continue;
    const ParamSpec& s = free_[j].spec;
    std::vector<ModelSpec> scan;
    std::vector<double> vals, spacing;
    // Scan toward both bounds: a saturation binds on one side only (torque_saturation's scale
    // below 1), and which side is not knowable from a flat start.
    const double lo = std::isfinite(s.lower) ? s.lower : s.null_value - 10 * s.scale;
    const double hi = std::isfinite(s.upper) ? s.upper : s.null_value + 10 * s.scale;
    for (double bound : {lo, hi}) {
      if (std::abs(bound - theta_[j]) < 1e-12) continue;  // starting at this bound
      for (double f : {0.25, 0.5, 0.75}) {
        std::vector<double> th = theta_;
        th[j] = theta_[j] + f * (bound - theta_[j]);
        vals.push_back(th[j]);
        spacing.push_back(0.25 * std::abs(bound - theta_[j]));
        scan.push_back(modelAt(th));
      }
    }
    const auto ev = eval(scan);
    std::size_t best = 0;
    for (std::size_t q = 1; q < ev.size(); ++q)
      if (ev[q].rss() < ev[best].rss()) best = q;
    if (!(ev[best].rss() < cost_)) continue;
    theta_[j] = vals[best];
    cur_ = ev[best];
    cost_ = cur_.rss();
    // scan_first parameters: a fine scan around the best point (spacing / 4 over +-spacing)
    // and the vertex of a least-squares parabola through it. The cost of these parameters
    // jitters from point to point (the simulation is slightly chaotic: rolling_resistance's
    // aggregate cost by +-2 % at 0.01 spacing), so any rule that keeps the lowest point
    // evaluated (the old bracket halving, the descent below) lands on a lucky sample (0.171
    // for a true 0.2); the parabola averages nine samples' jitter.
    if (s.scan_first && opt_.refine_scan) refineByParabola(j, spacing[best]);
    // Re-derive this column at the new point.
    std::vector<double> th = theta_;
    const double hj = fdStep(j, th);
    th[j] += hj;
    const auto c2 = eval({modelAt(th)})[0];
    J_.col(j) = (c2.stacked() - cur_.stacked()) / hj;
  }
}

/// See scanFlat. Moves theta[j] (and cur, cost) to the parabola's vertex, or to the lowest
/// fine-scan point if the parabola opens downwards, has its vertex outside the scan, or its
/// vertex's cost is off the parabola by more than 3 residual sds (the cost is not smooth there).
void Fitter::refineByParabola(std::size_t j, double spacing) {
  const ParamSpec& s = free_[j].spec;
  const double centre = theta_[j];
  std::vector<double> xs{centre}, ys{cost_};
  std::vector<ModelSpec> fine;
  std::vector<double> fine_vals;
  for (int q = -4; q <= 4; ++q) {
    const double v = centre + q * spacing / 4;
    if (q == 0 || v < s.lower || v > s.upper) continue;
    std::vector<double> th = theta_;
    th[j] = v;
    fine_vals.push_back(v);
    fine.push_back(modelAt(th));
  }
  if (fine.empty()) return;
  auto ev = eval(fine);
  std::size_t lowest = ev.size();  // ev.size(): the centre
  for (std::size_t q = 0; q < ev.size(); ++q) {
    xs.push_back(fine_vals[q]);
    ys.push_back(ev[q].rss());
    if (ev[q].rss() < (lowest == ev.size() ? cost_ : ev[lowest].rss())) lowest = q;
  }
  auto moveTo = [&](double v, Evaluation e) {
    theta_[j] = v;
    cur_ = std::move(e);
    cost_ = cur_.rss();
  };
  auto keepLowest = [&] {
    if (lowest < ev.size()) moveTo(fine_vals[lowest], std::move(ev[lowest]));
  };
  if (xs.size() < 4) return keepLowest();
  // y = c0 + c1 u + c2 u^2 with u = (x - centre) / spacing (conditioning).
  Eigen::MatrixXd A(xs.size(), 3);
  Eigen::VectorXd y(xs.size());
  for (std::size_t q = 0; q < xs.size(); ++q) {
    const double u = (xs[q] - centre) / spacing;
    A.row(q) << 1, u, u * u;
    y(q) = ys[q];
  }
  const Eigen::Vector3d c = A.colPivHouseholderQr().solve(y);
  const double resid_sd = std::sqrt((A * c - y).squaredNorm() / std::max<double>(1, xs.size() - 3));
  const double u_min = *std::min_element(xs.begin(), xs.end()) - centre, u_max = *std::max_element(xs.begin(), xs.end()) - centre;
  if (!(c(2) > 0)) return keepLowest();
  const double u_star = -c(1) / (2 * c(2));
  if (u_star * spacing < u_min || u_star * spacing > u_max) return keepLowest();
  std::vector<double> th = theta_;
  th[j] = centre + u_star * spacing;
  Evaluation at = eval({modelAt(th)})[0];
  const double predicted = c(0) + c(1) * u_star + c(2) * u_star * u_star;
  if (std::abs(at.rss() - predicted) > 3 * resid_sd + 1e-9 * std::abs(predicted)) return keepLowest();
  moveTo(th[j], std::move(at));
}

/// One damped Gauss-Newton step with Huber weights at the current residuals (IRLS), the damping
/// raised until the cost falls (at most 5 tries). False when the fit has converged.
bool Fitter::dampedStep(int it) {
  const Eigen::VectorXd r = cur_.stacked();
  const Eigen::VectorXd wts = cur_.weights(opt_.eval.huber);
  const Eigen::MatrixXd A = J_.transpose() * wts.asDiagonal() * J_;
  const Eigen::VectorXd g = J_.transpose() * wts.asDiagonal() * r;
  for (int tries = 0; tries < 5; ++tries) {
    Eigen::MatrixXd M = A;
    for (std::size_t j = 0; j < k_; ++j) {
      const double s2 = 1.0 / (free_[j].spec.scale * free_[j].spec.scale);
      M(j, j) += lambda_ * std::max(A(j, j), 1e-9 * s2) + 1e-12 * s2;
    }
    const Eigen::VectorXd delta = M.ldlt().solve(-g);
    std::vector<double> th = theta_;
    double step_norm = 0;
    for (std::size_t j = 0; j < k_; ++j) {
      th[j] = clampTo(free_[j].spec, theta_[j] + delta(j));
      step_norm = std::max(step_norm, std::abs(th[j] - theta_[j]) / free_[j].spec.scale);
    }
    // Predicted decrease of the quadratic model for the (clamped) step.
    Eigen::VectorXd d(k_);
    for (std::size_t j = 0; j < k_; ++j) d(j) = th[j] - theta_[j];
    const double predicted = -(g.dot(d) + 0.5 * d.dot(A * d));
    if (step_norm < 1e-4 || predicted < opt_.tolerance * cost_) return false;  // tiny step
    Evaluation trial = eval({modelAt(th)})[0];
    if (std::getenv("SBOT_CALIB_DEBUG")) {
      std::fprintf(stderr, "it %d try %d lambda %.3g cost %.6g -> %.6g theta", it, tries, lambda_, cost_, trial.rss());
      for (std::size_t j = 0; j < k_; ++j) std::fprintf(stderr, " %.6g->%.6g (g %.3g A %.3g)", theta_[j], th[j], g(j), A(j, j));
      std::fprintf(stderr, "\n");
    }
    if (trial.rss() < cost_) {
      const double rel = (cost_ - trial.rss()) / std::max(cost_, 1e-12);
      theta_ = th;
      cur_ = std::move(trial);
      cost_ = cur_.rss();
      lambda_ = std::max(1e-7, lambda_ / 4);
      return rel >= opt_.tolerance;
    }
    lambda_ *= 8;
    // A failed small step: the cost is jittery at this scale (the simulation is slightly chaotic).
    if (step_norm < 0.05) return false;
  }
  return false;  // not improved
}

/// Covariance at the optimum: (J'J)^-1 s^2, inflated by the autocorrelation of the residuals.
void Fitter::covariance() {
  res_.model = modelAt(theta_);
  res_.value = theta_;
  res_.rss = cost_;
  res_.n = cur_.n();
  res_.rho1 = cur_.rho1();
  res_.stderr_.assign(k_, std::numeric_limits<double>::quiet_NaN());
  if (k_ == 0 || J_.rows() == 0) return;
  const double dof = std::max<double>(1, static_cast<double>(res_.n) - k_);
  const double s2 = cost_ / dof;
  const double inflate = (1 + res_.rho1) / (1 - res_.rho1);
  const Eigen::VectorXd wts = cur_.weights(opt_.eval.huber);
  Eigen::MatrixXd A = J_.transpose() * wts.asDiagonal() * J_;
  for (std::size_t j = 0; j < k_; ++j) A(j, j) += 1e-12 / (free_[j].spec.scale * free_[j].spec.scale);
  res_.covariance = A.inverse() * s2 * inflate;
  for (std::size_t j = 0; j < k_; ++j) res_.stderr_[j] = std::sqrt(std::max(0.0, res_.covariance(j, j)));
}

}  // namespace

FitResult fitModel(const Dataset& ds, const ModelSpec& start, const std::vector<FreeParam>& free,
                   const std::vector<int>& runs, const FitOptions& opt, WorkerPool& pool) {
  return Fitter(ds, start, free, runs, opt, pool).run();
}

}  // namespace sbot::calib
