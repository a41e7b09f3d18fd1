#include "sbot_sim/core/sensors/proximity.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot::sensors {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

std::vector<Vec3> IrRayModel::directions() const { return coneRays(rays, 0.5 * cone_angle, pattern_azimuth); }

IrRayModel proximityRayModel(const RobotDescription& d) {
  IrRayModel m;
  m.range_min = extraNumber(d, "ir_range_min_m", m.range_min);
  m.range_max = extraNumber(d, "ir_range_max_m", m.range_max);
  m.cone_angle = extraNumber(d, "ir_cone_angle_rad", m.cone_angle);
  m.rays = extraCount(d, "ir_rays", m.rays, 1, 1000);
  if (m.rays < 1 || !(m.range_max > m.range_min) || !(m.range_min > 0)) {
    throw ConfigError(d.sidecar_path, "extra/ir_*", "need ir_rays >= 1 and 0 < ir_range_min_m < ir_range_max_m");
  }
  return m;
}

LogLogResponse proximityResponse(const IrRayModel& model) {
  // sbot.h getProximitySensor: "20 is 15 cm, 50 is 5 cm, 1000 is 1 cm, 3700 is 0.5 cm. [0;8191]".
  return LogLogResponse({{0.005, 3700.0}, {0.01, 1000.0}, {0.05, 50.0}, {0.15, 20.0}}, model.range_min,
                        model.range_max, 8191.0);
}

namespace {

/// Appends the sensor's cone, turned into world directions, to `dirs`.
void appendWorldDirections(const Pose& sensor, const std::vector<Vec3>& directions, std::vector<Vec3>& dirs) {
  for (const Vec3& local : directions) dirs.push_back(sensor.orientation * local);
}

/// One bundle's n hits summarised: how many, their mean distance, the nearest and its incidence.
BundleHit summarise(const Vec3* dirs, const RayHit* hits, std::size_t n, double range_min) {
  BundleHit out;
  double sum = 0;
  double nearest = kInf;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& dir = dirs[i];
    const RayHit& h = hits[i];
    if (!h.hit) continue;
    const double d = std::max(h.distance, range_min);
    sum += d;
    ++out.hits;
    if (h.distance < nearest) {
      nearest = h.distance;
      out.nearest = h;
      out.incidence = std::acos(std::min(1.0, std::abs(dir.normalized().dot(h.normal.normalized()))));
    }
  }
  out.mean_distance = out.hits > 0 ? sum / out.hits : kInf;
  return out;
}

}  // namespace

BundleHit traceBundle(const World& world, const Pose& sensor, const std::vector<Vec3>& directions,
                      double range_min, double range_max, const Robot* ignore) {
  std::vector<Vec3> dirs;
  dirs.reserve(directions.size());
  appendWorldDirections(sensor, directions, dirs);
  const std::vector<RayHit> hits = world.castRays(sensor.position, dirs, range_max, ignore);
  return summarise(dirs.data(), hits.data(), dirs.size(), range_min);
}

std::vector<BundleHit> traceBundles(const World& world, const std::vector<Pose>& sensors,
                                    const std::vector<Vec3>& directions, double range_min, double range_max,
                                    const Robot* ignore) {
  std::vector<Vec3> origins, dirs;  // bundle k: dirs[k n .. k n + n - 1], n = directions.size()
  origins.reserve(sensors.size());
  dirs.reserve(sensors.size() * directions.size());
  for (const Pose& p : sensors) {
    origins.push_back(p.position);
    appendWorldDirections(p, directions, dirs);
  }
  const std::vector<RayHit> hits = world.castRayBundles(origins, dirs, range_max, ignore);
  const std::size_t n = directions.size();
  std::vector<BundleHit> out;
  out.reserve(sensors.size());
  for (std::size_t k = 0; k < sensors.size(); ++k) out.push_back(summarise(&dirs[k * n], &hits[k * n], n, range_min));
  return out;
}

