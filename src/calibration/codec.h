// save()/load() of the workbench's result types, for worker processes (parallel.h, serialize.h).
#pragma once

#include "calibration/evaluation.h"
#include "calibration/fit.h"
#include "calibration/serialize.h"
#include "sbot_sim/core/effects/effect_registry.h"

namespace sbot {

inline void save(calib::Writer& w, const Pose2D& p) {
  w.raw(p.x);
  w.raw(p.y);
  w.raw(p.yaw);
}
inline void load(calib::Reader& r, Pose2D& p) {
  r.raw(p.x);
  r.raw(p.y);
  r.raw(p.yaw);
}
inline void save(calib::Writer& w, const EffectConfig& c) {
  calib::save(w, c.name);
  calib::save(w, c.params);
  calib::save(w, c.stderr_);
  calib::save(w, c.note);
}
inline void load(calib::Reader& r, EffectConfig& c) {
  calib::load(r, c.name);
  calib::load(r, c.params);
  calib::load(r, c.stderr_);
  calib::load(r, c.note);
}

}  // namespace sbot

namespace sbot::calib {

inline void save(Writer& w, const ModelSpec& m) {
  save(w, m.level);
  save(w, m.effects);
}
inline void load(Reader& r, ModelSpec& m) {
  load(r, m.level);
  load(r, m.effects);
}

inline void save(Writer& w, const Trace& t) {
  for (const auto* v : {&t.t, &t.x, &t.y, &t.yaw, &t.v, &t.w, &t.accel, &t.speed_left, &t.speed_right, &t.torque_left,
                        &t.torque_right, &t.pitch, &t.roll, &t.cmd_left, &t.cmd_right})
    save(w, *v);
  save(w, t.contact);
}
inline void load(Reader& r, Trace& t) {
  for (auto* v : {&t.t, &t.x, &t.y, &t.yaw, &t.v, &t.w, &t.accel, &t.speed_left, &t.speed_right, &t.torque_left,
                  &t.torque_right, &t.pitch, &t.roll, &t.cmd_left, &t.cmd_right})
    load(r, *v);
  load(r, t.contact);
}

inline void save(Writer& w, const RunPrediction& p) {
  save(w, p.values);
  save(w, p.features);
  save(w, p.surface);
  save(w, p.trace);
  sbot::save(w, p.alignment);
  save(w, p.notes);
}
inline void load(Reader& r, RunPrediction& p) {
  load(r, p.values);
  load(r, p.features);
  load(r, p.surface);
  load(r, p.trace);
  sbot::load(r, p.alignment);
  load(r, p.notes);
}

inline void save(Writer& w, const RunResiduals& x) {
  save(w, x.run);
  save(w, x.channels);
  save(w, x.chan);
  save(w, x.t);
  save(w, x.r);
  save(w, x.raw);
  save(w, x.valid);
  save(w, x.rss);
  save(w, x.n);
  save(w, x.prediction);
}
inline void load(Reader& r, RunResiduals& x) {
  load(r, x.run);
  load(r, x.channels);
  load(r, x.chan);
  load(r, x.t);
  load(r, x.r);
  load(r, x.raw);
  load(r, x.valid);
  load(r, x.rss);
  load(r, x.n);
  load(r, x.prediction);
}

inline void save(Writer& w, const Evaluation& e) { save(w, e.runs); }
inline void load(Reader& r, Evaluation& e) { load(r, e.runs); }

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
  save(w, f.rss);
  save(w, f.rss_start);
  save(w, f.n);
  save(w, f.rho1);
  save(w, f.iterations);
  save(w, f.evaluations);
  save(w, f.converged);
  save(w, f.evaluation);
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
  load(r, f.rss);
  load(r, f.rss_start);
  load(r, f.n);
  load(r, f.rho1);
  load(r, f.iterations);
  load(r, f.evaluations);
  load(r, f.converged);
  load(r, f.evaluation);
}

}  // namespace sbot::calib
