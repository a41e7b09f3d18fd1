// Turret servo: 2 degree units, [-100,100], 0.5 rad/s (Table 2.3).
#include <gtest/gtest.h>

#include <cmath>

#include "sim_fixture.h"

namespace sbot::test {
namespace {

TEST(Turret, RotatesAtHalfARadianPerSecond) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.3);
  EXPECT_FALSE(r.setTurretRotation(45));  // 90 degrees
  runFor(w, 2.0);
  // After 2 s at 0.5 rad/s it has turned about 1 rad, not yet pi/2.
  EXPECT_NEAR(r.turretAngle(), 1.0, 0.1);
  runFor(w, 2.5);
  EXPECT_NEAR(r.getTurretRotation(), 45, 1);
  EXPECT_NEAR(r.turretAngle(), M_PI / 2, 0.02);
  // The treels stay put while the turret turns (reaction torque is small against ground friction).
  EXPECT_LT(std::abs(r.basePose().yaw()), 0.05);
}

TEST(Turret, OutOfRangeIsClamped) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  EXPECT_TRUE(r.setTurretRotation(150));
  runFor(w, 8.0);
  EXPECT_EQ(r.getTurretRotation(), 100);
  EXPECT_TRUE(r.setTurretRotation(-1000));
  runFor(w, 15.0);
  EXPECT_EQ(r.getTurretRotation(), -100);
}

}  // namespace
}  // namespace sbot::test
