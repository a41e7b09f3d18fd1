// GCC 12 warns "'result' may be used uninitialized" inside Eigen's triangular product, reached from
// the 3x3 LDLT solve below (a known false positive of Eigen 3.4 under -O2); nothing of ours is.
// Set before the includes: the warning is placed in Eigen's header.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "calibration/replay.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>

#include "calibration/parallel.h"
#include "calibration/sensor_bridge.h"
#include "sbot_sim/core/effects/drive_effects.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world.h"

namespace sbot::calib {
namespace {

/// Observes contacts: was the robot touching a static obstacle (anything but the floor) this step?
class ContactProbe : public Effect {
 public:
  std::string name() const override { return "contact_probe"; }
  void onContact(ContactContext& c, dSurfaceParameters&) override {
    const bool a_static = !c.robot_a, b_static = !c.robot_b;
    if ((c.robot_a && b_static && c.material_b != "ground") || (c.robot_b && a_static && c.material_a != "ground"))
      touching = true;
  }
  bool touching = false;
};

double interp(const std::vector<double>& v, double dt, double t) {
  if (v.empty()) return kNaN;
  const double q = t / dt;
  if (q <= 0) return v.front();
  const std::size_t k = static_cast<std::size_t>(q);
  if (k + 1 >= v.size()) return v.back();
  const double f = q - k;
  return (1 - f) * v[k] + f * v[k + 1];
}

/// Rigid planar corrections (dx, dy, dyaw) that best align the predicted pose samples with the
/// measured ones, one per segment of `segment` seconds (the whole run when segment <= 0), each about
/// the segment's first predicted position. The first segment's correction has the tracker noise as
/// its prior (the start pose was measured); later ones are free: the model is re-anchored every
/// segment, so a chaotic or drifting heading does not swamp the comparison (multiple shooting).
/// Returns the first segment's correction; the trace gets it too (open-loop overlay).
Pose2D alignSegments(const Run& run, RunPrediction& p, const NoiseModel& noise, double segment) {
  auto itx = run.channels.find("x"), ity = run.channels.find("y"), ityaw = run.channels.find("yaw");
  const bool hxy = itx != run.channels.end() && ity != run.channels.end() &&
                   itx->second.t.size() == ity->second.t.size() && !itx->second.t.empty();
  const bool hyaw = ityaw != run.channels.end() && !ityaw->second.t.empty();
  if (!hxy && !hyaw) return {};
  const double sp = noise.sigma("x", 0), sa = noise.sigma("yaw", 0);
  const double t_end = run.t_end + 1e-9;
  const int nseg = segment > 0 ? std::max(1, static_cast<int>(std::ceil(t_end / segment))) : 1;
  auto segOf = [&](double t) { return segment > 0 ? std::min(nseg - 1, static_cast<int>(t / segment)) : 0; };
  // Anchor of each segment: first predicted position sample in it (or the previous anchor).
  std::vector<Eigen::Vector2d> anchor(nseg, Eigen::Vector2d::Zero());
  std::vector<bool> has(nseg, false);
  std::vector<int> count(nseg, 0);
  if (hxy) {
    const auto& px = p.values.at("x");
    const auto& py = p.values.at("y");
    for (std::size_t i = 0; i < px.size(); ++i) {
      const int sgi = segOf(itx->second.t[i]);
      ++count[sgi];
      if (!has[sgi]) {
        anchor[sgi] = Eigen::Vector2d(px[i], py[i]);
        has[sgi] = true;
      }
    }
  }
  if (hyaw)
    for (double t : ityaw->second.t) ++count[segOf(t)];
  // Yaw is compared unwrapped: the measured series is unwrapped, and each segment's prediction is
  // shifted by whole turns to start within half a turn of the measurement, so a model that turns
  // too little gives a growing (not a saw-tooth) residual.
  std::vector<double> yaw_meas;
  std::vector<double> turns(nseg, 0.0);
  if (hyaw) {
    yaw_meas = unwrapped(ityaw->second);
    const auto& pa = p.values.at("yaw");
    std::vector<bool> seen(nseg, false);
    for (std::size_t i = 0; i < pa.size(); ++i) {
      const int sgi = segOf(ityaw->second.t[i]);
      if (seen[sgi] || !std::isfinite(pa[i])) continue;
      seen[sgi] = true;
      turns[sgi] = 2 * M_PI * std::round((pa[i] - yaw_meas[i]) / (2 * M_PI));
    }
  }
  std::vector<Eigen::Vector3d> corr(nseg, Eigen::Vector3d::Zero());
  for (int sgi = 0; sgi < nseg; ++sgi) {
    if (count[sgi] == 0) continue;
    Eigen::Vector3d a = Eigen::Vector3d::Zero();
    const Eigen::Vector2d c0 = anchor[sgi];
    for (int iter = 0; iter < 3; ++iter) {
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      const Eigen::Vector3d prior_sigma = sgi == 0 ? Eigen::Vector3d(sp, sp, sa) : Eigen::Vector3d(1.0, 1.0, 1.0);
      for (int q = 0; q < 3; ++q) {
        H(q, q) += 1 / (prior_sigma(q) * prior_sigma(q));
        g(q) += a(q) / (prior_sigma(q) * prior_sigma(q));
      }
      const double c = std::cos(a(2)), s = std::sin(a(2));
      if (hxy) {
        const auto& px = p.values.at("x");
        const auto& py = p.values.at("y");
        for (std::size_t i = 0; i < px.size(); ++i) {
          if (segOf(itx->second.t[i]) != sgi || !std::isfinite(px[i])) continue;
          const double rx = px[i] - c0.x(), ry = py[i] - c0.y();
          const double X = c0.x() + a(0) + c * rx - s * ry, Y = c0.y() + a(1) + s * rx + c * ry;
          const double ex = X - itx->second.v[i], ey = Y - ity->second.v[i];
          const Eigen::Vector3d jx(1, 0, -s * rx - c * ry), jy(0, 1, c * rx - s * ry);
          H += (jx * jx.transpose() + jy * jy.transpose()) / (sp * sp);
          g += (jx * ex + jy * ey) / (sp * sp);
        }
      }
      if (hyaw) {
        const auto& pa = p.values.at("yaw");
        for (std::size_t i = 0; i < pa.size(); ++i) {
          if (segOf(ityaw->second.t[i]) != sgi || !std::isfinite(pa[i])) continue;
          H(2, 2) += 1 / (sa * sa);
          g(2) += (pa[i] + a(2) - yaw_meas[i] - turns[sgi]) / (sa * sa);
        }
      }
      const Eigen::Vector3d step = H.ldlt().solve(-g);
      a += step;
      if (step.norm() < 1e-10) break;
    }
    corr[sgi] = a;
  }
  auto apply = [&](double t, double& x, double& y) {
    const int sgi = segOf(t);
    const Eigen::Vector3d& a = corr[sgi];
    const Eigen::Vector2d c0 = anchor[sgi];
    const double c = std::cos(a(2)), s = std::sin(a(2));
    const double rx = x - c0.x(), ry = y - c0.y();
    x = c0.x() + a(0) + c * rx - s * ry;
    y = c0.y() + a(1) + s * rx + c * ry;
  };
  if (hxy) {
    auto& px = p.values["x"];
    auto& py = p.values["y"];
    for (std::size_t i = 0; i < px.size(); ++i) apply(itx->second.t[i], px[i], py[i]);
  }
  if (hyaw) {
    auto& pa = p.values["yaw"];
    for (std::size_t i = 0; i < pa.size(); ++i) {
      const int sgi = segOf(ityaw->second.t[i]);
      pa[i] += corr[sgi](2) - turns[sgi];
    }
  }
  // The open-loop trace (plots) gets the first segment's correction only.
  if (!p.trace.x.empty()) {
    const Eigen::Vector3d& a = corr[0];
    const Eigen::Vector2d c0 = anchor[0];
    const double c = std::cos(a(2)), s = std::sin(a(2));
    for (std::size_t i = 0; i < p.trace.x.size(); ++i) {
      const double rx = p.trace.x[i] - c0.x(), ry = p.trace.y[i] - c0.y();
      p.trace.x[i] = c0.x() + a(0) + c * rx - s * ry;
      p.trace.y[i] = c0.y() + a(1) + s * rx + c * ry;
      p.trace.yaw[i] += a(2);
    }
  }
  return {corr[0](0), corr[0](1), corr[0](2)};
}

/// The channels a drive replay records besides the pose: those the run measures, all with keep_trace.
struct NeededChannels {
  bool speed = false, torque = false, tilt = false;
  std::vector<std::string> sensors;  ///< ir*, ground*, light*
};
NeededChannels neededChannels(const Run& run, const ReplayOptions& opt) {
  NeededChannels need;
  for (const auto& [c, s] : run.channels) {
    const std::string g = NoiseModel::group(c);
    need.speed |= g == "speed";
    need.torque |= g == "torque";
    need.tilt |= g == "tilt";
    if (g == "ir" || g == "ground" || g == "light") need.sensors.push_back(c);
  }
  need.speed |= opt.keep_trace;
  need.torque |= opt.keep_trace;
  need.tilt |= opt.keep_trace;
  return need;
}

/// Appends the robot's state after each step to a Trace.
struct TraceRecorder {
  Robot& robot;
  const ReplayOptions& opt;
  const ContactProbe& probe;
  const NeededChannels& need;
  double su, tu;  ///< the level's API speed and torque units
  Trace tr;
  double last_yaw = 0, unwrap = 0;

