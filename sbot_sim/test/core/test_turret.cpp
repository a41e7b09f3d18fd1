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

std::size_t levelBodies(const Robot& r) {
  return static_cast<std::size_t>(std::stoi(r.description().extraOr("dynamical_bodies", "0")));
}

WorldConfig weldingWorld() {
  WorldConfig c = flatWorld();
  c.lock_idle_turret = true;
  return c;
}

double jointPosition(const Robot& r, const std::string& joint) {
  for (const JointState& j : r.jointStates())
    if (j.name == joint) return j.position;
  ADD_FAILURE() << "no joint state for " << joint;
  return NAN;
}

TEST(TurretWeld, ASettledTurretIsWeldedAndANewTargetFreesIt) {
  World w(weldingWorld());
  Robot& r = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  const std::string joint = r.description().turret.joint;
  EXPECT_TRUE(r.turretLocked()) << "at rest on its zero from the start";
  EXPECT_EQ(r.bodies().size() + 1, levelBodies(r));
  runFor(w, 0.3);
  r.setTurretRotation(20);  // 40 deg
  w.step();
  EXPECT_FALSE(r.turretLocked());
  EXPECT_EQ(r.bodies().size(), levelBodies(r));
  runFor(w, 1.0);
  EXPECT_FALSE(r.turretLocked()) << "still turning (0.5 rad/s)";
  EXPECT_GT(r.turretAngle(), 0.3);
  runFor(w, 2.0);
  ASSERT_TRUE(r.turretLocked()) << "settled at its target";
  const double welded_at = r.turretAngle();
  EXPECT_NEAR(welded_at, 20 * r.description().turret.unit, 0.02);
  EXPECT_EQ(r.getTurretRotation(), 20);
  EXPECT_EQ(r.getTurretRotationTorque(), 0);
  EXPECT_DOUBLE_EQ(jointPosition(r, joint), welded_at) << "TF keeps the turret joint";
  EXPECT_DOUBLE_EQ(r.jointAngle(joint), welded_at);
  // The welded turret's links stay where the hinge had them, and they move with the treels.
  const Pose base = r.basePose(), turret = r.linkPose("turret");
  EXPECT_NEAR((base.inverse() * turret).orientation.angularDistance(
                  Quat(Eigen::AngleAxisd(welded_at, Vec3::UnitZ()))), 0.0, 0.01);
  // The same target again does not free it; another one does, and it turns back from there.
  r.setTurretRotation(20);
  w.step();
  EXPECT_TRUE(r.turretLocked());
  r.setTurretRotation(-10);
  runFor(w, 0.5);
  EXPECT_FALSE(r.turretLocked());
  EXPECT_LT(r.turretAngle(), welded_at - 0.15);
  EXPECT_GT(r.turretAngle(), welded_at - 0.3) << "0.5 rad/s from where it was welded";
}

TEST(TurretWeld, OnlyTurretsWithTheirMassOffTheAxis) {
  World w(weldingWorld());
  for (const std::string level : {"fast", "simple", "basic", "medium", "detailed"}) {
    const bool off_axis = level != "fast" && level != "simple";  // the 4 cm COM offset (seed 2.2.2)
    EXPECT_EQ(Robot::weldsIdleTurret(w.config(), loadLevel(level)), off_axis) << level;
  }
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  EXPECT_FALSE(r.turretLocked());
  // Switched to a level that welds, the settled turret is welded; and freed again on the way back.
  w.switchLevel("sbot_0", loadLevel("medium"));
  runFor(w, 0.5);
  EXPECT_TRUE(r.turretLocked());
  w.switchLevel("sbot_0", loadLevel("simple"));
  EXPECT_FALSE(r.turretLocked());
  EXPECT_EQ(r.bodies().size(), levelBodies(r));
}

TEST(TurretWeld, OffByDefaultAndWithTheExactSolver) {
  WorldConfig exact = weldingWorld();
  exact.solver = "exact";
  for (const WorldConfig& c : {flatWorld(), exact}) {
    World w(c);
    Robot& r = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
    runFor(w, 0.5);
    EXPECT_FALSE(r.turretLocked()) << c.solver;
    EXPECT_EQ(r.bodies().size(), levelBodies(r)) << c.solver;
  }
}

}  // namespace
}  // namespace sbot::test
