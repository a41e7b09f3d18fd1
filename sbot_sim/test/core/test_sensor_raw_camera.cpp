// Omnidirectional raw camera (2.2.5, Table 2.6): image size, polar layout, lamps and LEDs visible.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/raw_camera.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using sensors::RawCamera;

std::array<int, 3> pixel(const std::vector<std::uint8_t>& rgb, int w, int x, int y) {
  const std::size_t i = (static_cast<std::size_t>(y) * w + x) * 3;
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

TEST(SensorRawCamera, PolarImageWithLampAndLeds) {
  World w(flatWorld());
  Robot& a = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  Robot& b = w.addRobot(loadLevel("medium"), {0, 0.4, 0}, "sbot_1");
  (void)b;
  sensors::Environment env(w);
  env.addLamp(Vec3(1.0, 0, 0.3), 1e5, Vec3(1, 1, 0));
  env.setSameLightColor("sbot_1", 15, 0, 0, sensors::BLINKING_RATE_NO_BLINK);
  runFor(w, 0.2);
  RawCamera cam(w, a, env);
  std::vector<std::uint8_t> rgb;
  const auto t0 = std::chrono::steady_clock::now();
  cam.render(rgb);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("raw camera frame (160x112 internal, 640x448 out): %.1f ms\n", ms);
  const int W = cam.params().width, H = cam.params().height;
  ASSERT_EQ(rgb.size(), static_cast<std::size_t>(W * H * 3));
  // Corners are outside the mirror circle: black. Near the centre: the own turret (not black).
  EXPECT_EQ(pixel(rgb, W, 1, 1), (std::array<int, 3>{0, 0, 0}));
  auto c = pixel(rgb, W, W / 2 + 6, H / 2 + 6);
  EXPECT_GT(c[0] + c[1] + c[2], 30);
  // The lamp straight ahead (+x) and slightly above the camera shows up yellow in the image's upper half.
  double u, v;
  ASSERT_TRUE(cam.project((Vec3(1.0, 0, 0.3) - a.linkPose("camera").position).normalized(), a.linkPose("turret"), &u, &v));
  const int sx = static_cast<int>(u * W / cam.params().internal_width), sy = static_cast<int>(v * H / cam.params().internal_height);
  EXPECT_LT(sy, H / 2);
  auto lamp = pixel(rgb, W, sx, sy);
  EXPECT_EQ(lamp, (std::array<int, 3>{255, 255, 0}));
  // sbot_1's red LEDs (to the left, +y) appear in the left half.
  int red_left = 0, red_right = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      auto p = pixel(rgb, W, x, y);
      if (p[0] == 255 && p[1] == 0 && p[2] == 0) (x < W / 2 ? red_left : red_right)++;
    }
  EXPECT_GT(red_left, 0);
  EXPECT_EQ(red_right, 0);
}

}  // namespace
}  // namespace sbot::test