  TraceRecorder(Robot& robot, const ReplayOptions& opt, const ContactProbe& probe, const NeededChannels& need,
                const RobotDescription& d, int n)
      : robot(robot), opt(opt), probe(probe), need(need), su(d.treels.speed_unit), tu(d.treels.torque_unit) {
    for (auto* v : {&tr.t, &tr.x, &tr.y, &tr.yaw, &tr.v, &tr.w, &tr.speed_left, &tr.speed_right, &tr.torque_left,
                    &tr.torque_right, &tr.pitch, &tr.roll, &tr.cmd_left, &tr.cmd_right})
      v->reserve(n + 1);
  }

  void record(double t, double cl, double cr) {
    const Pose p = robot.basePose();
    const Vec3 rpy = rpyFromQuat(p.orientation);
    // Inclinometer: attitude against the true vertical (gravity), which differs from world z only
    // when the hidden truth tilts gravity. Heading stays the world yaw (overhead tracker).
    Vec3 tilt_rpy = rpy;
    if (opt.tilt != 0) {
      const Vec3 up(-std::sin(opt.tilt) * std::cos(opt.tilt_direction), -std::sin(opt.tilt) * std::sin(opt.tilt_direction),
                    std::cos(opt.tilt));
      const Quat level = Quat::FromTwoVectors(up, Vec3::UnitZ());  // true vertical -> z
      tilt_rpy = rpyFromQuat(level * p.orientation);
    }
    double yaw = rpy.z();
    if (!tr.yaw.empty()) {
      unwrap += wrapAngle(yaw - last_yaw) - (yaw - last_yaw);
    }
    last_yaw = yaw;
    tr.t.push_back(t);
    tr.x.push_back(p.position.x());
    tr.y.push_back(p.position.y());
    tr.yaw.push_back(yaw + unwrap);
    const Vec3 lv = robot.linearVelocity();
    const Vec3 fwd = p.orientation * Vec3::UnitX();
    tr.v.push_back(lv.dot(fwd));
    tr.w.push_back(robot.angularVelocity().z());
    tr.cmd_left.push_back(cl);
    tr.cmd_right.push_back(cr);
    tr.contact.push_back(probe.touching ? 1 : 0);
    if (need.tilt) {
      tr.pitch.push_back(tilt_rpy.y());
      tr.roll.push_back(tilt_rpy.x());
    }
    if (need.speed) {
      tr.speed_left.push_back(robot.encoderSpeed(0) / su);
      tr.speed_right.push_back(robot.encoderSpeed(1) / su);
    }
    if (need.torque) {
      tr.torque_left.push_back(robot.trackTorqueLeft() / tu);
      tr.torque_right.push_back(robot.trackTorqueRight() / tu);
    }
  }
};

/// The sensor channels' samples, each computed at the step nearest to its requested time stamp.
struct SensorSampler {
  SensorBridge bridge;
  std::map<int, std::vector<std::pair<std::string, std::size_t>>> due;  ///< step -> (channel, sample)
  std::map<std::string, std::vector<double>> values;
  std::map<std::string, std::map<std::string, std::vector<double>>> features;
  std::map<std::string, std::vector<std::string>> surface;
  std::set<std::string> absent;  ///< channels the level has no sensor for

