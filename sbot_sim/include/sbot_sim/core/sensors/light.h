// Light sensors of the light ring (seed 2.2.8, 2.4.2, Tables 2.10 and 2.14; sbot.h getLightSensor /
// getAllLightSensors). 8 sensors, frames light_0..light_7 on the turret ring, +x outward.
// Reading: unsigned in [0, 700], 0 = full dark, 700 = full light.
//
// Model (2.4.2: isotropic point sources, point sensors, inverse-square fall-off, line-of-sight
// shadowing only, no reflection or diffusion, sensor-defined angular sensitivity, constant ambient):
//
//   E = ambient + sum_s  I_s * S(theta_s) / (100 d_s)^2                    [mcd/cm^2]
//   reading = min(700, round(E / 0.1685))                                  (Table 2.10 sensor unit)
//
//   * sources s: the Environment's lamps (intensity I [mcd]) and every lit LED group of OTHER robots
//     (2.2.8; at its light_j frame, I = 0.8 mcd x (r + g + b) units, Table 2.10; blinking evaluated
//     at the World's time). The sensor is treated as broadband: the three colours count alike
//     (spectral_weight, default 1,1,1; the seed says the hardware sensor sees "(green) light" but
//     gives no spectral data). The robot's own LEDs are not seen (they face outward beside it).
//   * d_s: distance sensor -> source [m] (x100 -> cm; the seed's light unit is mcd/cm^2).
//   * S(theta) = max(0, cos theta), theta = angle between the sensor's +x and the direction to the
//     source: the Lambert cosine response of a flat photodiode behind the ring. The seed lets a
//     sensor "define angular sensitivity" without giving one; this lobe is the physical default
//     and makes the 8 sensors a usable light compass (a source 45 deg off axis reads 71 %).
//   * shadowing: a ray from the sensor (started 1 mm out along +x, off its own surface) to the source;
//     any body hit before the source (own robot, other robots, walls, terrain) blocks it entirely.
//     For an LED the last 3 mm are not tested (the LED sits on its robot's ring surface), so an LED
//     on the far side of its turret is hidden by that turret. Note: on the levels with a gripper
//     body (Basic, Medium, Detailed) the gripper box sits right in front of light_0 at ring height,
//     so light_0 is shadowed by its own gripper for sources less than ~75 deg above the horizon
//     ahead; `self_shadowing = false` ignores the own robot if that is not wanted.
//   * ambient (Environment::getAmbientLight) [mcd/cm^2] is added unshadowed and unweighted.
//   * saturation: readings clip at 700; the seed warns that sensors over-saturate easily, which
//     with these units happens above 118 mcd/cm^2 (e.g. a 1.18e6 mcd = 1180 cd lamp at 1 m, or a
//     118 cd lamp at 31.6 cm).
//   * cost: sources whose unshadowed contribution is below `cull_units` (0.01 reading units) are
//     skipped before any ray is cast (an LED at full white is culled beyond 1.46 m); LEDs whose
//     ring faces away from the sensor are hidden by their own turret without a ray (ledFaces);
//     readAll() collects the lit LEDs once for the 8 sensors.
// Noise: none by default (the seed specifies none for light); `noise` > 0 adds uniform relative
// noise E (1 + U(-noise, noise)) from the robot's stream "light", after the effects.
// Effects see channel "light", value = E [mcd/cm^2] (ambient included), surface empty.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "sbot_sim/core/link_ref.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;
class Robot;

namespace sensors {

constexpr int kLightSensors = 8;

struct LightSensorParams {
  double unit = 0.1685;             ///< [mcd/cm^2] per reading unit (Table 2.10)
  double max_reading = 700;         ///< Table 2.10
  double led_unit = 0.8;            ///< [mcd] per LED colour unit (Table 2.10)
  Vec3 spectral_weight = Vec3::Ones();  ///< weight of red, green, blue LED light
  double noise = 0.0;               ///< relative uniform noise (0 = none, as the seed)
  double origin_offset = 0.001;     ///< [m] shadow-ray start along the sensor's +x
  double source_clearance = 0.003;  ///< [m] untested end of a shadow ray to an LED
  double cull_units = 0.01;         ///< [reading units] skip weaker sources
  bool self_shadowing = true;       ///< the own robot's bodies can shadow its sensors
};

/// Lambertian angular sensitivity S = max(0, cos theta) for cos theta = `cos_theta`.
inline double lightAngularSensitivity(double cos_theta) { return cos_theta > 0 ? cos_theta : 0.0; }
/// Illuminance [mcd/cm^2] from an isotropic source of `intensity_mcd` at `distance_m`, seen at an
/// angle whose cosine is `cos_theta` from the sensor axis (no shadowing).
double pointIlluminance(double intensity_mcd, double distance_m, double cos_theta);

class LightSensors {
 public:
  /// Parameters from the sidecar (light_sensor_unit_mcd_cm2, light_sensor_max_units, led_unit_mcd).
  LightSensors(World& world, Robot& robot, const Environment& env);

  std::array<unsigned, kLightSensors> readAll();  ///< getAllLightSensors, each [0,700]
  unsigned read(int sensor);                      ///< getLightSensor; throws out_of_range
  /// Noise-free, effect-free illuminance [mcd/cm^2] at the sensor (ambient included).
  double illuminance(int sensor) const;

  LightSensorParams& params() { return params_; }
  const LightSensorParams& params() const { return params_; }

 private:
  bool visible(const Vec3& from, const Vec3& to, double clearance) const;
  double illuminance(int sensor, const std::vector<LedSource>& leds) const;
  unsigned finish(int sensor, double illuminance);
  World& world_;
  Robot& robot_;
  const Environment& env_;
  LightSensorParams params_;
  std::array<LinkRef, kLightSensors> links_;
};

}  // namespace sensors
}  // namespace sbot
