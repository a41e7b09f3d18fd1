#include "calibration/generator.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "calibration/codec.h"
#include "calibration/replay.h"
#include "sbot_sim/core/random_streams.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot::calib {
namespace {

struct Pattern {
  std::string name;
  std::vector<std::pair<double, std::pair<double, double>>> cmds;  // (t, (left, right))
};

// Speed changes are ramped: at most kMaxStep units per track every kRampDt seconds. The core's
// treels react to a large instantaneous step with a heading jump that depends chaotically on the
// exact state (and the Medium model can tip over on a hard stop), which no experimenter would
// provoke on purpose; see docs/calibration.md "Experiment design".
constexpr double kMaxStep = 20, kRampDt = 0.2;

std::vector<std::pair<double, std::pair<double, double>>> ramped(
    const std::vector<std::pair<double, std::pair<double, double>>>& in) {
  std::vector<std::pair<double, std::pair<double, double>>> out;
  double l = 0, r = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    double t = in[i].first;
    const double tl = in[i].second.first, tr = in[i].second.second;
    const double t_next = i + 1 < in.size() ? in[i + 1].first : 1e9;
    while ((std::abs(tl - l) > 1e-9 || std::abs(tr - r) > 1e-9) && t < t_next - 1e-9) {
      l += std::max(-kMaxStep, std::min(kMaxStep, tl - l));
      r += std::max(-kMaxStep, std::min(kMaxStep, tr - r));
      out.push_back({t, {l, r}});
      t += kRampDt;
    }
    if (out.empty() || out.back().first < in[i].first - 1e-9) out.push_back({in[i].first, {l, r}});
  }
  return out;
}

// Commands of one drive experiment lasting `dur` seconds (the robot stops for the last second).
std::vector<Pattern> drivePatterns(const std::string& family, double dur, double track_width) {
  std::vector<Pattern> out;
  const double run_t = std::max(1.0, dur - 1.0);
  auto constant = [&](const std::string& name, double l, double r) {
    out.push_back({name, ramped({{0.0, {l, r}}, {run_t, {0, 0}}})});
  };
  if (family == "straight") {
    for (int s : {20, 40, 60}) constant("straight_" + std::to_string(s), s, s);
  } else if (family == "spin") {
    for (int s : {30, 60}) {
      constant("spin_cw_" + std::to_string(s), s, -s);
      constant("spin_ccw_" + std::to_string(s), -s, s);
    }
  } else if (family == "arc") {
    constant("arc_left", 30, 55);
    constant("arc_right", 55, 30);
  } else if (family == "square") {
    for (int dir : {+1, -1}) {
      std::vector<std::pair<double, std::pair<double, double>>> c;
      const double v = 40 * 0.0028;
      const double t90 = (M_PI / 2) / (2 * v / track_width);  // nominal spin time for 90 degrees
      double t = 0;
      while (t < run_t) {
        c.push_back({t, {40, 40}});  // side
        t += 1.5;
        if (t >= run_t) break;
        c.push_back({t, {0, 0}});  // stop (ramped down)
        t += 0.5;
        if (t >= run_t) break;
        c.push_back({t, {-dir * 40.0, dir * 40.0}});  // corner
        t += t90;
        if (t >= run_t) break;
        c.push_back({t, {0, 0}});
        t += 0.5;
      }
      c.push_back({run_t, {0, 0}});
      out.push_back({dir > 0 ? "square_ccw" : "square_cw", ramped(c)});
    }
  } else if (family == "steps") {
    std::vector<std::pair<double, std::pair<double, double>>> c;
    const double levels[] = {20, 40, 60, 40, 20, 0, -20, -40, -20, 0};
    double t = 0;
    for (int i = 0; t < run_t; ++i, t += 1.0) {
      const double s = levels[i % 10];
      c.push_back({t, {s, s}});
    }
    c.push_back({run_t, {0, 0}});
    out.push_back({"steps", ramped(c)});
  }
  return out;
}

