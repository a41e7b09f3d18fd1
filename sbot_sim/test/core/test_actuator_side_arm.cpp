// Side arm (seed 2.2.4, Table 2.5): inverse kinematics, ranges, availability, servo motion.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <cmath>

#include "sbot_sim/core/actuators/side_arm.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using actuators::SideArm;

TEST(ActuatorSideArm, OnlyTheDetailedLevelHasOne) {
  World w(flatWorld());
  Robot& m = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  SideArm arm(w, m);
  EXPECT_FALSE(arm.available());
  EXPECT_FALSE(arm.setPos(10, 10, 80));
  int e = 1, r = 1, d = 1;
  arm.getPos(&e, &r, &d);
  EXPECT_EQ(e, 0);
  EXPECT_EQ(d, 0);
}

TEST(ActuatorSideArm, InverseKinematicsRoundTrips) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("detailed"), {0, 0, 0}, "sbot_0");
  SideArm arm(w, r);
  ASSERT_TRUE(arm.available());
  for (double depth : {0.03, 0.06, 0.1}) {
    for (double rot : {-0.5, 0.0, 0.7}) {
      double qe, ql, qr, e, ro, d;
      arm.inverse(0.2, rot, depth, &qe, &ql, &qr);
      arm.forward(qe, ql, qr, &e, &ro, &d);
      EXPECT_NEAR(e, 0.2, 1e-9);
      EXPECT_NEAR(ro, rot, 1e-9);
      EXPECT_NEAR(d, depth, 1e-9);
    }
  }
  // Rest: depth 60 mm at the rest half-angle of 60 degrees.
  double qe, ql, qr;
  arm.inverse(0, 0, 0.06, &qe, &ql, &qr);
  EXPECT_NEAR(ql, 0, 1e-6);
  EXPECT_NEAR(qr, 0, 1e-6);
}

TEST(ActuatorSideArm, ClampsToItsRanges) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("detailed"), {0, 0, 0}, "sbot_0");
  SideArm arm(w, r);
  EXPECT_EQ(arm.elevationLimit(), 98);
  EXPECT_EQ(arm.rotationLimit(), 131);
  EXPECT_EQ(arm.depthMin(), 21);
  EXPECT_EQ(arm.depthMax(), 118);
  EXPECT_FALSE(arm.setPos(10, -20, 80));
  EXPECT_TRUE(arm.setPos(500, 0, 60));
  EXPECT_TRUE(arm.setPos(0, 0, 500));
}

TEST(ActuatorSideArm, ServosReachTheTarget) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("detailed"), {0, 0, 0}, "sbot_0");
  SideArm arm(w, r);
  EXPECT_FALSE(arm.setPos(0, 40, 80));  // rotate 18 deg, extend to 80 mm
  for (int i = 0; i < 200; ++i) {
    w.step();
    arm.update(w.config().step);
  }
  int e, ro, d;
  arm.getPos(&e, &ro, &d);
  EXPECT_NEAR(e, 0, 3);
  EXPECT_NEAR(ro, 40, 3);
  EXPECT_NEAR(d, 80, 3);
}

TEST(ActuatorSideArm, WeakConnectionMadeByClosingBrokenByPulling) {
  World w(flatWorld());
  Robot& a = w.addRobot(loadLevel("detailed"), {0, 0, 0}, "sbot_0");
  const double az = 110 * M_PI / 180, dist = 0.17;  // the arm's rest direction (110 deg)
  Robot& b = w.addRobot(loadLevel("medium"), {dist * std::cos(az), dist * std::sin(az), 0}, "sbot_1");
  SideArm arm(w, a);
  auto run = [&](int steps) {
    for (int i = 0; i < steps; ++i) {
      w.step();
      arm.update(w.config().step);
    }
  };
  arm.setPos(-30, 0, 110);  // lowered 14 deg, extended to 110 mm
  arm.setOpened();
  run(200);
  EXPECT_FALSE(arm.gripping());
  arm.setClosed();
  run(150);
  ASSERT_TRUE(arm.gripping());
  EXPECT_EQ(arm.gripped(), "sbot_1");
  ASSERT_NE(w.connections().find("sbot_0", Connection::SideArm), nullptr);
  arm.setOpened();
  EXPECT_FALSE(arm.gripping());
  // Grip again, then pull the held robot away with 15 N: the 1 N side-arm grip gives way.
  arm.setClosed();
  run(150);
  ASSERT_TRUE(arm.gripping());
  const Vec3 away = Vec3(std::cos(az), std::sin(az), 0) * 15.0;
  for (int i = 0; i < 100 && arm.gripping(); ++i) {
    dBodyAddForce(b.baseBody(), away.x(), away.y(), 0);
    w.step();
    arm.update(w.config().step);
  }
  EXPECT_FALSE(arm.gripping());
}

TEST(ActuatorSideArm, JawCommandsAndNoConnectionInFreeSpace) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("detailed"), {0, 0, 0}, "sbot_0");
  SideArm arm(w, r);
  arm.setClosed();
  EXPECT_TRUE(arm.jawsClosedCommanded());
  for (int i = 0; i < 100; ++i) {
    w.step();
    arm.update(w.config().step);
  }
  EXPECT_FALSE(arm.gripping());
  arm.setOpened();
  EXPECT_FALSE(arm.jawsClosedCommanded());
  int e, ro, d;
  arm.getTorque(&e, &ro, &d);
  EXPECT_LE(std::abs(e), 127);
  EXPECT_LE(std::abs(ro), 127);
}

}  // namespace
}  // namespace sbot::test
