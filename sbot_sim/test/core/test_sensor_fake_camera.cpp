// Fake camera (seed 2.2.5 item 1, Table 2.7): lit LEDs of other robots and lamps within 10 m and
// +-70 deg of elevation, not occluded; bearing relative to the robot heading, distance, colour.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "sbot_sim/core/sensors/fake_camera.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

TEST(FakeCamera, SeesTheNearSideLedsOfAnotherRobotWithBearingAndDistance) {
  World w(flatWorld());
  Robot& a = w.addRobot(loadLevel("simple"), {0, 0, 0.4}, "a");
  Robot& b = w.addRobot(loadLevel("simple"), {1.0, 0.6, 2.0}, "b");
  Environment env(w);
  FakeCamera cam(w, a, env);
  EXPECT_TRUE(cam.blobs().empty()) << "no LED lit";
  env.setSameLightColor("b", 15, 0, 0, BLINKING_RATE_NO_BLINK);
  env.setSameLightColor("a", 0, 15, 0, BLINKING_RATE_NO_BLINK);  // own LEDs are not reported
  const auto blobs = cam.blobs();
  ASSERT_GE(blobs.size(), 3u);
  ASSERT_LE(blobs.size(), 5u) << "the far side of b's turret hides the rest of its 8 LEDs";
  const Pose c = a.linkPose("fake_camera");
  for (const Blob& blob : blobs) {
    EXPECT_EQ(blob.source, "b");
    EXPECT_EQ(blob.colour, Vec3(1, 0, 0));
    const Pose led = b.linkPose("light_" + std::to_string(blob.index));
    const Vec3 v = led.position - c.position;
    EXPECT_NEAR(blob.distance, v.norm(), 1e-9);
    // Bearing relative to a's heading (yaw 0.4, turret at 0).
    EXPECT_NEAR(blob.bearing, wrapAngle(std::atan2(v.y(), v.x()) - 0.4), 1e-3);
    EXPECT_NEAR(blob.bearing_camera, blob.bearing, 1e-3);
    EXPECT_LT(blob.elevation, 0) << "LEDs are below the camera";
    // Visible LEDs face the camera.
    EXPECT_LT((led.orientation * Vec3::UnitX()).dot(v), 0) << blob.index;
  }
  for (std::size_t i = 1; i < blobs.size(); ++i) EXPECT_LE(blobs[i - 1].distance, blobs[i].distance);
}

TEST(FakeCamera, BearingIsRelativeToTheTreelsWhenTheTurretTurns) {
  World w(flatWorld());
  Robot& a = w.addRobot(loadLevel("simple"), {0, 0, 0}, "a");
  w.addRobot(loadLevel("simple"), {0, 1.0, 0}, "b");  // straight to the left of a
  Environment env(w);
  env.setLightColor("b", 6, 0, 0, 15, BLINKING_RATE_NO_BLINK);  // light_6 at -90 deg faces a
  a.setTurretRotation(45);  // 90 deg
  runFor(w, 4.0);
  FakeCamera cam(w, a, env);
  const auto blobs = cam.blobs();
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].bearing, M_PI / 2, 0.05) << "to the left of the treels";
  EXPECT_NEAR(blobs[0].bearing_camera, 0.0, 0.05) << "straight ahead of the turned camera";
  EXPECT_EQ(blobs[0].colour, Vec3(0, 0, 1));
  EXPECT_NEAR(blobs[0].distance, 1.0 - 0.057, 0.02);
}