  SensorSampler(World& world, Robot& robot, const Dataset& ds, const Run& run, const std::vector<std::string>& channels,
                int n, double dt, std::vector<std::string>& notes)
      : bridge(world, robot, ds) {
    for (const auto& c : channels) {
      const Series& s = run.channels.at(c);
      values[c].assign(s.t.size(), kNaN);
      features[c]["distance"].assign(s.t.size(), kNaN);
      features[c]["incidence"].assign(s.t.size(), kNaN);
      surface[c].assign(s.t.size(), "");
    }
    if (bridge.available()) {
      for (const auto& c : channels) {
        const Series& s = run.channels.at(c);
        for (std::size_t i = 0; i < s.t.size(); ++i)
          due[std::max(0, std::min(n, static_cast<int>(std::lround(s.t[i] / dt))))].push_back({c, i});
      }
    } else if (!channels.empty()) {
      notes.push_back("sensor channels not simulated: " + bridge.whyUnavailable());
    }
  }

  void sample(int k) {
    auto it = due.find(k);
    if (it == due.end()) return;
    for (const auto& [c, i] : it->second) {
      SensorReading rd = bridge.read(c);
      if (std::isnan(rd.value)) absent.insert(c);
      values[c][i] = rd.value;
      features[c]["distance"][i] = rd.distance;
      features[c]["incidence"][i] = rd.incidence;
      surface[c][i] = rd.surface;
    }
  }
};

/// The predictions at the measurement times, with the features the diagnosis regresses on.
void predictAtSamples(const Run& run, const Trace& tr, double dt, SensorSampler& sensors, RunPrediction& out) {
  for (const auto& [c, s] : run.channels) {
    const std::vector<double>* src = nullptr;
    if (c == "x") src = &tr.x;
    else if (c == "y") src = &tr.y;
    else if (c == "yaw") src = &tr.yaw;
    else if (c == "speed_left") src = &tr.speed_left;
    else if (c == "speed_right") src = &tr.speed_right;
    else if (c == "torque_left") src = &tr.torque_left;
    else if (c == "torque_right") src = &tr.torque_right;
    else if (c == "pitch") src = &tr.pitch;
    else if (c == "roll") src = &tr.roll;
    std::vector<double> vals(s.t.size(), kNaN);
    if (src) {
      for (std::size_t i = 0; i < s.t.size(); ++i) vals[i] = interp(*src, dt, s.t[i]);
    } else if (sensors.values.count(c)) {
      vals = sensors.values[c];
      out.features[c] = sensors.features[c];
      out.surface[c] = sensors.surface[c];
    }
    out.values[c] = std::move(vals);
    auto& f = out.features[c];
    f["v"].resize(s.t.size());
    f["w"].resize(s.t.size());
    f["accel"].resize(s.t.size());
    f["contact"].resize(s.t.size());
    f["yaw"].resize(s.t.size());
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      f["yaw"][i] = interp(tr.yaw, dt, s.t[i]);
      f["v"][i] = interp(tr.v, dt, s.t[i]);
      f["w"][i] = interp(tr.w, dt, s.t[i]);
      f["accel"][i] = interp(tr.accel, dt, s.t[i]);
      const std::size_t k = std::min(tr.contact.size() - 1, static_cast<std::size_t>(std::lround(s.t[i] / dt)));
      f["contact"][i] = tr.contact[k];
    }
  }
}

RunPrediction replayDrive(World& world, const RobotDescription& d, const Dataset& ds, const Run& run,
                          const Pose2D& start, const ReplayOptions& opt, ContactProbe& probe) {
  RunPrediction out;
  Robot& robot = world.addRobot(d, start, "sbot_0");
  const double dt = world.config().step;
  const int settle = static_cast<int>(std::round(opt.settle / dt));
  robot.setTrackSpeeds(0, 0);
  world.stepN(settle);
  for (const auto& e : world.effects()) {
    e->reset();
    if (auto* sag = dynamic_cast<BatterySagEffect*>(e.get())) sag->setElapsed(robot.name(), run.start_time);
  }

  const NeededChannels need = neededChannels(run, opt);
  const double su = d.treels.speed_unit;
  const int n = static_cast<int>(std::ceil(run.t_end / dt - 1e-9)) + 1;
  TraceRecorder rec(robot, opt, probe, need, d, n);
  SensorSampler sensors(world, robot, ds, run, need.sensors, n, dt, out.notes);

  auto c0 = run.commandAt(0);
  probe.touching = false;
  rec.record(0, c0.first, c0.second);
  sensors.sample(0);
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    const auto c = run.commandAt(t);
    if (run.passiveAt(t)) {
      robot.setTracksPassive(true);
    } else {
      robot.setTrackSpeeds(c.first * su, c.second * su);
    }
    const auto force = run.forceAt(t);
    if (force.first != 0 || force.second != 0) robot.addBaseForce(Vec3(force.first, force.second, 0));
    probe.touching = false;
    world.step();
    rec.record((k + 1) * dt, c.first, c.second);
    sensors.sample(k + 1);
  }
  for (const auto& c : sensors.absent) out.notes.push_back(c + " not simulated: level " + d.level + " has no such sensor");
  Trace& tr = rec.tr;
  // acceleration by central differences of v
  tr.accel.assign(tr.v.size(), 0);
  for (std::size_t i = 1; i + 1 < tr.v.size(); ++i) tr.accel[i] = (tr.v[i + 1] - tr.v[i - 1]) / (2 * dt);

