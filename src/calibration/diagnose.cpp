#include "calibration/diagnose.h"

#include "calibration/diagnose_internal.h"

#include <unistd.h>

#include <cstdlib>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <numeric>
#include <random>
#include <sstream>

#include "sbot_sim/core/random_streams.h"

namespace sbot::calib {

std::string detail::fmt(double v, int prec) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

namespace {

using detail::fmt;

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

}  // namespace sbot::calib
