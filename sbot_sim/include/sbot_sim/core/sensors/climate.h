// Temperature and humidity sensors (seed 2.2.11; sbot.h getTemperatureAndHumidityLeft / Right:
// temperature [deg C] in [-40, 123], relative humidity [%] in [0, 100]).
//
// The seed does not model them ("outside the capabilities of the simulator engine"). We give the
// world one temperature and one humidity (Environment::setTemperature / setHumidity) and model the
// two sensor pairs on either side of the front gripper as reading those world values:
//   * temperature: immediate (the seed mentions no lag), clamped to [-40, 123];
//   * humidity: first-order lag with time constant tau = 4 s ("humidity readings with a time lag of
//     about 4 seconds", read as the 63 % response time of an SHT1x-type sensor), clamped to
//     [0, 100]. Computed lazily and exactly: the Environment logs the time of every humidity change
//     and the sensor integrates h' = (h_world - h) / tau piecewise analytically between its last
//     read and now, so nothing runs per step and the result is independent of how often it is read.
// Left and right see the same world values (no spatial field); each keeps its own lag state
// (identical unless created at different times). No noise, no effects.
#pragma once

#include <cstddef>

namespace sbot {
namespace sensors {

class Environment;

/// One first-order-lag humidity sensor (and an immediate temperature sensor).
class ClimateSensor {
 public:
  /// Starts settled at the world's current humidity.
  explicit ClimateSensor(const Environment& env, double tau = 4.0);
  /// Temperature [deg C] and humidity [%] now (sbot.h getTemperatureAndHumidity*).
  void read(float* temperature, float* humidity);
  double humidity();     ///< [%] lagged, now
  double temperature() const;  ///< [deg C] now
  double tau() const { return tau_; }

 private:
  void advance(double now);
  const Environment& env_;
  double tau_;
  double state_;     ///< lagged humidity at time last_
  double last_;      ///< [s]
};

/// The left and right sensor pairs.
class ClimateSensors {
 public:
  explicit ClimateSensors(const Environment& env, double tau = 4.0) : left_(env, tau), right_(env, tau) {}
  void getTemperatureAndHumidityLeft(float* temperature, float* humidity) { left_.read(temperature, humidity); }
  void getTemperatureAndHumidityRight(float* temperature, float* humidity) { right_.read(temperature, humidity); }
  ClimateSensor& left() { return left_; }
  ClimateSensor& right() { return right_; }

 private:
  ClimateSensor left_, right_;
};

}  // namespace sensors
}  // namespace sbot
