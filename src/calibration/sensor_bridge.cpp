#include "calibration/sensor_bridge.h"

#include <cmath>
#include <limits>
#include <memory>

#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/ground.h"
#include "sbot_sim/core/sensors/light.h"
#include "sbot_sim/core/sensors/proximity.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sbot_sim/core/world.h"

namespace sbot::calib {
namespace {

// The channel's group and index: "ir12" -> ("ir", 12).
std::pair<std::string, int> split(const std::string& c) {
  const auto p = c.find_first_of("0123456789");
  if (p == std::string::npos) return {c, -1};
  return {c.substr(0, p), std::atoi(c.c_str() + p)};
}

}  // namespace

// Noise-free readings through the core's sensor modules: the same ray bundles (traceBundle), the
// same response curves and the same effect hook (sensors::applyEffects) as ProximitySensors::read,
// GroundSensors::read and LightSensors::read, minus the sensor noise and the rounding. The world's
// lamps and ambient light come from the dataset.
struct SensorBridge::Impl {
  Impl(World& w, Robot& r, const Dataset& ds) : world(w), robot(r), env(w) {
    for (const auto& l : ds.lamps) env.addLamp(l.position, l.intensity);
    env.setAmbientLight(ds.ambient_light);
    suite = std::make_unique<sensors::SensorSuite>(world, robot, env);
    const RobotDescription& d = robot.description();
    if (suite->proximity()) {
      ir_model = sensors::proximityRayModel(d);
      ir_dirs = ir_model.directions();
    }
    if (suite->ground()) {
      ground_model = sensors::groundRayModel(d);
      ground_dirs = ground_model.directions();
    }
  }
  World& world;
  Robot& robot;
  sensors::Environment env;
  std::unique_ptr<sensors::SensorSuite> suite;
  sensors::IrRayModel ir_model, ground_model;
  std::vector<Vec3> ir_dirs, ground_dirs;

  // The IR and ground sensors end a reading alike: the sample's distance, incidence and surface are
  // reported, then the effect hook and the sensor's response curve give the value (0 if not finite).
  SensorReading respond(SensorSample s, const sensors::LogLogResponse& response) {
    SensorReading out;
    out.distance = s.value;
    out.incidence = s.incidence;
    out.surface = s.surface;
    const double d = sensors::applyEffects(world, robot, s);
    out.value = std::isfinite(d) ? std::min(response.signal(d), response.maxReading()) : 0.0;
    return out;
  }

  SensorReading ir(int k) {
    SensorReading out;
    auto* prox = suite->proximity();
    if (!prox || k < 0 || k >= sensors::kProximitySensors) return out;
    SensorSample s;
    s.channel = "ir";
    s.index = k;
    if (prox->model() == sensors::ProximitySensors::Model::RayTraced) {
      const sensors::BundleHit hit = sensors::traceBundle(world, robot.linkPose("ir_" + std::to_string(k)), ir_dirs,
                                                          ir_model.range_min, ir_model.range_max, &robot);
      if (hit.hits == 0) {
        out.value = 0;
        return out;
      }
      s.value = hit.mean_distance;
      s.surface = hit.nearest.surface;
      s.incidence = hit.incidence;
    } else {
      s.value = prox->rawDistance(k);
      s.surface = "robot";
      if (!std::isfinite(s.value)) {
        out.value = 0;
        return out;
      }
    }
    return respond(s, prox->response());
  }

  SensorReading ground(int k) {
    SensorReading out;
    auto* g = suite->ground();
    if (!g || k < 0 || k >= sensors::kGroundSensors) return out;
    const sensors::BundleHit hit = sensors::traceBundle(world, robot.linkPose("ground_" + std::to_string(k)),
                                                        ground_dirs, ground_model.range_min, ground_model.range_max,
                                                        &robot);
    if (hit.hits == 0) {
      out.value = 0;
      return out;
    }
    return respond({"ground", k, hit.mean_distance, hit.nearest.surface, hit.incidence}, g->response());
  }

  SensorReading light(int k) {
    SensorReading out;
    auto* l = suite->light();
    if (!l || k < 0 || k >= sensors::kLightSensors) return out;
    const double e = l->illuminance(k);
    // Incidence and distance of the strongest lamp (for the angular effect and the report).
    const Pose pose = robot.linkPose("light_" + std::to_string(k));
    const Vec3 axis = pose.orientation * Vec3::UnitX();
    double best = 0;
    for (const auto& lamp : env.lamps()) {
      const Vec3 v = lamp.position - pose.position;
      const double dist = v.norm();
      if (dist <= 0) continue;
      const double c = axis.dot(v) / dist;
      const double contribution = sensors::pointIlluminance(lamp.intensity, dist, c);
      if (contribution > best) {
        best = contribution;
        out.distance = dist;
        out.incidence = std::acos(std::max(-1.0, std::min(1.0, c)));
      }
    }
    SensorSample s{"light", k, e, "", std::isfinite(out.incidence) ? out.incidence : 0.0};
    double v = sensors::applyEffects(world, robot, s);
    if (!std::isfinite(v) || v < 0) v = 0;
    out.value = std::min(l->params().max_reading, v / l->params().unit);
    return out;
  }
};

SensorBridge::SensorBridge(World& world, Robot& robot, const Dataset& ds) : impl_(new Impl(world, robot, ds)) {}
SensorBridge::~SensorBridge() = default;

bool SensorBridge::available() const { return impl_->suite->proximity() != nullptr; }

std::string SensorBridge::whyUnavailable() const { return "the robot's level has no such sensors"; }

void SensorBridge::placed() {}

SensorReading SensorBridge::read(const std::string& channel) {
  const auto [g, k] = split(channel);
  if (g == "ir") return impl_->ir(k);
  if (g == "ground") return impl_->ground(k);
  if (g == "light") return impl_->light(k);
  return {};
}

bool SensorBridge::supports(const std::string& group) { return group == "ir" || group == "ground" || group == "light"; }

}  // namespace sbot::calib