  predictAtSamples(run, tr, dt, sensors, out);
  if (opt.keep_trace) out.trace = std::move(tr);
  if (opt.align && ds.align_initial_pose) out.alignment = alignSegments(run, out, ds.noise, ds.align_segment);
  return out;
}

/// The robot settled once on an open floor far from everything, and the resting height of its
/// base_link there.
std::pair<Robot*, double> settledFarAway(World& world, const RobotDescription& d) {
  Robot& robot = world.addRobot(d, {1000.0, 1000.0, 0.0}, "sbot_0");
  world.stepN(30);
  return {&robot, robot.basePose().position.z() - world.terrainHeight(1000.0, 1000.0)};
}

/// Where a placement puts base_link: `z` above the terrain, or resting (rest_z) when not given.
Pose placedPose(const World& world, const Pose2D& pose, double z, double rest_z) {
  const double ground = world.terrainHeight(pose.x, pose.y);
  return Pose(Vec3(pose.x, pose.y, ground + (std::isnan(z) ? rest_z : z)), quatFromRPY(0, 0, pose.yaw));
}

RunPrediction replayPlace(World& world, const RobotDescription& d, const Dataset& ds, const Run& run,
                          const ReplayOptions&) {
  RunPrediction out;
  const auto [robot_ptr, rest_z] = settledFarAway(world, d);
  Robot& robot = *robot_ptr;
  SensorBridge bridge(world, robot, ds);
  for (const auto& [c, s] : run.channels) {
    out.values[c].assign(s.t.size(), kNaN);
    out.features[c]["distance"].assign(s.t.size(), kNaN);
    out.features[c]["incidence"].assign(s.t.size(), kNaN);
    out.surface[c].assign(s.t.size(), "");
  }
  if (!bridge.available()) {
    out.notes.push_back("sensor channels not simulated: " + bridge.whyUnavailable());
    return out;
  }
  std::set<std::string> absent;
  for (std::size_t row = 0; row < run.placements.size(); ++row) {
    const Placement& pl = run.placements[row];
    robot.setBasePose(placedPose(world, pl.pose, pl.z, rest_z));
    bridge.placed();
    for (const auto& [c, s] : run.channels) {
      for (std::size_t i = 0; i < s.t.size(); ++i) {
        if (static_cast<std::size_t>(s.t[i]) != row) continue;
        SensorReading rd = bridge.read(c);
        if (std::isnan(rd.value)) absent.insert(c);
        out.values[c][i] = rd.value;
        out.features[c]["distance"][i] = rd.distance;
        out.features[c]["incidence"][i] = rd.incidence;
        out.surface[c][i] = rd.surface;
      }
    }
  }
  for (const auto& c : absent) out.notes.push_back(c + " not simulated: level " + d.level + " has no such sensor");
  return out;
}

}  // namespace

