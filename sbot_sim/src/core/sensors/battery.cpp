#include "sbot_sim/core/sensors/battery.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sbot_sim/core/robot.h"

namespace sbot::sensors {

double batteryOpenCircuitVoltage(double soc) {
  static const double kSoc[] = {0.0, 0.05, 0.10, 0.20, 0.30, 0.40, 0.50, 0.60, 0.70, 0.80, 0.90, 1.0};
  static const double kVolt[] = {6.00, 6.90, 7.36, 7.48, 7.54, 7.58, 7.64, 7.74, 7.84, 7.96, 8.20, 8.40};
  constexpr int n = sizeof(kSoc) / sizeof(kSoc[0]);
  soc = std::max(0.0, std::min(1.0, std::isnan(soc) ? 0.0 : soc));
  for (int i = 1; i < n; ++i) {
    if (soc <= kSoc[i]) {
      const double t = (soc - kSoc[i - 1]) / (kSoc[i] - kSoc[i - 1]);
      return kVolt[i - 1] + t * (kVolt[i] - kVolt[i - 1]);
    }
  }
  return kVolt[n - 1];
}

Battery::Battery(const Robot& robot, const BatteryParams& params)
    : robot_(robot), params_(params), power_(params.electronics_power) {
  if (!(params_.drive_efficiency > 0) || !(params_.energy() > 0)) {
    throw std::invalid_argument("battery: drive efficiency and capacity must be > 0");
  }
}

double Battery::currentPower() const {
  double p = params_.electronics_power;
  for (const JointState& j : robot_.jointStates()) {
    const double mech = std::abs(j.effort * j.velocity);
    if (std::isfinite(mech)) p += mech / params_.drive_efficiency;
  }
  return p;
}

void Battery::update(double dt) {
  if (!(dt > 0)) return;
  power_ = soc_ > 0 ? currentPower() : 0.0;
  const double e = power_ * dt;
  used_ += e;
  soc_ = std::max(0.0, soc_ - e / params_.energy());
}

void Battery::setStateOfCharge(double soc) {
  if (!(soc >= 0 && soc <= 1)) throw std::invalid_argument("state of charge must be in [0,1]");
  soc_ = soc;
}

double Battery::voltage() const {
  const double voc = batteryOpenCircuitVoltage(soc_);
  if (soc_ <= 0) return voc;
  const double current = power_ / voc;
  return std::max(0.0, voc - current * params_.internal_resistance);
}

unsigned Battery::getBatteryVoltage() const {
  const double r = voltage() / params_.full_scale_voltage * 255.0;
  return static_cast<unsigned>(std::lround(std::max(0.0, std::min(255.0, r))));
}

}  // namespace sbot::sensors