double turretRadius(const RobotDescription& d) {
  const LinkDescription* turret = d.findLink("turret");
  double r = 0;
  if (turret) {
    for (const auto& s : turret->collisions) {
      const Vec3& o = s.origin.position;
      switch (s.type) {
        case CollisionShape::Type::Sphere:
        case CollisionShape::Type::Cylinder:
          r = std::max(r, std::hypot(o.x(), o.y()) + s.radius);
          break;
        case CollisionShape::Type::Box:
          for (int sx : {-1, 1})
            for (int sy : {-1, 1})
              for (int sz : {-1, 1}) {
                const Vec3 c = s.origin.transform(
                    Vec3(sx * 0.5 * s.size.x(), sy * 0.5 * s.size.y(), sz * 0.5 * s.size.z()));
                r = std::max(r, std::hypot(c.x(), c.y()));
              }
          break;
      }
    }
  }
  return r > 0 ? r : 0.057;
}

// ---- look-up table ---------------------------------------------------------------------------------

double IrLookupTable::lookup(double gap, double bearing) const {
  if (gaps.size() < 2 || bearings.size() < 2) return 0.0;
  bearing = std::abs(bearing);
  if (!(gap <= gaps.back()) || !(bearing <= bearings.back())) return 0.0;
  gap = std::max(gap, gaps.front());
  bearing = std::max(bearing, bearings.front());
  auto cell = [](const std::vector<double>& axis, double v) {
    std::size_t i = std::upper_bound(axis.begin(), axis.end(), v) - axis.begin();
    i = std::min(std::max<std::size_t>(i, 1), axis.size() - 1) - 1;
    const double t = (v - axis[i]) / (axis[i + 1] - axis[i]);
    return std::make_pair(i, std::max(0.0, std::min(1.0, t)));
  };
  const auto [i, u] = cell(gaps, gap);
  const auto [j, v] = cell(bearings, bearing);
  const double a = readings[i][j] * (1 - v) + readings[i][j + 1] * v;
  const double b = readings[i + 1][j] * (1 - v) + readings[i + 1][j + 1] * v;
  return a * (1 - u) + b * u;
}

void IrLookupTable::save(const std::string& path) const {
  OutputFile f(path);
  f << std::setprecision(10);
  f << "# ir_lut.yaml -- GENERATED sample-based IR proximity table (seed 2.2.6 item 1), used by the\n"
       "# Fast and Simple levels (sidecar extra ir_model: lut). Do not edit by hand. Regenerate with\n"
       "#   SBOT_WRITE_IR_LUT=1 build/ws/devel/lib/sbot_sim/core_test_sensor_ir_lut\n"
       "# (sbot_sim/test/core/test_sensor_ir_lut.cpp; without the variable that test checks that this\n"
       "# file still matches the generator and the current URDF).\n"
       "#\n"
       "# readings[i][j]: noise-free IR reading [API units, 0..8191] of one proximity sensor when a\n"
       "# neighbouring s-bot (level `target_level`, turret radius `target_radius_m`) has its turret\n"
       "# axis at horizontal gap gaps_m[i] (distance sensor->axis minus the turret radius) and at\n"
       "# bearing bearings_rad[j] (|angle from the sensor's +x|). Sampled with the ray-traced model\n"
       "# (5 rays, 30 deg cone, 0.2-20 cm, piecewise log-log response through the sbot.h points)\n"
       "# against the neighbour alone (no floor, no walls), averaged over `target_yaws` headings.\n"
       "# The simulator interpolates bilinearly and adds the 10 % distance noise at run time.\n";
  f << "format_version: 1\n";
  f << "target_level: " << target_level << "\n";
  f << "target_radius_m: " << target_radius << "\n";
  f << "sensor_height_m: " << sensor_height << "\n";
  f << "target_yaws: " << target_yaws << "\n";
  f << "ray_model: {rays: " << model.rays << ", cone_angle_rad: " << model.cone_angle
    << ", range_min_m: " << model.range_min << ", range_max_m: " << model.range_max
    << ", pattern_azimuth_rad: " << model.pattern_azimuth << "}\n";
  auto list = [&f](const std::vector<double>& v, int precision) {
    f << "[";
    for (std::size_t i = 0; i < v.size(); ++i) {
      f << (i ? ", " : "") << std::fixed << std::setprecision(precision) << v[i];
    }
    f << "]";
    f.unsetf(std::ios::fixed);
  };
  f << "gaps_m: ";
  list(gaps, 4);
  f << "\nbearings_rad: ";
  list(bearings, 6);
  f << "\nreadings:\n";
  for (const auto& row : readings) {
    f << "  - ";
    list(row, 2);
    f << "\n";
  }
  f.commit();
}

