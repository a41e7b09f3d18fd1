// Sensor effects: what lies between the geometry a sensor sees and its reading. They act through
// Effect::onSensor on the raw physical value the sensor modules pass (sensors/sensor_common.h):
// IR proximity and ground sensors pass the detected distance [m], light sensors the illuminance
// [mcd/cm^2]. The IR effects are defined on the READING (reflectance multiplies the reflected
// light, an ambient offset adds to it) and converted back to an equivalent distance through the
// sensor's own response curve, so the module's noise and quantisation still apply afterwards.
// A sensor that detects nothing does not call the effects (an IR ambient offset therefore only
// shows on detections; see docs/calibration.md).
#pragma once

#include <functional>
#include <map>
#include <string>

#include "sbot_sim/core/effects/effect_registry.h"

namespace sbot {

/// Relative IR reflectance per surface label (open parameters: one per label, null 1). Applies to
/// the proximity ("ir") and ground ("ground") channels.
class IrReflectanceEffect : public ParametricEffect {
 public:
  explicit IrReflectanceEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// IR incidence-angle law: reading x cos(incidence)^exponent (a diffuse surface seen obliquely).
class IrIncidenceEffect : public ParametricEffect {
 public:
  explicit IrIncidenceEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// Ambient IR offset: reading + offset [API units] (daylight, the other robots' emitters).
class IrAmbientEffect : public ParametricEffect {
 public:
  explicit IrAmbientEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// Per-sensor IR gain and offset: reading_k x gain<k> + offset<k>, k = 0..14.
class IrGainOffsetEffect : public ParametricEffect {
 public:
  explicit IrGainOffsetEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// Light-sensor angular sensitivity: cos(theta)^exponent instead of the module's Lambert cosine
/// (exponent 1), theta = the incidence the module reports for the strongest source. Inert while the
/// light module reports no incidence (requested core change, docs/calibration.md).
class LightAngularEffect : public ParametricEffect {
 public:
  explicit LightAngularEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// Light-sensor ambient term: illuminance + offset [mcd/cm^2] (stray light, dark current).
class LightAmbientEffect : public ParametricEffect {
 public:
  explicit LightAmbientEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// Map an IR / ground distance [m] through reading -> f(reading) -> distance, with the sensor
/// response of `robot`'s level for `channel` ("ir" or "ground"). Used by the IR effects.
double transformIrDistance(const Robot& robot, const std::string& channel, double distance,
                           const std::function<double(double)>& f);

}  // namespace sbot