// The IR calibration walls of the place and approach families: one per surface, 2 m long, far from
// the drive runs (which start within 1 m of the origin). Their face is at x = kWallX.
constexpr double kWallX = 30.0;
struct CalibrationWall {
  std::string surface;
  double y;  ///< [m] centre of the wall along it
};
const std::vector<CalibrationWall>& calibrationWalls() {
  static const std::vector<CalibrationWall> w{{"white_paper", -4.0}, {"grey_paper", 0.0}, {"black_card", 4.0}};
  return w;
}

std::vector<double> stamps(double t_end, double hz, double phase) {
  std::vector<double> t;
  for (double s = phase; s <= t_end + 1e-9; s += 1.0 / hz) t.push_back(s);
  return t;
}

// A drive run recorded `start_time` into the session: its commands, no channels yet.
Run driveRun(const std::string& name, const std::string& group,
             const std::vector<std::pair<double, std::pair<double, double>>>& cmds, double t_end, double start_time) {
  Run run;
  run.name = name;
  run.file = name + ".csv";
  run.kind = RunKind::Drive;
  run.group = group;
  for (const auto& [t, c] : cmds) {
    run.cmd_t.push_back(t);
    run.cmd_left.push_back(c.first);
    run.cmd_right.push_back(c.second);
  }
  run.t_end = t_end;
  run.start_time = start_time;
  return run;
}

// The time stamps of a measured channel at `hz`, with a random phase; values to be simulated.
void addChannel(Run& run, const std::string& channel, double hz, std::mt19937_64& rng) {
  Series s;
  s.t = stamps(run.t_end, hz, std::uniform_real_distribution<double>(0, 1)(rng) / hz);
  s.v.assign(s.t.size(), 0);
  s.line.assign(s.t.size(), 0);
  run.channels[channel] = s;
}

// The overhead tracker: x, y, yaw from one message.
void addTracker(Run& run, double hz, std::mt19937_64& rng) {
  addChannel(run, "x", hz, rng);
  run.channels["y"] = run.channels["x"];
  run.channels["yaw"] = run.channels["x"];
}

}  // namespace

const std::vector<std::string>& generatorFamilies() {
  static const std::vector<std::string> f{"straight", "spin", "arc", "square", "steps", "place", "approach"};
  return f;
}

void checkGeneratorOptions(const GeneratorOptions& opt) {
  auto fmtNumber = [](double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  };
  auto list = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
  };
  for (const auto& f : opt.experiments)
    if (std::find(generatorFamilies().begin(), generatorFamilies().end(), f) == generatorFamilies().end())
      throw std::invalid_argument("--families: unknown family '" + f + "' (known: " + list(generatorFamilies()) + ")");
  // A drive run drives for duration - 1 s and stands for the last second (drivePatterns); a dataset
  // refuses runs beyond an hour.
  if (!(opt.duration >= kMinDuration && opt.duration <= kMaxRunDuration))
    throw std::invalid_argument("--duration expects " + fmtNumber(kMinDuration) + " to " + fmtNumber(kMaxRunDuration) +
                                " s (each drive run drives for duration - 1 s, then stands for 1 s), got " +
                                fmtNumber(opt.duration));
  // An unnoticed floor slope: the s-bot is fully manoeuvrable up to 29 deg (seed Table 4.1, the
  // creep calibration in sbot_parameters.yaml); beyond, it creeps back or slides, and the downhill
  // direction is drawn at random, so a negative tilt says nothing more.
  if (!(opt.tilt_deg >= 0 && opt.tilt_deg <= kMaxTiltDeg))
    throw std::invalid_argument("--tilt expects a floor tilt from 0 to " + fmtNumber(kMaxTiltDeg) +
                                " deg (the s-bot drives freely up to ~29 deg; the downhill direction is random), got " +
                                fmtNumber(opt.tilt_deg));
  for (const char* f : {"place", "approach"}) {
    if (!opt.experiments.count(f)) continue;
    // Look-up-table levels see other s-bots, not walls (proximity.h): the walls' runs would be noise only.
    auto rayTraced = [](const std::string& level) { return loadLevel(level).extraOr("ir_model", "raytrace") == "raytrace"; };
    if (rayTraced(opt.level)) continue;
    std::vector<std::string> levels;
    for (const auto& l : modelLevels())
      if (rayTraced(l)) levels.push_back(l);
    throw std::invalid_argument("--families " + std::string(f) + " needs a level with ray-traced IR (" + list(levels) +
                                "); level '" + opt.level + "' reads IR from a look-up table of other s-bots that does not see walls");
  }
}

