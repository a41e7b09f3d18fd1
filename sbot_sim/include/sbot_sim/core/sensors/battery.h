// Battery voltage meter (seed 2.2.12, Table 2.12; sbot.h getBatteryVoltage: [0,255] = 0..10 V).
// The seed planned but never calibrated this module; ours is a simple energy model.
//
//   * pack: lithium-ion, 7.2 V nominal, 1400 mAh (Table 2.12) => E_full = 7.2 V x 1.4 Ah =
//     10.08 Wh = 36288 J (2.2.12 "a total capacity of 10 Wh").
//   * power drawn: P = P_electronics + sum_j |tau_j omega_j| / eta over every actuated joint of
//     Robot::jointStates() (tau = motor torque applied last step, omega = joint rate), i.e. the
//     mechanical output of the track, turret and gripper motors divided by a drive efficiency.
//     CHOICES (the seed has no measurement): P_electronics = 2.5 W (CPU, sensors, radio, camera
//     idle: half of the seed's "below 5 W" budget), eta = 0.5 (DC motor x gearbox). Idle life is
//     36288 / 2.5 = 4.0 h; at the seed's 5 W ceiling 2.0 h, matching "a minimal battery life of two
//     hours" (2.2.12). Stall currents (torque at zero speed) are not charged: |tau omega| = 0.
//   * state of charge: SoC -= P dt / E_full, clamped to [0, 1].
//   * voltage: open-circuit voltage of a 2-cell Li-ion pack against SoC (piecewise linear through
//     typical cell data x 2: 100 % 8.40 V, 90 % 8.20, 80 % 7.96, 70 % 7.84, 60 % 7.74, 50 % 7.64,
//     40 % 7.58, 30 % 7.54, 20 % 7.48, 10 % 7.36, 5 % 6.90, 0 % 6.00 V) minus the drop over an
//     internal resistance of 0.15 ohm at the current I = P / V_oc.
//   * reading = round(V / 10 V x 255), clamped to [0, 255] (full, idle: 213; empty: 153).
// This is the ONE per-step sensor module: call update(dt) once per World::step() (it reads the
// joint states and integrates; a few multiplications per joint). No noise, no effects.
#pragma once

#include <vector>

namespace sbot {

class Robot;

namespace sensors {

struct BatteryParams {
  double nominal_voltage = 7.2;     ///< [V] Table 2.12
  double capacity_ah = 1.4;         ///< [Ah] Table 2.12
  double electronics_power = 2.5;   ///< [W] constant draw (CHOICE)
  double drive_efficiency = 0.5;    ///< mechanical / electrical power of the drives (CHOICE)
  double internal_resistance = 0.15;///< [ohm] pack (CHOICE)
  double full_scale_voltage = 10.0; ///< [V] reading 255 (sbot.h)
  double energy() const { return nominal_voltage * capacity_ah * 3600.0; }  ///< [J]
};

/// Open-circuit voltage [V] of the 2-cell pack at state of charge `soc` in [0,1].
double batteryOpenCircuitVoltage(double soc);

class Battery {
 public:
  explicit Battery(const Robot& robot, const BatteryParams& params = BatteryParams());

  /// Integrate the draw over `dt` [s] (call once per step, after World::step()).
  void update(double dt);

  unsigned getBatteryVoltage() const;   ///< sbot.h: [0,255] = 0..10 V
  double voltage() const;               ///< terminal voltage [V] at the current draw
  double stateOfCharge() const { return soc_; }  ///< [0,1]
  void setStateOfCharge(double soc);    ///< e.g. a fresh (1) or half-empty (0.5) battery
  double power() const { return power_; }        ///< [W] drawn during the last update
  double energyUsed() const { return used_; }    ///< [J] since construction
  bool depleted() const { return soc_ <= 0; }
  const BatteryParams& params() const { return params_; }
  /// Electrical power [W] the robot draws now (electronics + drives).
  double currentPower() const;

 private:
  const Robot& robot_;
  BatteryParams params_;
  double soc_ = 1.0;
  double power_;
  double used_ = 0;
};

}  // namespace sensors
}  // namespace sbot
