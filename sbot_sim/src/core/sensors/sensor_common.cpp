#include "sbot_sim/core/sensors/sensor_common.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/world.h"

namespace sbot::sensors {

double extraNumber(const RobotDescription& d, const std::string& key, double fallback) {
  auto it = d.extra.find(key);
  if (it == d.extra.end()) return fallback;
  try {
    std::size_t used = 0;
    const double v = std::stod(it->second, &used);
    if (used != it->second.size() && it->second.find_first_not_of(" \t", used) != std::string::npos) {
      throw std::invalid_argument("trailing text");
    }
    if (!std::isfinite(v)) throw std::invalid_argument("not finite");
    return v;
  } catch (const std::exception&) {
    throw ConfigError(d.sidecar_path, "extra/" + key, "expected a finite number, got '" + it->second + "'");
  }
}

int extraCount(const RobotDescription& d, const std::string& key, int fallback, int lo, int hi) {
  const double v = extraNumber(d, key, fallback);
  if (v != std::floor(v) || v < lo || v > hi)
    throw ConfigError(d.sidecar_path, "extra/" + key,
                      "expected a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" +
                          d.extra.at(key) + "'");
  return static_cast<int>(v);
}

bool extraBool(const RobotDescription& d, const std::string& key, bool fallback) {
  auto it = d.extra.find(key);
  if (it == d.extra.end()) return fallback;
  std::string v = it->second;
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return std::tolower(c); });
  if (v == "true" || v == "1" || v == "yes" || v == "on") return true;
  if (v == "false" || v == "0" || v == "no" || v == "off") return false;
  throw ConfigError(d.sidecar_path, "extra/" + key, "expected true or false, got '" + it->second + "'");
}

double applyEffects(const World& world, const Robot& robot, SensorSample& sample) {
  for (const auto& e : world.effects()) e->onSensor(robot, sample);
  return sample.value;
}

// ---- LogLogResponse --------------------------------------------------------------------------------

LogLogResponse::LogLogResponse(std::vector<std::pair<double, double>> points, double range_min,
                               double range_max, double max_reading)
    : points_(std::move(points)), range_min_(range_min), range_max_(range_max), max_reading_(max_reading) {
  if (points_.size() < 2) throw std::invalid_argument("LogLogResponse needs at least two points");
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!(points_[i].first > 0) || !(points_[i].second > 0)) {
      throw std::invalid_argument("LogLogResponse points must be positive");
    }
    if (i > 0 && !(points_[i].first > points_[i - 1].first && points_[i].second < points_[i - 1].second)) {
      throw std::invalid_argument("LogLogResponse points must increase in distance, decrease in reading");
    }
  }
  if (!(range_min_ > 0) || !(range_max_ > range_min_) || !(max_reading_ > 0)) {
    throw std::invalid_argument("LogLogResponse: need 0 < range_min < range_max and max_reading > 0");
  }
}

double LogLogResponse::unclamped(double d) const {
  const double ld = std::log(d);
  // Segment: the first one whose far end lies beyond d (extrapolate with the end segments).
  std::size_t i = 0;
  while (i + 2 < points_.size() && d > points_[i + 1].first) ++i;
  const double x0 = std::log(points_[i].first), x1 = std::log(points_[i + 1].first);
  const double y0 = std::log(points_[i].second), y1 = std::log(points_[i + 1].second);
  const double slope = (y1 - y0) / (x1 - x0);
  return std::exp(y0 + slope * (ld - x0));
}

double LogLogResponse::reading(double distance) const {
  if (!std::isfinite(distance) || distance > range_max_) return 0.0;
  return signal(distance);
}

double LogLogResponse::signal(double distance) const {
  if (std::isnan(distance) || distance == std::numeric_limits<double>::infinity()) return 0.0;
  const double d = std::max(distance, range_min_);
  return std::min(max_reading_, std::max(0.0, unclamped(d)));
}

double LogLogResponse::distance(double reading) const {
  if (!(reading > 0)) return std::numeric_limits<double>::infinity();
  const double ly = std::log(reading);
  std::size_t i = 0;
  while (i + 2 < points_.size() && reading < points_[i + 1].second) ++i;
  const double x0 = std::log(points_[i].first), x1 = std::log(points_[i + 1].first);
  const double y0 = std::log(points_[i].second), y1 = std::log(points_[i + 1].second);
  const double slope = (y1 - y0) / (x1 - x0);
  const double d = std::exp(x0 + (ly - y0) / slope);
  return std::max(range_min_, d);
}

// ---- geometry --------------------------------------------------------------------------------------

std::vector<Vec3> coneRays(int rays, double half_angle, double first_azimuth) {
  std::vector<Vec3> out;
  if (rays <= 0) return out;
  out.push_back(Vec3::UnitX());
  const int n = rays - 1;
  for (int k = 0; k < n; ++k) {
    const double az = first_azimuth + 2 * M_PI * k / n;
    out.push_back(Vec3(std::cos(half_angle), std::sin(half_angle) * std::cos(az),
                       std::sin(half_angle) * std::sin(az)));
  }
  return out;
}

std::vector<LedSource> litLeds(World& world, const Environment& env, const Robot* exclude) {
  std::vector<LedSource> out;
  const double now = world.time();
  for (Robot* r : world.robots()) {
    if (r == exclude) continue;
    const LedRing& ring = env.ledRing(r->name());
    if (!ring.anyOn()) continue;
    for (int g = 0; g < kLedGroups; ++g) {
      if (!ring.isLit(g, now) || !r->hasLink(ring.frames[g])) continue;
      const Pose p = r->linkPose(ring.frames[g]);
      out.push_back(LedSource{p.position, p.orientation * Vec3::UnitX(), &ring.groups[g], r, g});
    }
  }
  return out;
}

double wrapPi(double a) {
  a = std::remainder(a, 2 * M_PI);
  return a <= -M_PI ? a + 2 * M_PI : a;
}

}  // namespace sbot::sensors