namespace {
std::atomic<long> g_replays{0};

/// True when the run measures sensors whose readings depend on where the robot is (IR, ground, light).
bool readsTheWorld(const Run& run) {
  for (const auto& [c, s] : run.channels) {
    const std::string g = NoiseModel::group(c);
    if (g == "ir" || g == "ground" || g == "light") return true;
  }
  return false;
}
}  // namespace

long replayCount() { return WorkerPool::counted(); }

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

std::string ModelSpec::describe() const {
  if (effects.empty()) return "nominal model";
  std::ostringstream o;
  for (std::size_t i = 0; i < effects.size(); ++i) {
    o << (i ? " + " : "") << effects[i].name << "(";
    bool first = true;
    for (const auto& [k, v] : effects[i].params) {
      o << (first ? "" : ", ") << k << "=" << v;
      first = false;
    }
    o << ")";
  }
  return o.str();
}

bool canSimulateChannel(const std::string& channel) {
  const std::string g = NoiseModel::group(channel);
  if (g == "ir" || g == "ground" || g == "light") return SensorBridge::supports(g);
  return true;
}

double levelTrackWidth(const std::string& level) {
  static std::mutex mutex;
  static std::map<std::string, double> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(level);
  if (it != cache.end()) return it->second;
  const RobotDescription& d = loadLevel(level);
  WorldConfig c;
  World w(c);
  const double width = trackWidthOf(w.addRobot(d, {0, 0, 0}, "probe"));
  cache[level] = width;
  return width;
}