IrLookupTable IrLookupTable::load(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(readInputFile(path, "IR look-up table"));
  } catch (const std::exception& e) {
    throw ConfigError(path, "", std::string("cannot read the IR look-up table: ") + e.what());
  }
  IrLookupTable t;
  auto need = [&](const char* key) {
    if (!root[key]) throw ConfigError(path, key, "missing");
    return root[key];
  };
  try {
    t.target_level = need("target_level").as<std::string>();
    t.target_radius = need("target_radius_m").as<double>();
    t.sensor_height = root["sensor_height_m"] ? root["sensor_height_m"].as<double>() : 0.0;
    t.target_yaws = root["target_yaws"] ? root["target_yaws"].as<int>() : 0;
    if (const YAML::Node m = root["ray_model"]) {
      t.model.rays = m["rays"].as<int>(t.model.rays);
      t.model.cone_angle = m["cone_angle_rad"].as<double>(t.model.cone_angle);
      t.model.range_min = m["range_min_m"].as<double>(t.model.range_min);
      t.model.range_max = m["range_max_m"].as<double>(t.model.range_max);
      t.model.pattern_azimuth = m["pattern_azimuth_rad"].as<double>(t.model.pattern_azimuth);
    }
    t.gaps = need("gaps_m").as<std::vector<double>>();
    t.bearings = need("bearings_rad").as<std::vector<double>>();
    t.readings = need("readings").as<std::vector<std::vector<double>>>();
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "", std::string("malformed IR look-up table: ") + e.what());
  }
  if (t.gaps.size() < 2 || t.bearings.size() < 2) throw ConfigError(path, "gaps_m/bearings_rad", "need >= 2 values each");
  for (std::size_t i = 1; i < t.gaps.size(); ++i)
    if (!(t.gaps[i] > t.gaps[i - 1])) throw ConfigError(path, "gaps_m", "must increase");
  for (std::size_t i = 1; i < t.bearings.size(); ++i)
    if (!(t.bearings[i] > t.bearings[i - 1])) throw ConfigError(path, "bearings_rad", "must increase");
  if (t.readings.size() != t.gaps.size()) throw ConfigError(path, "readings", "need one row per gap");
  for (const auto& row : t.readings)
    if (row.size() != t.bearings.size()) throw ConfigError(path, "readings", "need one column per bearing");
  return t;
}

std::vector<double> defaultLutGaps() {
  std::vector<double> g;
  // First row 1 mm (closer, even touching, reads as 1 mm: a ray starting on the neighbour's surface
  // is ill-defined); last row 20 cm, beyond which the 20 cm rays cannot reach the neighbour.
  for (double mm : {1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 14.0, 17.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0,
                    50.0, 60.0, 70.0, 80.0, 90.0, 100.0, 110.0, 120.0, 130.0, 140.0, 150.0, 160.0, 170.0, 180.0,
                    190.0, 195.0, 199.0, 200.0}) {
    g.push_back(mm * 1e-3);
  }
  return g;
}