namespace {

/// The drive patterns of the chosen families, repeated, thinned to opt.max_runs.
std::vector<Pattern> drivePatternList(const GeneratorOptions& opt, const std::set<std::string>& families) {
  // Track width of the level, for nominal 90 degree turns of the square.
  const double width = levelTrackWidth(opt.level);
  std::vector<Pattern> patterns;
  for (int rep = 0; rep < std::max(1, opt.repeat); ++rep)
    for (const auto& f : generatorFamilies()) {
      if (!families.count(f) || f == "place" || f == "approach") continue;
      for (auto p : drivePatterns(f, opt.duration, width)) {
        if (opt.repeat > 1) p.name += "_r" + std::to_string(rep + 1);
        patterns.push_back(p);
      }
    }
  if (opt.max_runs > 0 && patterns.size() > opt.max_runs) {
    // Keep a spread of families: take every k-th pattern.
    std::vector<Pattern> keep;
    const double stride = static_cast<double>(patterns.size()) / opt.max_runs;
    for (std::size_t i = 0; i < opt.max_runs; ++i) keep.push_back(patterns[static_cast<std::size_t>(i * stride)]);
    patterns = keep;
  }
  return patterns;
}

/// The drive runs (commands, measurement time stamps, true start pose). The runs are recorded one
/// after the other in one session (battery time), with 20 s between runs to reposition the robot.
void addDriveRuns(const std::vector<Pattern>& patterns, const GeneratorOptions& opt, double& session, Dataset& ds) {
  std::vector<Pose2D> true_start(patterns.size());
  for (std::size_t i = 0; i < patterns.size(); ++i) {
    const Pattern& p = patterns[i];
    std::mt19937_64 rng(stableHash(opt.seed, "run/" + p.name));
    std::uniform_real_distribution<double> u01(0, 1);
    Run run = driveRun(p.name, p.name.substr(0, p.name.find('_')), p.cmds, opt.duration, session);
    session += opt.duration + 20.0;
    true_start[i] = {-1 + 2 * u01(rng), -1 + 2 * u01(rng), -M_PI + 2 * M_PI * u01(rng)};
    addTracker(run, opt.tracker_hz, rng);
    if (opt.measure_speed) {
      addChannel(run, "speed_left", opt.encoder_hz, rng);
      run.channels["speed_right"] = run.channels["speed_left"];
    }
    if (opt.measure_torque) {
      // Encoders and torques come in one message (sbot_msgs/TrackState): same time stamps.
      if (opt.measure_speed && opt.torque_hz == opt.encoder_hz) run.channels["torque_left"] = run.channels["speed_left"];
      else addChannel(run, "torque_left", opt.torque_hz, rng);
      run.channels["torque_right"] = run.channels["torque_left"];
    }
    if (opt.measure_tilt) {
      addChannel(run, "pitch", opt.tilt_hz, rng);
      run.channels["roll"] = run.channels["pitch"];
    }
    run.initial_pose = true_start[i];
    ds.runs.push_back(run);
  }
}

/// Static IR calibration ("place"): the robot placed in front of the three walls, sensors 2, 7 and
/// 12 facing the wall at 0-60 deg incidence and 1-16 cm.
void addPlaceRuns(const GeneratorOptions& opt, Dataset& ds) {
  const auto ir = levelIrSensors(opt.level);
  for (const auto& w : calibrationWalls()) {
    // One run per (surface, sensor), grouped by surface so that every fold sees every surface.
    constexpr double kClearance = 0.065;  // [m] robot outline around base_link (turret, treels corners)
    for (int k : {2, 7, 12}) {
      if (k >= static_cast<int>(ir.size())) continue;
      Run run;
      run.name = "place_" + w.surface + "_ir" + std::to_string(k);
      run.file = run.name + ".csv";
      run.kind = RunKind::Place;
      run.group = w.surface;
      const Vec3 pk = ir[k].first;
      for (double deg : {0.0, 20.0, 40.0, 60.0}) {
        const double th = deg * M_PI / 180;
        for (double dcm : {1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 16.0}) {
          const double d = dcm / 100;
          const double yaw = th - ir[k].second;  // sensor axis at angle th to the wall normal (+x)
          const double c = std::cos(yaw), sn = std::sin(yaw);
          const double sx = c * pk.x() - sn * pk.y(), sy = sn * pk.x() + c * pk.y();
          const double bx = kWallX - d * std::cos(th) - sx;
          const double by = w.y - d * std::sin(th) - sy;
          if (kWallX - bx < kClearance) continue;  // the robot would be inside the wall
          run.placements.push_back({{bx, by, yaw}, kNaN});
        }
      }
      for (int q = 0; q < static_cast<int>(ir.size()); ++q) {
        Series sr;
        for (std::size_t row = 0; row < run.placements.size(); ++row) {
          sr.t.push_back(static_cast<double>(row));
          sr.v.push_back(0);
          sr.line.push_back(0);
        }
        run.channels["ir" + std::to_string(q)] = sr;
      }
      run.t_end = static_cast<double>(run.placements.size());
      ds.runs.push_back(run);
    }
  }
}

/// IR wall approaches ("approach", drive runs): the robot reverses toward each wall at 2.8 cm/s with
/// its rear at 0, 20, 40 and 60 deg to the wall normal, from out of IR range until its centre is
/// 8 cm from the wall (the rear sensors then read from ~3 cm), the IR ring logged all the way.
void addApproachRuns(const GeneratorOptions& opt, double& session, Dataset& ds) {
  const std::size_t n_ir = levelIrSensors(opt.level).size();
  constexpr double kCommand = -10;   // [units] 2.8 cm/s backwards
  constexpr double kEndDistance = 0.08;  // [m] base_link to the wall face at the end
  const double run_t = std::max(1.0, opt.duration - 1.0);
  const double travel = std::abs(kCommand) * loadLevel(opt.level).treels.speed_unit * run_t;
  for (const auto& w : calibrationWalls()) {
    int j = 0;
    for (double deg : {0.0, 20.0, 40.0, 60.0}) {
      const double th = deg * M_PI / 180;  // direction of the rear, from the wall normal
      const std::string name = "approach_" + w.surface + "_" + std::to_string(static_cast<int>(deg));
      // Grouped by surface: every fold sees every surface.
      Run run = driveRun(name, "approach_" + w.surface, ramped({{0.0, {kCommand, kCommand}}, {run_t, {0, 0}}}),
                         opt.duration, session);
      session += opt.duration + 20.0;
      const double lane = -0.45 + 0.3 * j++;  // one lane of the wall per incidence
      run.initial_pose = {kWallX - kEndDistance - travel * std::cos(th),
                          w.y + lane - 0.5 * travel * std::sin(th), wrapAngle(th + M_PI)};
      std::mt19937_64 rng(stableHash(opt.seed, "run/" + run.name));
      addTracker(run, opt.tracker_hz, rng);
      addChannel(run, "ir0", opt.sensor_hz, rng);  // the whole ring in one message: same stamps
      for (std::size_t q = 1; q < n_ir; ++q) run.channels["ir" + std::to_string(q)] = run.channels["ir0"];
      ds.runs.push_back(run);
    }
  }
}

/// Simulates the "real" robot in `real` and fills every run's channels with its noisy measurements.
void measureRuns(const GeneratorOptions& opt, const WorldConfig& real, double tilt_dir, WorkerPool& pool, Dataset& ds) {
  ModelSpec truth_model{opt.level, opt.hidden};
  ReplayOptions ro;
  ro.align = false;
  ro.world_override = &real;
  ro.tilt = opt.tilt_deg * M_PI / 180;
  ro.tilt_direction = tilt_dir;
  const auto preds = pool.map<RunPrediction>(ds.runs.size(), [&](std::size_t i) {
    return replayRun(ds, ds.runs[i], truth_model, ro);
  });
  for (std::size_t i = 0; i < ds.runs.size(); ++i) {
    Run& run = ds.runs[i];
    const RunPrediction& p = preds[i];
    std::mt19937_64 rng(stableHash(opt.seed, "noise/" + run.name));
    std::normal_distribution<double> n01(0, 1);
    std::uniform_real_distribution<double> u01(0, 1);
    const auto& noise = opt.noise;
    for (auto& [c, s] : run.channels) {
      const auto& pred = p.values.at(c);
      for (std::size_t k = 0; k < s.v.size(); ++k) {
        const double truth_v = pred[k];
        double v = truth_v + noise.sigma(c, truth_v) * n01(rng);
        const std::string g = NoiseModel::group(c);
        if (c == "yaw") v = wrapAngle(v);
        if (g == "speed" || g == "torque") v = std::round(v);  // the API reports integers
        if ((g == "ir" || g == "ground") && u01(rng) < opt.ir_outlier_rate) v = truth_v * (3 + 5 * u01(rng));
        if (g == "ir" || g == "ground" || g == "light") v = std::max(0.0, std::round(v));
        s.v[k] = v;
      }
    }
    // The dataset's start pose is a tracker measurement.
    run.initial_pose.x += noise.sigma("x", 0) * n01(rng);
    run.initial_pose.y += noise.sigma("y", 0) * n01(rng);
    run.initial_pose.yaw = wrapAngle(run.initial_pose.yaw + noise.sigma("yaw", 0) * n01(rng));
  }
}

}  // namespace

