// Inclinometer (seed 2.2.9, sbot.h getSlope): pitch and roll of the treels in degrees, pitch
// positive nose up, roll positive right side down; orientation and body rates for sensor_msgs/Imu.
#include <gtest/gtest.h>

#include <cmath>

#include "sbot_sim/core/sensors/inclinometer.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

constexpr double kDeg = M_PI / 180;

TEST(Inclinometer, SignConventions) {
  // REP-103 pitch about +y (left) is nose DOWN: a nose-up attitude has a negative REP pitch.
  EXPECT_NEAR(slopeOf(quatFromRPY(0, -20 * kDeg, 0.7)).pitch, 20, 1e-9);
  EXPECT_NEAR(slopeOf(quatFromRPY(0, -20 * kDeg, 0.7)).roll, 0, 1e-9);
  EXPECT_NEAR(slopeOf(quatFromRPY(15 * kDeg, 0, -2.0)).roll, 15, 1e-9);  // left side up, right down
  EXPECT_NEAR(slopeOf(quatFromRPY(15 * kDeg, 0, -2.0)).pitch, 0, 1e-9);
  EXPECT_NEAR(std::abs(slopeOf(quatFromRPY(M_PI, 0, 0)).roll), 180, 1e-9);  // capsized
}

TEST(Inclinometer, ReadsATeleportedAttitudeInWholeDegrees) {
  World w(flatWorld());
  Robot& r = w.addRobotAt(loadLevel("simple"), Pose(Vec3(0, 0, 0.3), quatFromRPY(-12.4 * kDeg, -33.6 * kDeg, 1.0)),
                          "sbot_0");
  Inclinometer inc(r);
  int pitch = 0, roll = 0;
  inc.getSlope(&pitch, &roll);
  EXPECT_EQ(pitch, 34);
  EXPECT_EQ(roll, -12);
  EXPECT_TRUE(inc.orientation().isApprox(r.basePose().orientation, 1e-12));
  inc.getSlope(nullptr, nullptr);  // null outputs are allowed
}

// A 40 x 40 cm ramp rising toward +x by `deg` degrees, centred at the origin.
WorldConfig rampWorld(double deg) {
  WorldConfig c = flatWorld();
  BoxObstacle ramp;
  ramp.name = "ramp";
  ramp.size = Vec3(0.6, 0.6, 0.02);
  ramp.center = Vec3(0, 0, 0.06);
  ramp.pitch = -deg * kDeg;  // a positive box pitch lowers its +x end
  c.terrain.boxes.push_back(ramp);
  return c;
}

// Attitude [deg] of a Medium s-bot resting 1.5 s at `yaw` in world `c`. The physics leaves the
// Medium chassis ~3 deg nose-down on its wheels even on a flat floor, and the soft contacts give a
// little under a sideways load: the tests compare with the flat-floor attitude, within 2 deg.
Slope restingSlope(const WorldConfig& c, double yaw) {
  World w(c);
  Robot& r = w.addRobot(loadLevel("medium"), {0, 0, yaw}, "sbot_0");
  runFor(w, 1.5);
  return Inclinometer(r).slope();
}

TEST(Inclinometer, OnARampFacingUphillPitchIsPositive) {
  const Slope flat = restingSlope(flatWorld(), 0);
  const Slope ramp = restingSlope(rampWorld(12), 0);
  EXPECT_NEAR(ramp.pitch - flat.pitch, 12, 2);
  EXPECT_NEAR(ramp.roll - flat.roll, 0, 2);
}

TEST(Inclinometer, OnARampFacingAcrossRightSideUpIsNegativeRoll) {
  // Facing +y the robot's right side is toward +x, uphill: right side up = negative roll.
  const Slope flat = restingSlope(flatWorld(), M_PI / 2);
  const Slope ramp = restingSlope(rampWorld(12), M_PI / 2);
  EXPECT_NEAR(ramp.pitch - flat.pitch, 0, 2);
  EXPECT_NEAR(ramp.roll - flat.roll, -12, 2);
}

TEST(Inclinometer, BodyRatesForTheImu) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.3);
  r.setSpeed(40, -40);  // clockwise spin
  runFor(w, 1.5);
  const Inclinometer inc(r);
  const Vec3 rate = inc.angularVelocity();
  EXPECT_LT(rate.z(), -0.5) << "spinning clockwise about the body's up axis";
  // Body frame: the world rate rotated into base_link.
  EXPECT_TRUE(rate.isApprox(r.basePose().orientation.conjugate() * r.angularVelocity(), 1e-9));
  EXPECT_NEAR((r.basePose().orientation * rate).z(), r.angularVelocity().z(), 1e-9);
}

}  // namespace
}  // namespace sbot::test