std::vector<std::pair<Vec3, double>> levelIrSensors(const std::string& level) {
  const RobotDescription& d = loadLevel(level);
  WorldConfig c;
  World w(c);
  Robot& r = w.addRobot(d, {0, 0, 0}, "probe");
  const Pose inv = r.basePose().inverse();
  std::vector<std::pair<Vec3, double>> out;
  for (int k = 0; k < 15; ++k) {
    const std::string link = "ir_" + std::to_string(k);
    if (!r.hasLink(link)) break;
    const Pose p = inv * r.linkPose(link);
    const Vec3 axis = p.orientation * Vec3::UnitX();
    out.push_back({p.position, std::atan2(axis.y(), axis.x())});
  }
  return out;
}

WorldConfig replayWorldConfig(const Dataset& ds, const RobotDescription& level, const ReplayOptions& opt) {
  WorldConfig wc = opt.world_override ? *opt.world_override : ds.world;
  if (!ds.world_sets_step) wc.step = level.recommended_step;
  if (!ds.world_sets_gravity) wc.gravity = level.gravity;
  return wc;
}

std::string impossiblePlacement(const Dataset& ds, const std::string& level) {
  const RobotDescription& d = loadLevel(level.empty() ? ds.robot : level);
  World world(replayWorldConfig(ds, d, ReplayOptions()));
  const auto [robot, rest_z] = settledFarAway(world, d);
  // A drive run's robot stands on the terrain, so it is set along the ground's local slope (a start
  // on a 20 deg ramp set level sat 1.5 cm inside it); a placement is replayed level, as placed.
  auto onTheSlope = [&](const Pose2D& pose) {
    constexpr double kHalfBase = 0.03;  // [m] finite-difference half base for the ground's gradient
    auto h = [&](double dx, double dy) { return world.terrainHeight(pose.x + dx, pose.y + dy); };
    const Vec3 normal = Vec3(-(h(kHalfBase, 0) - h(-kHalfBase, 0)), -(h(0, kHalfBase) - h(0, -kHalfBase)),
                             2 * kHalfBase).normalized();
    const Quat tilt = Quat::FromTwoVectors(Vec3::UnitZ(), normal);
    return Pose(Vec3(pose.x, pose.y, h(0, 0)) + normal * rest_z, tilt * quatFromRPY(0, 0, pose.yaw));
  };
  auto problemAt = [&](const Run& run, const std::string& which, const Pose2D& pose, double z) -> std::string {
    robot->setBasePose(run.kind == RunKind::Drive ? onTheSlope(pose) : placedPose(world, pose, z, rest_z));
    const World::Overlap o = world.deepestOverlap(*robot);
    if (o.depth <= World::kPlacementTolerance) return "";
    std::ostringstream why;
    why << run.path << ": run '" << run.name << "', " << which << " (x " << pose.x << " m, y " << pose.y << " m, yaw "
        << pose.yaw << " rad";
    if (!std::isnan(z)) why << ", z " << z << " m";
    why << "): a " << d.level << " s-bot there would sit " << o.depth << " m deep inside " << o.with << " (at most "
        << World::kPlacementTolerance << " m): no robot can have been measured there";
    return why.str();
  };
  for (const Run& run : ds.runs) {
    if (run.kind == RunKind::Drive) {
      if (std::string why = problemAt(run, "start pose", run.initial_pose, kNaN); !why.empty()) return why;
      continue;
    }
    for (std::size_t row = 0; row < run.placements.size(); ++row)
      if (std::string why = problemAt(run, "placement " + std::to_string(row + 1), run.placements[row].pose,
                                      run.placements[row].z);
          !why.empty())
        return why;
  }
  return "";
}

