#include "sbot_sim/core/sensors/climate.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sbot_sim/core/sensors/environment.h"

namespace sbot::sensors {

ClimateSensor::ClimateSensor(const Environment& env, double tau)
    : env_(env), tau_(tau), state_(env.humidity()), last_(env.time()) {
  if (!(tau > 0)) throw std::invalid_argument("humidity lag time constant must be > 0 [s]");
}

void ClimateSensor::advance(double now) {
  if (!(now > last_)) return;
  const auto& log = env_.humidityLog();
  // Walk the piecewise-constant world humidity from last_ to now.
  double t = last_;
  // Index of the value in force at time t: the last entry with time <= t.
  std::size_t i = 0;
  while (i + 1 < log.size() && log[i + 1].first <= t) ++i;
  while (t < now) {
    const double end = (i + 1 < log.size()) ? std::min(now, log[i + 1].first) : now;
    const double target = log[i].second;
    state_ = target + (state_ - target) * std::exp(-(end - t) / tau_);
    t = end;
    if (i + 1 < log.size() && log[i + 1].first <= t) ++i;
  }
  last_ = now;
}

double ClimateSensor::humidity() {
  advance(env_.time());
  return std::max(0.0, std::min(100.0, state_));
}

double ClimateSensor::temperature() const { return std::max(-40.0, std::min(123.0, env_.temperature())); }

void ClimateSensor::read(float* temperature, float* humidity) {
  if (temperature) *temperature = static_cast<float>(this->temperature());
  if (humidity) *humidity = static_cast<float>(this->humidity());
}

}  // namespace sbot::sensors
