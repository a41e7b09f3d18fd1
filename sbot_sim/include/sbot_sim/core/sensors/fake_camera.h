// Fake camera (seed 2.2.5 item 1, Table 2.7): high-level recognition of the light sources an s-bot
// could see with its omni-directional camera, without rendering. All levels.
//
// Frame `fake_camera` on the turret, 5.0 cm above the turret centre (Table 2.7 vertical offset),
// axes = turret axes (x forward, z up). It reports every
//   * lit LED group of every OTHER robot (Environment light rings; blinking evaluated at the World's
//     time; the LED at the robot's light_j frame), and every lamp with intensity > 0,
// that is
//   * within 10 m (Table 2.7 maximum sensor distance 1000 cm; sidecar fake_camera_range_m),
//   * within +-70 deg of the camera's horizontal plane (Table 2.7 "sensing vertical angle 70 deg",
//     read as the elevation limit above and below; sidecar fake_camera_vertical_angle_rad), and
//   * not occluded: a ray from the camera to the source hits nothing before it (the own robot is
//     ignored -- the real camera looks at a mirror above the turret; the last 3 mm before an LED
//     are not tested because the LED sits on its ring, so LEDs on the far side of a turret are
//     hidden by it).
// 360 deg horizontally. No noise (the seed gives none), no effects (nothing physical to modify).
// Cost: one line of sight per candidate LED/lamp within range and elevation, all tested together
// (World::castRaysOfLengths: against a robot's geoms only where the line crosses its box), so a
// lit swarm of N costs O(N^2) cheap box tests per frame; LEDs whose ring faces away from the
// camera are hidden by their own turret without a ray.
#pragma once

#include <string>
#include <vector>

#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;
class Robot;

namespace sensors {

struct Blob {
  double bearing = 0;         ///< [rad] (-pi, pi], relative to the robot (treels) heading,
                              ///< counter-clockwise positive: bearing_camera + turret angle
  double bearing_camera = 0;  ///< [rad] in the fake_camera (turret) frame
  double distance = 0;        ///< [m] camera -> source
  double elevation = 0;       ///< [rad] above (+) / below (-) the camera's horizontal plane
  Vec3 colour = Vec3::Zero(); ///< RGB in [0,1] (LED units / 15; lamp colour)
  std::string source;         ///< robot name of the LED, or "lamp"
  int index = 0;              ///< LED group (0..7) or lamp number
};

struct FakeCameraParams {
  double range = 10.0;                  ///< [m] Table 2.7
  double vertical_angle = 1.2217305;    ///< [rad] Table 2.7: 70 deg
  double source_clearance = 0.003;      ///< [m] untested end of a ray to an LED
  bool see_lamps = true;
};

class FakeCamera {
 public:
  FakeCamera(World& world, Robot& robot, const Environment& env);
  /// Everything visible now, nearest first.
  std::vector<Blob> blobs() const;
  FakeCameraParams& params() { return params_; }

 private:
  World& world_;
  Robot& robot_;
  const Environment& env_;
  FakeCameraParams params_;
  std::string link_;
};

}  // namespace sensors
}  // namespace sbot
