#include "sbot_sim/core/sensors/light.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/world.h"

namespace sbot::sensors {

double pointIlluminance(double intensity_mcd, double distance_m, double cos_theta) {
  const double d_cm = std::max(distance_m, 1e-4) * 100.0;
  return intensity_mcd * lightAngularSensitivity(cos_theta) / (d_cm * d_cm);
}

LightSensors::LightSensors(World& world, Robot& robot, const Environment& env)
    : world_(world), robot_(robot), env_(env) {
  const RobotDescription& d = robot.description();
  params_.unit = extraNumber(d, "light_sensor_unit_mcd_cm2", params_.unit);
  params_.max_reading = extraNumber(d, "light_sensor_max_units", params_.max_reading);
  params_.led_unit = extraNumber(d, "led_unit_mcd", params_.led_unit);
  for (int i = 0; i < kLightSensors; ++i) {
    links_[i] = LinkRef("light_" + std::to_string(i));
    if (!robot.hasLink(links_[i].name())) {
      throw ConfigError(d.urdf_path, "link " + links_[i].name(), "missing (needed by the light sensors)");
    }
  }
}

bool LightSensors::visible(const Vec3& from, const Vec3& to, double clearance) const {
  const Vec3 v = to - from;
  const double length = v.norm() - clearance;
  if (length <= 0) return true;
  return !world_.castRay(from, v, length, params_.self_shadowing ? nullptr : &robot_).hit;
}

double LightSensors::illuminance(int sensor) const {
  return illuminance(sensor, litLeds(world_, env_, &robot_));
}

double LightSensors::illuminance(int sensor, const std::vector<LedSource>& leds) const {
  if (sensor < 0 || sensor >= kLightSensors) throw std::out_of_range("light sensor must be in [0,7]");
  const Pose pose = robot_.linkPose(links_[sensor]);
  const Vec3 axis = pose.orientation * Vec3::UnitX();
  const Vec3 origin = pose.position + params_.origin_offset * axis;
  const double cull = params_.cull_units * params_.unit;  // [mcd/cm^2]
  double e = env_.getAmbientLight();
  auto add = [&](const Vec3& source, double intensity, double clearance) {
    if (intensity <= 0) return;
    const Vec3 v = source - pose.position;
    const double d = v.norm();
    if (d <= 0) return;
    const double contribution = pointIlluminance(intensity, d, axis.dot(v) / d);
    if (contribution <= 0 || contribution < cull) return;
    if (visible(origin, source, clearance)) e += contribution;
  };
  for (const Lamp& lamp : env_.lamps()) add(lamp.position, lamp.intensity, 0.0);
  for (const LedSource& led : leds) {
    if (!ledFaces(led, pose.position)) continue;  // behind its own ring
    const double intensity =
        params_.led_unit * (params_.spectral_weight.x() * led.led->r + params_.spectral_weight.y() * led.led->g +
                            params_.spectral_weight.z() * led.led->b);
    add(led.position, intensity, params_.source_clearance);
  }
  return e;
}

unsigned LightSensors::finish(int sensor, double illuminance) {
  SensorSample s;
  s.channel = "light";
  s.index = sensor;
  s.value = illuminance;
  double e = applyEffects(world_, robot_, s);
  if (std::isnan(e) || e < 0) e = 0.0;  // +inf saturates below
  if (params_.noise > 0) e *= 1.0 + robot_.random().uniform("light", -params_.noise, params_.noise);
  const double reading = std::min(params_.max_reading, std::max(0.0, e / params_.unit));
  return static_cast<unsigned>(std::lround(reading));
}

unsigned LightSensors::read(int sensor) { return finish(sensor, illuminance(sensor)); }

std::array<unsigned, kLightSensors> LightSensors::readAll() {
  const std::vector<LedSource> leds = litLeds(world_, env_, &robot_);
  std::array<unsigned, kLightSensors> out{};
  for (int i = 0; i < kLightSensors; ++i) out[i] = finish(i, illuminance(i, leds));
  return out;
}

}  // namespace sbot::sensors