std::vector<double> defaultLutBearings() {
  std::vector<double> b;
  for (int k = 0; k <= 36; ++k) b.push_back(k * 2.5 * M_PI / 180.0);
  return b;
}

IrLookupTable generateIrLookupTable(const RobotDescription& target, const std::vector<double>& gaps,
                                    const std::vector<double>& bearings, int yaws, const IrRayModel& model) {
  WorldConfig config;
  config.terrain.ground_plane = false;  // "no walls, obstacles": only the neighbour is seen
  World world(config);
  Robot& t = world.addRobot(target, Pose2D{0, 0, 0}, "lut_target");
  const Pose rest = t.basePose();
  IrLookupTable lut;
  lut.gaps = gaps;
  lut.bearings = bearings;
  lut.target_level = target.level;
  lut.target_radius = turretRadius(target);
  lut.target_yaws = yaws;
  lut.model = model;
  // The sensing s-bot stands on the same ground: its IR sensors are at the target's own IR height.
  lut.sensor_height = t.hasLink("ir_0") ? t.linkPose("ir_0").position.z() : t.linkPose("turret").position.z();
  const std::vector<Vec3> dirs = model.directions();
  const LogLogResponse response = proximityResponse(model);
  lut.readings.assign(gaps.size(), std::vector<double>(bearings.size(), 0.0));
  for (int k = 0; k < yaws; ++k) {
    const double yaw = 2 * M_PI * k / yaws;
    t.setBasePose(Pose(rest.position, quatFromRPY(0, 0, yaw)));
    const Vec3 axis = t.hasLink("turret") ? t.linkPose("turret").position : t.basePose().position;
    for (std::size_t i = 0; i < gaps.size(); ++i) {
      for (std::size_t j = 0; j < bearings.size(); ++j) {
        const double r = lut.target_radius + gaps[i];
        // Sensor facing +x; the neighbour's axis at bearing b, distance r from it.
        const Vec3 sensor(axis.x() - r * std::cos(bearings[j]), axis.y() - r * std::sin(bearings[j]),
                          lut.sensor_height);
        const BundleHit hit =
            traceBundle(world, Pose(sensor, Quat::Identity()), dirs, model.range_min, model.range_max, nullptr);
        lut.readings[i][j] += response.reading(hit.mean_distance) / yaws;
      }
    }
  }
  return lut;
}

std::string defaultIrLookupTablePath() { return descriptionDirectory() + "/config/ir_lut.yaml"; }

const IrLookupTable& defaultIrLookupTable() {
  static std::mutex mutex;
  static std::unique_ptr<IrLookupTable> table;
  std::lock_guard<std::mutex> lock(mutex);
  if (!table) table = std::make_unique<IrLookupTable>(IrLookupTable::load(defaultIrLookupTablePath()));
  return *table;
}

// ---- ProximitySensors ------------------------------------------------------------------------------

ProximitySensors::ProximitySensors(World& world, Robot& robot, Model model, const IrLookupTable* lut)
    : world_(world),
      robot_(robot),
      model_(model),
      lut_(lut),
      ray_model_(proximityRayModel(robot.description())),
      directions_(ray_model_.directions()),
      response_(proximityResponse(ray_model_)),
      noise_(extraNumber(robot.description(), "ir_noise", 0.1)) {
  if (model_ == Model::LookupTable && !lut_) throw std::invalid_argument("IR look-up table model needs a table");
  for (int i = 0; i < kProximitySensors; ++i) {
    links_[i] = LinkRef("ir_" + std::to_string(i));
    if (!robot.hasLink(links_[i].name())) {
      throw ConfigError(robot.description().urdf_path, "link " + links_[i].name(), "missing (needed by the IR sensors)");
    }
  }
}

ProximitySensors::Raw ProximitySensors::raw(int sensor) const {
  if (sensor < 0 || sensor >= kProximitySensors) throw std::out_of_range("proximity sensor must be in [0,14]");
  if (model_ == Model::LookupTable) return rawLut(sensor);
  return rawOf(traceBundle(world_, robot_.linkPose(links_[sensor]), directions_, ray_model_.range_min,
                           ray_model_.range_max, &robot_));
}

