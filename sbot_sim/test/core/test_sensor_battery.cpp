// Battery voltage meter (seed 2.2.12, Table 2.12, sbot.h getBatteryVoltage [0,255] = 0..10 V):
// 7.2 V x 1.4 Ah = 10.08 Wh; electronics draw plus motor draw; >= 2 h at the seed's 5 W.
#include <gtest/gtest.h>

#include <cmath>

#include "sbot_sim/core/sensors/battery.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

TEST(Battery, CapacityAndVoltageCurve) {
  BatteryParams p;
  EXPECT_NEAR(p.energy(), 7.2 * 1.4 * 3600, 1e-9);  // 36288 J = 10.08 Wh (2.2.12 "10 Wh")
  EXPECT_DOUBLE_EQ(batteryOpenCircuitVoltage(1.0), 8.4);
  EXPECT_DOUBLE_EQ(batteryOpenCircuitVoltage(0.0), 6.0);
  EXPECT_DOUBLE_EQ(batteryOpenCircuitVoltage(0.5), 7.64);
  for (double s = 0; s < 1; s += 0.01) EXPECT_LT(batteryOpenCircuitVoltage(s), batteryOpenCircuitVoltage(s + 0.01));
  // The nominal 7.2 V is the average over the discharge (within 0.3 V).
  double mean = 0;
  for (int i = 0; i < 1000; ++i) mean += batteryOpenCircuitVoltage((i + 0.5) / 1000) / 1000;
  EXPECT_NEAR(mean, 7.2, 0.5);
}

TEST(Battery, IdleRobotLastsFourHoursAndReadsInApiUnits) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  Battery b(r);
  // Full and idle: 8.4 V - (2.5 W / 8.4 V) x 0.15 ohm = 8.355 V = 213 units of 10/255 V.
  b.update(w.config().step);
  EXPECT_NEAR(b.power(), 2.5, 0.01);
  EXPECT_NEAR(b.voltage(), 8.355, 0.002);
  EXPECT_EQ(b.getBatteryVoltage(), 213u);
  // Idle life: 36288 J / 2.5 W = 14515 s = 4.03 h (>= the seed's 2 h).
  double t = 0;
  while (!b.depleted() && t < 10 * 3600) {
    b.update(10.0);
    t += 10.0;
  }
  EXPECT_NEAR(t / 3600, 4.03, 0.01);
  EXPECT_EQ(b.getBatteryVoltage(), 153u);  // 6.0 V empty
  EXPECT_NEAR(b.energyUsed(), BatteryParams().energy(), 30.0);
}

TEST(Battery, AtTheSeedsFiveWattsItLastsTwoHours) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  BatteryParams p;
  p.electronics_power = 5.0;
  Battery b(r, p);
  double t = 0;
  while (!b.depleted()) {
    b.update(1.0);
    t += 1.0;
  }
  EXPECT_NEAR(t / 3600, 2.016, 0.01);
}

TEST(Battery, DrivingDrawsMotorPowerAndTheVoltageSags) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  Battery idle(r);
  idle.update(0.01);
  r.setSpeed(70, 70);
  runFor(w, 0.05);  // accelerating: high torque at rising speed
  Battery b(r);
  double mech = 0;
  for (const JointState& j : r.jointStates()) mech += std::abs(j.effort * j.velocity);
  ASSERT_GT(mech, 0.01) << "the motors must be doing work";
  b.update(0.01);
  EXPECT_NEAR(b.power(), 2.5 + mech / 0.5, 1e-9);
  EXPECT_LT(b.voltage(), idle.voltage());
  // Turning on the spot for a minute uses clearly more than idling for a minute (150 J): the
  // skidding treels work against friction (216 J). Straight at a constant speed on flat ground the
  // motors do almost no work: with the turret welded (opt-in) cruising takes 159 J, on its hinge
  // quickstep's unconverged hinge adds ~10 J of torque jitter; neither measures the battery model.
  r.setSpeed(50, -50);
  Battery driving(r);
  for (int i = 0; i < 6000; ++i) {
    w.step();
    driving.update(w.config().step);
  }
  r.setSpeed(0, 0);
  EXPECT_GT(driving.energyUsed(), 1.1 * 2.5 * 60);
  EXPECT_LT(driving.energyUsed(), 5.0 * 60) << "within the seed's 5 W budget";
  EXPECT_LT(driving.stateOfCharge(), 1.0);
  EXPECT_THROW(driving.setStateOfCharge(1.5), std::invalid_argument);
  // At 50 % charge the pack's open-circuit voltage is 7.64 V; under the last step's load it sags by
  // I R (0.15 ohm). That load jitters from step to step in a spin (3-7.5 W), so it is bounded, not
  // pinned: up to 8 W, 0.16 V.
  driving.setStateOfCharge(0.5);
  EXPECT_GT(driving.power(), 2.5);
  EXPECT_NEAR(driving.voltage(), 7.64 - driving.power() / 7.64 * 0.15, 1e-9);
  EXPECT_LT(driving.power(), 8.0);
}

}  // namespace
}  // namespace sbot::test
