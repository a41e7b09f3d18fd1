// Treels module acceptance (issue: foundation): speed in s-bot units, spinning on the spot,
// stalling against a wall, the acceleration phase, API clamping.
#include <gtest/gtest.h>

#include <cmath>

#include "sim_fixture.h"

namespace sbot::test {
namespace {

TEST(Treels, Speed50Gives14cmPerSecond) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  r.setSpeed(50, 50);
  runFor(w, 2.0);  // acceleration phase and settling
  const Vec3 p0 = r.basePose().position;
  runFor(w, 3.0);
  const Vec3 p1 = r.basePose().position;
  const double speed = (p1 - p0).head<2>().norm() / 3.0;
  EXPECT_NEAR(speed, 0.140, 0.140 * 0.05) << "steady speed at setSpeed(50,50) [m/s]";
  // It drove forward (+x at yaw 0), not sideways.
  EXPECT_GT(p1.x() - p0.x(), 0.9 * (p1 - p0).head<2>().norm());
  int l, rr;
  r.getSpeed(&l, &rr);
  EXPECT_NEAR(l, 50, 2);
  EXPECT_NEAR(rr, 50, 2);
}

TEST(Treels, SpeedIsReachedOnlyAfterAnAccelerationPhase) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);  // settle on the ground
  r.setSpeed(70, 70);
  w.step();
  const double v_first = r.linearVelocity().head<2>().norm();
  EXPECT_LT(v_first, 0.5 * 70 * 0.0028) << "the body cannot reach the requested speed in one step";
  runFor(w, 1.5);
  EXPECT_NEAR(r.linearVelocity().head<2>().norm(), 70 * 0.0028, 0.05 * 70 * 0.0028);
}

TEST(Treels, SpinOnTheSpotDriftsLessThan1cmPerTurn) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0.3, -0.2, 0.4}, "sbot_0");
  runFor(w, 0.5);
  const Vec3 start = r.basePose().position;
  r.setSpeed(50, -50);
  // Count turns by integrating yaw changes.
  double turned = 0, last = r.basePose().yaw();
  double max_drift = 0;
  while (std::abs(turned) < 2 * 2 * M_PI && w.time() < 60) {
    w.step();
    const double y = r.basePose().yaw();
    turned += wrapAngle(y - last);
    last = y;
    max_drift = std::max(max_drift, (r.basePose().position - start).head<2>().norm());
  }
  ASSERT_GE(std::abs(turned), 4 * M_PI) << "did not complete two turns within 60 s";
  EXPECT_LT(turned, 0) << "left forward, right backward turns clockwise (negative yaw)";
  const double drift = (r.basePose().position - start).head<2>().norm();
  EXPECT_LT(drift / 2.0, 0.01) << "centre drift per turn [m]";
  EXPECT_LT(max_drift, 0.02);
}

TEST(Treels, DrivingIntoAWallStalls) {
  WorldConfig c = flatWorld();
  // A fixed wall 20 cm ahead of the robot.
  c.terrain.boxes.push_back({"wall", Vec3(0.25, 0, 0.1), Vec3(0.05, 1.0, 0.2), 0, 0, "wall"});
  World w(c);
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  r.setSpeed(50, 50);
  runFor(w, 4.0);
  EXPECT_LT(r.basePose().position.x(), 0.25);
  EXPECT_LT(r.linearVelocity().head<2>().norm(), 0.005) << "robot still moving against the wall";
  int tl, tr;
  r.getTrackTorque(&tl, &tr);
  // Maximum track torque is 90 units (Table 2.2): a blocked motor pushes with (nearly) all of it.
  EXPECT_GE(tl, 80);
  EXPECT_GE(tr, 80);
  EXPECT_LE(tl, 91);
  // On free ground the same command needs only a small fraction of it.
  World free_world(flatWorld());
  Robot& f = free_world.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  f.setSpeed(50, 50);
  runFor(free_world, 3.0);
  int fl, fr;
  f.getTrackTorque(&fl, &fr);
  EXPECT_LT(std::abs(fl), 20);
}

TEST(Treels, ApiRangeIsClampedThenLimitedTo70) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  EXPECT_FALSE(r.setSpeed(70, -70));
  EXPECT_DOUBLE_EQ(r.requestedLeft(), 70 * 0.0028);
  EXPECT_TRUE(r.setSpeed(127, -500));
  EXPECT_DOUBLE_EQ(r.requestedLeft(), 70 * 0.0028);
  EXPECT_DOUBLE_EQ(r.requestedRight(), -70 * 0.0028);
  r.setTrackSpeeds(std::nan(""), 1.0);
  EXPECT_DOUBLE_EQ(r.requestedLeft(), 0.0) << "NaN must not reach the motors";
  EXPECT_DOUBLE_EQ(r.requestedRight(), 70 * 0.0028);
}

}  // namespace
}  // namespace sbot::test