ProximitySensors::Raw ProximitySensors::rawOf(const BundleHit& hit) {
  return Raw{hit.mean_distance, hit.hits ? hit.nearest.surface : std::string(), hit.incidence};
}

ProximitySensors::Raw ProximitySensors::rawLut(int sensor) const {
  const double reach = lut_->gaps.back();
  // A first cull on the base bodies' centres, before any link frame or turret size is looked up (by
  // name: that was most of a lone Simple robot's sensing time). Each robot's sensors and turret rim
  // lie within kRobotBound of its base body's centre, so a robot culled here is culled below too.
  constexpr double kRobotBound = 0.15;  // [m] > a 5.7 cm turret radius plus the body's offset from the axis
  const dReal* me = dBodyGetPosition(robot_.baseBody());
  const double cull = reach + 2 * kRobotBound;  // compared squared: the loop runs per sensor and robot
  bool pose_known = false;
  Pose pose, inv;
  double best = 0;
  for (Robot* other : world_.robots()) {
    if (other == &robot_) continue;
    const dReal* it = dBodyGetPosition(other->baseBody());
    const double dx = it[0] - me[0], dy = it[1] - me[1];
    if (dx * dx + dy * dy > cull * cull) continue;
    const double radius = turretRadius(other->description());
    if (!pose_known) {
      pose = robot_.linkPose(links_[sensor]);
      inv = pose.inverse();
      pose_known = true;
    }
    const Vec3 axis = other->hasLink("turret") ? other->linkPose("turret").position : other->basePose().position;
    if ((axis - pose.position).head<2>().norm() - radius > reach) continue;  // the sensor's own cull
    const Vec3 local = inv.transform(axis);
    const double gap = std::hypot(local.x(), local.y()) - radius;
    const double bearing = std::atan2(local.y(), local.x());
    best = std::max(best, lut_->lookup(gap, bearing));
  }
  if (best <= 0) return Raw{kInf, std::string(), 0.0};
  return Raw{response_.distance(best), "robot", 0.0};
}

double ProximitySensors::rawDistance(int sensor) const { return raw(sensor).distance; }

unsigned ProximitySensors::finish(int sensor, const Raw& r) {
  if (!std::isfinite(r.distance)) return 0;
  SensorSample s;
  s.channel = "ir";
  s.index = sensor;
  s.value = r.distance;
  s.surface = r.surface;
  s.incidence = r.incidence;
  double d = applyEffects(world_, robot_, s);
  if (std::isnan(d) || d == kInf) return 0;
  if (noise_ > 0) d *= 1.0 + robot_.random().uniform("ir", -noise_, noise_);
  const double v = response_.signal(d);
  return static_cast<unsigned>(std::lround(std::min(v, response_.maxReading())));
}

unsigned ProximitySensors::read(int sensor) { return finish(sensor, raw(sensor)); }

std::array<unsigned, kProximitySensors> ProximitySensors::readAll() {
  std::array<unsigned, kProximitySensors> out{};
  if (model_ == Model::LookupTable) {
    for (int i = 0; i < kProximitySensors; ++i) out[i] = read(i);
    return out;
  }
  // The whole ring with one search of the spaces (castRayBundles); the readings, and the order
  // of their noise draws, are those of read(0..14).
  std::vector<Pose> poses;
  poses.reserve(kProximitySensors);
  for (const auto& link : links_) poses.push_back(robot_.linkPose(link));
  const std::vector<BundleHit> hits =
      traceBundles(world_, poses, directions_, ray_model_.range_min, ray_model_.range_max, &robot_);
  for (int i = 0; i < kProximitySensors; ++i) out[i] = finish(i, rawOf(hits[i]));
  return out;
}

}  // namespace sbot::sensors
