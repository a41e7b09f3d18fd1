// Shared pieces of the sensor modules (sensors/*.h).
//
// Every sensor module follows the same ARGoS-style pattern:
//   1. nothing is computed per step: a value is computed when it is read (the battery is the one
//      exception, see battery.h);
//   2. the physical ("raw") value is computed in SI or the seed's physical unit (distance [m],
//      illuminance [mcd/cm^2], amplitude [-]);
//   3. the raw value is passed through every world effect's Effect::onSensor (effects.h), so the
//      calibration workbench can fit reflectance, gain, offset, ... without touching sensor code;
//   4. sensor noise is drawn from the robot's OWN named random stream (Robot::random(), stream
//      named after the channel, e.g. "ir"), so adding a robot or reading another sensor never
//      shifts the numbers a robot sees, and the same seed plus the same read sequence gives the
//      same values;
//   5. the result is converted to the standard s-bot API's units (sbot.h, seed Appendix A) and
//      clamped to the API range.
// Model parameters come from the level's sidecar `extra` map (RobotDescription::extra, generated
// from sbot_description/config/sbot_parameters.yaml) with the seed's values as fall-backs.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "sbot_sim/core/effects.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;
class Robot;
struct RobotDescription;

namespace sensors {

/// Sidecar `extra` value `key` as a number; `fallback` if absent. Throws ConfigError naming the
/// sidecar and key if present but not a finite number.
double extraNumber(const RobotDescription& d, const std::string& key, double fallback);
/// Sidecar `extra` value `key` as a whole number in [lo, hi] (ray counts); `fallback` if absent.
int extraCount(const RobotDescription& d, const std::string& key, int fallback, int lo, int hi);
/// Sidecar `extra` value `key` as a boolean ("true"/"false"/"1"/"0"/"yes"/"no").
bool extraBool(const RobotDescription& d, const std::string& key, bool fallback);

/// Run every effect of `world` on `sample` (in the order they were added); returns sample.value.
double applyEffects(const World& world, const Robot& robot, SensorSample& sample);

/// Monotonically decreasing sensor response through calibration points, linear in log-log space
/// between the points and extrapolated with the first / last segment's log-log slope. Used for the
/// IR proximity (2.2.6) and ground (2.2.7) sensors: reading = f(distance).
class LogLogResponse {
 public:
  /// `points`: (distance [m], reading) with strictly increasing distance and strictly decreasing
  /// reading, at least two. Beyond `range_max` the reading is 0 (nothing detected); below
  /// `range_min` the distance is taken as `range_min`. Readings are clamped to [0, max_reading].
  LogLogResponse(std::vector<std::pair<double, double>> points, double range_min, double range_max,
                 double max_reading);

  /// Continuous (unrounded) reading for an object detected at `distance` [m]; 0 if distance >
  /// range_max or not finite (nothing within the sensing range).
  double reading(double distance) const;
  /// The same curve WITHOUT the range cut: the sensor signal for an (effective) distance, used after
  /// effects and noise have been applied to a detected object's distance (a detection at 19.5 cm
  /// with +10 % noise reads ~15, not 0). 0 for +infinity.
  double signal(double distance) const;
  /// Inverse of signal(): the effective distance [m] that gives `reading`, at least range_min and
  /// NOT limited to range_max (weak readings map beyond the range). Readings <= 0 give +infinity.
  double distance(double reading) const;

  double rangeMin() const { return range_min_; }
  double rangeMax() const { return range_max_; }
  double maxReading() const { return max_reading_; }
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  double unclamped(double distance) const;
  std::vector<std::pair<double, double>> points_;
  double range_min_, range_max_, max_reading_;
};

/// Unit direction vectors (in the sensor frame, +x = sensing axis) of a 1 + n ray bundle: one
/// central ray along +x and `rays - 1` peripheral rays on a cone of half-angle `half_angle` [rad],
/// evenly spaced about the axis starting at `first_azimuth` [rad] (0 = toward +y).
std::vector<Vec3> coneRays(int rays, double half_angle, double first_azimuth);

/// Wrap an angle to (-pi, pi].
double wrapPi(double a);

struct LedGroup;
class Environment;

/// One lit LED group of a robot's light ring, as a light source for light sensors and cameras.
struct LedSource {
  Vec3 position = Vec3::Zero();  ///< [m] world, the robot's light_<group> frame origin
  Vec3 normal = Vec3::UnitX();   ///< outward direction of the ring there (frame +x)
  const LedGroup* led = nullptr; ///< colour
  const Robot* robot = nullptr;
  int group = 0;
};
/// Every LED group lit at the World's current time, of every robot except `exclude`.
std::vector<LedSource> litLeds(World& world, const Environment& env, const Robot* exclude);
/// Whether an LED on a convex ring can be seen from `viewer` at all: viewer in front of the ring's
/// tangent plane at the LED (otherwise the LED's own turret hides it; no ray needed).
inline bool ledFaces(const LedSource& led, const Vec3& viewer) {
  return led.normal.dot(viewer - led.position) > 0;
}

}  // namespace sensors
}  // namespace sbot