Dataset generateDataset(const GeneratorOptions& opt, WorkerPool& pool, GeneratedTruth* truth) {
  Dataset ds;
  ds.name = opt.name;
  ds.robot = opt.level;
  ds.world.solver = opt.solver;
  ds.noise = opt.noise;
  ds.align_segment = opt.align_segment;
  ds.description = "synthetic dataset (sbot_calibrate generate, seed " + std::to_string(opt.seed) + ")";
  loadLevel(opt.level);  // fail early on an unknown level
  checkGeneratorOptions(opt);

  // The world the "real" robot drives in: the dataset's (flat) world, possibly tilted (gravity).
  WorldConfig real = ds.world;
  std::mt19937_64 world_rng(stableHash(opt.seed, "world"));
  const double tilt_dir = std::uniform_real_distribution<double>(-M_PI, M_PI)(world_rng);
  if (truth) {
    truth->hidden = opt.hidden;
    truth->world = real;
    truth->tilt_deg = opt.tilt_deg;
    truth->tilt_direction = tilt_dir;
  }

  std::set<std::string> families = opt.experiments;
  if (families.empty()) families = {"straight", "spin", "arc", "square", "steps"};
  double session = 0;
  addDriveRuns(drivePatternList(opt, families), opt, session, ds);
  if (families.count("place") || families.count("approach")) {
    for (const auto& w : calibrationWalls())
      ds.world.terrain.boxes.push_back({"wall_" + w.surface, Vec3(kWallX + 0.01, w.y, 0.05), Vec3(0.02, 2.0, 0.1), 0, 0,
                                        w.surface});
    real.terrain.boxes = ds.world.terrain.boxes;
    if (truth) truth->world = real;
  }
  if (families.count("place")) addPlaceRuns(opt, ds);
  if (families.count("approach")) addApproachRuns(opt, session, ds);
  measureRuns(opt, real, tilt_dir, pool, ds);
  return ds;
}

}  // namespace sbot::calib
