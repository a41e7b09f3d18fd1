#include "sbot_sim/core/effects/sensor_effects.h"

#include <cmath>
#include <limits>
#include <map>
#include <mutex>

#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/sensors/ground.h"
#include "sbot_sim/core/sensors/proximity.h"

namespace sbot {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The level's response curve of a channel, built once per description.
const sensors::LogLogResponse& responseOf(const Robot& robot, const std::string& channel) {
  static std::mutex mutex;
  static std::map<std::pair<const RobotDescription*, std::string>, sensors::LogLogResponse> cache;
  std::lock_guard<std::mutex> lock(mutex);
  const RobotDescription* d = &robot.description();
  auto key = std::make_pair(d, channel);
  auto it = cache.find(key);
  if (it == cache.end()) {
    if (channel == "ground")
      it = cache.emplace(key, sensors::groundResponse(sensors::groundRayModel(*d))).first;
    else
      it = cache.emplace(key, sensors::proximityResponse(sensors::proximityRayModel(*d))).first;
  }
  return it->second;
}

bool isIr(const SensorSample& s) { return s.channel == "ir" || s.channel == "ground"; }

}  // namespace

double transformIrDistance(const Robot& robot, const std::string& channel, double distance,
                           const std::function<double(double)>& f) {
  if (!std::isfinite(distance)) return distance;
  const sensors::LogLogResponse& r = responseOf(robot, channel);
  const double reading = f(r.signal(distance));
  return reading > 0 ? r.distance(reading) : kInf;
}

// ---- ir_reflectance ------------------------------------------------------------------------------

IrReflectanceEffect::IrReflectanceEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo IrReflectanceEffect::describe() {
  EffectInfo i{"ir_reflectance",
               "IR reflectance per surface label",
               "sensor",
               "Real IR sensors see the colour of a surface: the reflected light, hence the reading, is "
               "multiplied by the surface's relative reflectance (white paper ~1, black card much less). "
               "One parameter per surface label; labels not listed reflect like the calibration surface.",
               {"ir", "ground"},
               "static placements at several distances in front of each surface",
               {{"<surface>", "1", 1.0, 0.05, 5.0, 0.2, "reflectance relative to the calibration surface"}}};
  i.open_params = true;
  return i;
}

void IrReflectanceEffect::onSensor(const Robot& robot, SensorSample& s) {
  if (!isIr(s) || s.surface.empty()) return;
  const double r = paramOr(s.surface, 1.0);
  if (r == 1.0) return;
  s.value = transformIrDistance(robot, s.channel, s.value, [r](double reading) { return reading * r; });
}

// ---- ir_incidence --------------------------------------------------------------------------------

IrIncidenceEffect::IrIncidenceEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo IrIncidenceEffect::describe() {
  return {"ir_incidence",
          "IR incidence-angle law",
          "sensor",
          "A surface seen at an angle returns less light to the receiver: reading x cos(incidence)^exponent "
          "(the module's ray model alone only lengthens the distance).",
          {"ir"},
          "placements at one distance and incidence angles 0-60 deg",
          {{"exponent", "1", 0.0, 0.0, 8.0, 0.5, "exponent of the cosine law"}}};
}

void IrIncidenceEffect::onSensor(const Robot& robot, SensorSample& s) {
  if (s.channel != "ir") return;
  const double n = param("exponent");
  if (n == 0) return;
  const double c = std::max(0.05, std::cos(s.incidence));
  const double f = std::pow(c, n);
  s.value = transformIrDistance(robot, s.channel, s.value, [f](double reading) { return reading * f; });
}

// ---- ir_ambient ----------------------------------------------------------------------------------

IrAmbientEffect::IrAmbientEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo IrAmbientEffect::describe() {
  return {"ir_ambient",
          "IR ambient offset",
          "sensor",
          "Ambient infrared (daylight, lamps, other robots' emitters) adds a constant to every IR reading "
          "of a detected object.",
          {"ir"},
          "placements at large distances (weak readings show an offset best)",
          {{"offset", "units", 0.0, -100.0, 300.0, 10.0, "added to the reading"}}};
}

void IrAmbientEffect::onSensor(const Robot& robot, SensorSample& s) {
  if (s.channel != "ir") return;
  const double o = param("offset");
  if (o == 0) return;
  s.value = transformIrDistance(robot, s.channel, s.value, [o](double reading) { return reading + o; });
}

// ---- ir_gain_offset ------------------------------------------------------------------------------

namespace {
std::vector<ParamSpec> gainOffsetSpecs() {
  std::vector<ParamSpec> v;
  for (int k = 0; k < 15; ++k)
    v.push_back({"gain" + std::to_string(k), "1", 1.0, 0.2, 5.0, 0.1, "gain of sensor " + std::to_string(k)});
  for (int k = 0; k < 15; ++k)
    v.push_back({"offset" + std::to_string(k), "units", 0.0, -300.0, 300.0, 10.0,
                 "offset of sensor " + std::to_string(k)});
  return v;
}
}  // namespace

IrGainOffsetEffect::IrGainOffsetEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo IrGainOffsetEffect::describe() {
  return {"ir_gain_offset",
          "Per-sensor IR gain and offset",
          "sensor",
          "Every IR sensor has its own emitter power and receiver sensitivity: reading_k x gain<k> + offset<k>.",
          {"ir"},
          "static placements facing each sensor to a white surface at two or more distances",
          gainOffsetSpecs()};
}

void IrGainOffsetEffect::onSensor(const Robot& robot, SensorSample& s) {
  if (s.channel != "ir" || s.index < 0 || s.index >= 15) return;
  const double g = param("gain" + std::to_string(s.index)), o = param("offset" + std::to_string(s.index));
  if (g == 1.0 && o == 0.0) return;
  s.value = transformIrDistance(robot, s.channel, s.value, [g, o](double reading) { return reading * g + o; });
}

// ---- light ---------------------------------------------------------------------------------------

LightAngularEffect::LightAngularEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo LightAngularEffect::describe() {
  return {"light_angular",
          "Light-sensor angular sensitivity",
          "sensor",
          "The photodiode's angular lobe is cos(theta)^exponent rather than Lambert's cosine (exponent 1): "
          "a narrower lobe (exponent > 1) reads less for sources off the sensor axis.",
          {"light"},
          "a lamp at fixed distance, the robot turned in 15 deg steps",
          {{"exponent", "1", 1.0, 0.0, 6.0, 0.3, "exponent of the cosine lobe"}}};
}

void LightAngularEffect::onSensor(const Robot&, SensorSample& s) {
  if (s.channel != "light") return;
  const double n = param("exponent");
  if (n == 1.0 || s.incidence == 0) return;
  const double c = std::max(1e-3, std::cos(s.incidence));
  s.value *= std::pow(c, n - 1);
}

LightAmbientEffect::LightAmbientEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo LightAmbientEffect::describe() {
  return {"light_ambient",
          "Light-sensor ambient term",
          "sensor",
          "Stray light and dark current add a constant illuminance to every light sensor.",
          {"light"},
          "readings with the lamps off and on",
          {{"offset", "mcd/cm^2", 0.0, -5.0, 60.0, 1.0, "added illuminance"}}};
}

void LightAmbientEffect::onSensor(const Robot&, SensorSample& s) {
  if (s.channel == "light") s.value += param("offset");
}

}  // namespace sbot
