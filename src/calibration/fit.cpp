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

FitResult fitModel(const Dataset& ds, const ModelSpec& start, const std::vector<FreeParam>& free,
                   const std::vector<int>& runs, const FitOptions& opt, WorkerPool& pool) {
  FitResult res;
  res.free = free;
  const std::size_t k = free.size();
  std::vector<double> theta(k);
  for (std::size_t j = 0; j < k; ++j) {
    auto it = start.effects[free[j].effect].params.find(free[j].name);
    theta[j] = clampTo(free[j].spec, it == start.effects[free[j].effect].params.end() ? free[j].spec.null_value
                                                                                       : it->second);
  }
  auto modelAt = [&](const std::vector<double>& th) {
    ModelSpec m = start;
    applyParams(m, free, th);
    return m;
  };
  auto tick = [&] {
    ++res.evaluations;
    if (opt.on_evaluation) opt.on_evaluation();
  };

  Evaluation cur;
  double cost = 0;
  // See the scan_first branch below. Moves theta[j] (and cur, cost) to the parabola's vertex, or to
  // the lowest fine-scan point if the parabola opens downwards, has its vertex outside the scan, or
  // its vertex's cost is off the parabola by more than 3 residual sds (the cost is not smooth there).
  auto refineByParabola = [&](std::size_t j, double spacing) {
    const ParamSpec& s = free[j].spec;
    const double centre = theta[j];
    std::vector<double> xs{centre}, ys{cost};
    std::vector<ModelSpec> fine;
    std::vector<double> fine_vals;
    for (int q = -4; q <= 4; ++q) {
      const double v = centre + q * spacing / 4;
      if (q == 0 || v < s.lower || v > s.upper) continue;
      std::vector<double> th = theta;
      th[j] = v;
      fine_vals.push_back(v);
      fine.push_back(modelAt(th));
    }
    if (fine.empty()) return;
    auto ev = batch(ds, fine, runs, opt.eval, pool);
    tick();
    std::size_t lowest = ev.size();  // ev.size(): the centre
    for (std::size_t q = 0; q < ev.size(); ++q) {
      xs.push_back(fine_vals[q]);
      ys.push_back(ev[q].rss());
      if (ev[q].rss() < (lowest == ev.size() ? cost : ev[lowest].rss())) lowest = q;
    }
    auto moveTo = [&](double v, Evaluation e) {
      theta[j] = v;
      cur = std::move(e);
      cost = cur.rss();
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
    std::vector<double> th = theta;
    th[j] = centre + u_star * spacing;
    Evaluation at = batch(ds, {modelAt(th)}, runs, opt.eval, pool)[0];
    tick();
    const double predicted = c(0) + c(1) * u_star + c(2) * u_star * u_star;
    if (std::abs(at.rss() - predicted) > 3 * resid_sd + 1e-9 * std::abs(predicted)) return keepLowest();
    moveTo(th[j], std::move(at));
  };
  if (opt.start_evaluation && opt.start_evaluation->runs.size() == runs.size()) {
    cur = *opt.start_evaluation;
  } else {
    cur = batch(ds, {modelAt(theta)}, runs, opt.eval, pool)[0];
    tick();
  }
  cost = cur.rss();
  res.rss_start = cost;
  Eigen::MatrixXd J;
  double lambda = 1e-3;

  for (int it = 0; it < opt.max_iterations && k > 0; ++it) {
    res.iterations = it + 1;
    // Jacobian by forward differences (backward at the upper bound), all columns in one batch.
    std::vector<ModelSpec> probes;
    std::vector<double> h(k);
    for (std::size_t j = 0; j < k; ++j) {
      const ParamSpec& s = free[j].spec;
      h[j] = opt.fd_step * s.scale;
      if (theta[j] + h[j] > s.upper) h[j] = -h[j];
      std::vector<double> th = theta;
      th[j] += h[j];
      probes.push_back(modelAt(th));
    }
    const auto cols = batch(ds, probes, runs, opt.eval, pool);
    tick();
    const Eigen::VectorXd r0 = cur.stacked();
    J.resize(r0.size(), k);
    for (std::size_t j = 0; j < k; ++j) J.col(j) = (cols[j].stacked() - r0) / h[j];

    // Flat start (e.g. a saturation that never binds at its null value) or a parameter marked
    // scan_first (ParamSpec): coarse scan once.
    if (it == 0 && opt.scan_flat) {
      for (std::size_t j = 0; j < k; ++j) {
        const bool flat = J.col(j).norm() * free[j].spec.scale <= 1e-3 * std::max(1.0, std::sqrt(cost));
        if (!flat && !free[j].spec.scan_first) continue;
        const ParamSpec& s = free[j].spec;
        std::vector<ModelSpec> scan;
        std::vector<double> vals, spacing;
        // Scan toward both bounds: a saturation binds on one side only (torque_saturation's scale
        // below 1), and which side is not knowable from a flat start.
        const double lo = std::isfinite(s.lower) ? s.lower : s.null_value - 10 * s.scale;
        const double hi = std::isfinite(s.upper) ? s.upper : s.null_value + 10 * s.scale;
        for (double bound : {lo, hi}) {
          if (std::abs(bound - theta[j]) < 1e-12) continue;  // starting at this bound
          for (double f : {0.25, 0.5, 0.75}) {
            std::vector<double> th = theta;
            th[j] = theta[j] + f * (bound - theta[j]);
            vals.push_back(th[j]);
            spacing.push_back(0.25 * std::abs(bound - theta[j]));
            scan.push_back(modelAt(th));
          }
        }
        const auto ev = batch(ds, scan, runs, opt.eval, pool);
        tick();
        std::size_t best = 0;
        for (std::size_t q = 1; q < ev.size(); ++q)
          if (ev[q].rss() < ev[best].rss()) best = q;
        if (ev[best].rss() < cost) {
          theta[j] = vals[best];
          cur = ev[best];
          cost = cur.rss();
          // scan_first parameters: a fine scan around the best point (spacing / 4 over +-spacing)
          // and the vertex of a least-squares parabola through it. The cost of these parameters
          // jitters from point to point (the simulation is slightly chaotic: rolling_resistance's
          // aggregate cost by +-2 % at 0.01 spacing), so any rule that keeps the lowest point
          // evaluated (the old bracket halving, the descent below) lands on a lucky sample (0.171
          // for a true 0.2); the parabola averages nine samples' jitter.
          if (s.scan_first && opt.refine_scan) refineByParabola(j, spacing[best]);
          // Re-derive this column at the new point.
          std::vector<double> th = theta;
          double hj = opt.fd_step * s.scale;
          if (th[j] + hj > s.upper) hj = -hj;
          th[j] += hj;
          const auto c2 = batch(ds, {modelAt(th)}, runs, opt.eval, pool)[0];
          tick();
          J.col(j) = (c2.stacked() - cur.stacked()) / hj;
        }
      }
    }

    // IRLS: Huber weights at the current residuals.
    const Eigen::VectorXd r = cur.stacked();
    const Eigen::VectorXd wts = cur.weights(opt.eval.huber);
    const Eigen::MatrixXd A = J.transpose() * wts.asDiagonal() * J;
    const Eigen::VectorXd g = J.transpose() * wts.asDiagonal() * r;
    bool improved = false;
    double rel = 0;
    bool tiny_step = false;
    for (int tries = 0; tries < 5; ++tries) {
      Eigen::MatrixXd M = A;
      for (std::size_t j = 0; j < k; ++j) {
        const double s2 = 1.0 / (free[j].spec.scale * free[j].spec.scale);
        M(j, j) += lambda * std::max(A(j, j), 1e-9 * s2) + 1e-12 * s2;
      }
      const Eigen::VectorXd delta = M.ldlt().solve(-g);
      std::vector<double> th = theta;
      double step_norm = 0;
      for (std::size_t j = 0; j < k; ++j) {
        th[j] = clampTo(free[j].spec, theta[j] + delta(j));
        step_norm = std::max(step_norm, std::abs(th[j] - theta[j]) / free[j].spec.scale);
      }
      // Predicted decrease of the quadratic model for the (clamped) step.
      Eigen::VectorXd d(k);
      for (std::size_t j = 0; j < k; ++j) d(j) = th[j] - theta[j];
      const double predicted = -(g.dot(d) + 0.5 * d.dot(A * d));
      if (step_norm < 1e-4 || predicted < opt.tolerance * cost) {
        tiny_step = true;
        break;
      }
      Evaluation trial = batch(ds, {modelAt(th)}, runs, opt.eval, pool)[0];
      tick();
      if (std::getenv("SBOT_CALIB_DEBUG")) {
        std::fprintf(stderr, "it %d try %d lambda %.3g cost %.6g -> %.6g theta", it, tries, lambda, cost, trial.rss());
        for (std::size_t j = 0; j < k; ++j) std::fprintf(stderr, " %.6g->%.6g (g %.3g A %.3g)", theta[j], th[j], g(j), A(j, j));
        std::fprintf(stderr, "\n");
      }
      if (trial.rss() < cost) {
        rel = (cost - trial.rss()) / std::max(cost, 1e-12);
        theta = th;
        cur = std::move(trial);
        cost = cur.rss();
        lambda = std::max(1e-7, lambda / 4);
        improved = true;
        break;
      }
      lambda *= 8;
      // A failed small step: the cost is jittery at this scale (the simulation is slightly chaotic).
      if (step_norm < 0.05) {
        tiny_step = true;
        break;
      }
    }
    if (!improved || rel < opt.tolerance || tiny_step) {
      res.converged = true;
      break;
    }
  }

  // Covariance at the optimum: (J'J)^-1 s^2, inflated by the autocorrelation of the residuals.
  res.model = modelAt(theta);
  res.value = theta;
  res.rss = cost;
  res.n = cur.n();
  res.rho1 = cur.rho1();
  res.stderr_.assign(k, std::numeric_limits<double>::quiet_NaN());
  if (k > 0 && J.rows() > 0) {
    const double dof = std::max<double>(1, static_cast<double>(res.n) - k);
    const double s2 = cost / dof;
    const double inflate = (1 + res.rho1) / (1 - res.rho1);
    const Eigen::VectorXd wts = cur.weights(opt.eval.huber);
    Eigen::MatrixXd A = J.transpose() * wts.asDiagonal() * J;
    for (std::size_t j = 0; j < k; ++j) A(j, j) += 1e-12 / (free[j].spec.scale * free[j].spec.scale);
    res.covariance = A.inverse() * s2 * inflate;
    for (std::size_t j = 0; j < k; ++j) res.stderr_[j] = std::sqrt(std::max(0.0, res.covariance(j, j)));
  }
  res.evaluation = std::move(cur);
  return res;
}

}  // namespace sbot::calib