RunPrediction replayRun(const Dataset& ds, const Run& run, const ModelSpec& model, const ReplayOptions& opt) {
  const RobotDescription& d = loadLevel(model.level.empty() ? ds.robot : model.level);
  const WorldConfig wc = replayWorldConfig(ds, d, opt);
  auto simulate = [&](const Pose2D& start) {
    ++g_replays;
    WorkerPool::count();
    World world(wc);
    if (opt.tilt != 0) {
      const double g = wc.gravity;
      world.setGravity(Vec3(g * std::sin(opt.tilt) * std::cos(opt.tilt_direction),
                            g * std::sin(opt.tilt) * std::sin(opt.tilt_direction), -g * std::cos(opt.tilt)));
    }
    auto probe = std::make_shared<ContactProbe>();
    world.addEffect(probe);
    for (auto& e : makeEffects(model.effects, "<model>")) world.addEffect(e);
    if (run.kind == RunKind::Drive) return replayDrive(world, d, ds, run, start, opt, *probe);
    return replayPlace(world, d, ds, run, opt);
  };
  RunPrediction out = simulate(run.initial_pose);
  // The alignment moves the predicted poses onto the tracker's, but IR, ground and light sensors
  // read the world from where the simulated robot was: started from the measured (noisy) pose, a
  // robot approaching a wall reads it from the wrong distance, and as readings are convex in the
  // distance the noise biases them up (a fitted reflectance came out 9 % low). Such runs are
  // simulated once more from the aligned start.
  const Pose2D a = out.alignment;
  const bool moved = std::abs(a.x) + std::abs(a.y) > 1e-6 || std::abs(a.yaw) > 1e-6;
  if (run.kind == RunKind::Drive && moved && readsTheWorld(run)) {
    out = simulate({run.initial_pose.x + a.x, run.initial_pose.y + a.y, run.initial_pose.yaw + a.yaw});
    out.alignment = {a.x + out.alignment.x, a.y + out.alignment.y, a.yaw + out.alignment.yaw};
  }
  return out;
}

}  // namespace sbot::calib