TEST(FakeCamera, RangeElevationOcclusionAndBlinking) {
  WorldConfig c = flatWorld();
  BoxObstacle wall;
  wall.name = "wall";
  wall.center = Vec3(0, -1.0, 0.1);
  wall.size = Vec3(0.5, 0.02, 0.2);
  c.terrain.boxes.push_back(wall);
  World w(c);
  Robot& a = w.addRobot(loadLevel("simple"), {0, 0, 0}, "a");
  w.addRobot(loadLevel("simple"), {0, -2.0, M_PI / 2}, "hidden");  // behind the wall
  w.addRobot(loadLevel("simple"), {10.5, 0, M_PI}, "far");          // beyond 10 m
  w.addRobot(loadLevel("simple"), {9.5, 0.0, M_PI}, "near");        // within 10 m
  Environment env(w);
  for (const char* n : {"hidden", "far", "near"}) env.setLightColor(n, 0, 15, 15, 15, BLINKING_RATE_2);  // front LED, facing a
  FakeCamera cam(w, a, env);
  auto blobs = cam.blobs();
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_EQ(blobs[0].source, "near");
  EXPECT_NEAR(blobs[0].bearing, 0.0, 0.01);
  // 2 Hz blinking: dark in the second quarter second after being set.
  runFor(w, 0.3);
  EXPECT_TRUE(cam.blobs().empty());
  runFor(w, 0.25);
  EXPECT_EQ(cam.blobs().size(), 1u);
  // Lamps: within +-70 deg elevation only, in the camera's frame (the robot rocks a degree or two
  // between its casters, so the lamps are placed in that frame).
  const Pose cam_frame = a.linkPose("fake_camera");
  auto at = [&](const Vec3& offset) { return Vec3(cam_frame.position + cam_frame.orientation * offset); };
  env.addLamp(at(Vec3(1.0, 0, 1.0)), 1000, Vec3(1, 1, 0));         // 45 deg up: seen
  env.addLamp(at(Vec3(0.2, 0, 1.0)), 1000);                         // 79 deg up: not seen
  env.addLamp(at(Vec3(-2.0, 0.1, 0.0)), 0.0);                       // switched off
  blobs = cam.blobs();
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_EQ(blobs[0].source, "lamp");
  EXPECT_EQ(blobs[0].index, 0);
  EXPECT_NEAR(blobs[0].elevation, M_PI / 4, 0.01);
  EXPECT_NEAR(blobs[0].distance, std::sqrt(2.0), 1e-6);
  EXPECT_EQ(blobs[0].colour, Vec3(1, 1, 0));
}

TEST(FakeCamera, AVerticalAngleFromAQuarterTurnOnSeesEveryElevation) {
  World w(flatWorld());
  RobotDescription wide = loadLevel("simple");
  wide.extra["fake_camera_vertical_angle_rad"] = "2.0";  // beyond pi/2: no elevation limit
  Robot& a = w.addRobot(loadLevel("simple"), {0, 0, 0}, "a");  // the seed's +-70 deg
  Robot& b = w.addRobot(wide, {15, 0, 0}, "b");                 // out of a's 10 m range
  Environment env(w);
  for (const Robot* r : {&a, &b}) {  // lamps 0-2 about a, 3-5 about b, in its camera's frame
    const Pose f = r->linkPose("fake_camera");
    for (const Vec3& offset : {Vec3(0.5, 0, 0.4), Vec3(0.1, 0, 0.6), Vec3(0, 0, 0.8)})  // 39, 81, 90 deg up
      env.addLamp(f.position + f.orientation * offset, 1000);
  }
  auto elevations = [](const FakeCamera& cam) {
    std::map<int, double> out;
    for (const Blob& bl : cam.blobs()) out[bl.index] = bl.elevation;
    return out;
  };
  const auto seen_a = elevations(FakeCamera(w, a, env));
  ASSERT_EQ(seen_a.size(), 1u) << "a sees only its 39 deg lamp";
  EXPECT_NEAR(seen_a.at(0), std::atan2(0.4, 0.5), 1e-6);
  const auto seen_b = elevations(FakeCamera(w, b, env));
  ASSERT_EQ(seen_b.size(), 3u) << "b sees all three of its lamps";
  EXPECT_NEAR(seen_b.at(3), std::atan2(0.4, 0.5), 1e-6);
  EXPECT_NEAR(seen_b.at(4), std::atan2(0.6, 0.1), 1e-6);
  EXPECT_NEAR(seen_b.at(5), M_PI / 2, 1e-6);
}

}  // namespace
}  // namespace sbot::test
