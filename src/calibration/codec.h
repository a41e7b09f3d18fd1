// save()/load() of the workbench's result types, for worker processes (parallel.h, serialize.h).
//
// A record's save() and load() must write and read the same members in the same order. So each record
// names that order once, as a tuple of member pointers (k...Members), and both directions walk it
// (saveMembers/loadMembers): adding a member in one place keeps the two sides in step.
#pragma once

#include <tuple>

#include "calibration/evaluation.h"
#include "calibration/fit.h"
#include "calibration/serialize.h"
#include "sbot_sim/core/effects/effect_registry.h"

namespace sbot::calib {

template <class Record, class Members>
void saveMembers(Writer& w, const Record& x, const Members& members) {
  std::apply([&](auto... m) { (save(w, x.*m), ...); }, members);
}
template <class Record, class Members>
void loadMembers(Reader& r, Record& x, const Members& members) {
  std::apply([&](auto... m) { (load(r, x.*m), ...); }, members);
}

}  // namespace sbot::calib

namespace sbot {

inline constexpr auto kPose2DMembers = std::make_tuple(&Pose2D::x, &Pose2D::y, &Pose2D::yaw);
inline void save(calib::Writer& w, const Pose2D& p) { calib::saveMembers(w, p, kPose2DMembers); }
inline void load(calib::Reader& r, Pose2D& p) { calib::loadMembers(r, p, kPose2DMembers); }

inline constexpr auto kEffectConfigMembers =
    std::make_tuple(&EffectConfig::name, &EffectConfig::params, &EffectConfig::stderr_, &EffectConfig::note);
inline void save(calib::Writer& w, const EffectConfig& c) { calib::saveMembers(w, c, kEffectConfigMembers); }
inline void load(calib::Reader& r, EffectConfig& c) { calib::loadMembers(r, c, kEffectConfigMembers); }

}  // namespace sbot

namespace sbot::calib {

inline constexpr auto kModelSpecMembers = std::make_tuple(&ModelSpec::level, &ModelSpec::effects);
inline void save(Writer& w, const ModelSpec& m) { saveMembers(w, m, kModelSpecMembers); }
inline void load(Reader& r, ModelSpec& m) { loadMembers(r, m, kModelSpecMembers); }

inline constexpr auto kTraceMembers =
    std::make_tuple(&Trace::t, &Trace::x, &Trace::y, &Trace::yaw, &Trace::v, &Trace::w, &Trace::accel,
                    &Trace::speed_left, &Trace::speed_right, &Trace::torque_left, &Trace::torque_right, &Trace::pitch,
                    &Trace::roll, &Trace::cmd_left, &Trace::cmd_right, &Trace::contact);
inline void save(Writer& w, const Trace& t) { saveMembers(w, t, kTraceMembers); }
inline void load(Reader& r, Trace& t) { loadMembers(r, t, kTraceMembers); }

inline constexpr auto kRunPredictionMembers =
    std::make_tuple(&RunPrediction::values, &RunPrediction::features, &RunPrediction::surface, &RunPrediction::trace,
                    &RunPrediction::alignment, &RunPrediction::notes);
inline void save(Writer& w, const RunPrediction& p) { saveMembers(w, p, kRunPredictionMembers); }
inline void load(Reader& r, RunPrediction& p) { loadMembers(r, p, kRunPredictionMembers); }

inline constexpr auto kRunResidualsMembers =
    std::make_tuple(&RunResiduals::run, &RunResiduals::channels, &RunResiduals::chan, &RunResiduals::t,
                    &RunResiduals::r, &RunResiduals::raw, &RunResiduals::valid, &RunResiduals::rss, &RunResiduals::n,
                    &RunResiduals::prediction);
inline void save(Writer& w, const RunResiduals& x) { saveMembers(w, x, kRunResidualsMembers); }
inline void load(Reader& r, RunResiduals& x) { loadMembers(r, x, kRunResidualsMembers); }

inline void save(Writer& w, const Evaluation& e) { save(w, e.runs); }
inline void load(Reader& r, Evaluation& e) { load(r, e.runs); }

/// FitResult's members after the covariance matrix (free parameters and covariance are written by hand).
inline constexpr auto kFitResultSummaryMembers =
    std::make_tuple(&FitResult::rss, &FitResult::rss_start, &FitResult::n, &FitResult::rho1, &FitResult::iterations,
                    &FitResult::evaluations, &FitResult::converged, &FitResult::evaluation);

inline void save(Writer& w, const FitResult& f) {
  save(w, f.model);
  save<std::uint64_t>(w, f.free.size());
  for (const auto& p : f.free) {
    save(w, p.effect);
    save(w, p.name);
  }
  save(w, f.value);
  save(w, f.stderr_);
  save<std::int64_t>(w, f.covariance.rows());
  for (Eigen::Index i = 0; i < f.covariance.size(); ++i) save(w, f.covariance.data()[i]);
  saveMembers(w, f, kFitResultSummaryMembers);
}
inline void load(Reader& r, FitResult& f) {
  load(r, f.model);
  std::uint64_t k;
  load(r, k);
  f.free.resize(k);
  for (auto& p : f.free) {
    load(r, p.effect);
    load(r, p.name);
    const EffectInfo& info = EffectRegistry::instance().info(f.model.effects.at(p.effect).name);
    p.spec = *info.specFor(p.name);
    p.spec.name = p.name;
  }
  load(r, f.value);
  load(r, f.stderr_);
  std::int64_t n;
  load(r, n);
  f.covariance.resize(n, n);
  for (Eigen::Index i = 0; i < f.covariance.size(); ++i) load(r, f.covariance.data()[i]);
  loadMembers(r, f, kFitResultSummaryMembers);
}

}  // namespace sbot::calib
