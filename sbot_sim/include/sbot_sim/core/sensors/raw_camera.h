// Omnidirectional raw camera (seed 2.2.5, Table 2.6): a camera looking up at a spherical mirror on
// top of the turret pole (camera frame 11.85 cm above the turret), giving a polar ("fish-eye") image
// of the surroundings: the centre looks straight down at the own turret, the edge of the image
// circle looks slightly above the horizon. Software ray casting, no GPU or display:
//
//   pixel (u, v) -> normalised polar coordinates (rho in [0, 1] from the image centre, azimuth)
//   azimuth: image "up" = the turret's forward (+x, toward the gripper), counter-clockwise = left
//   elevation = -90 deg + rho * (90 deg + horizon_margin)       (equiangular mirror)
//   ray from the camera frame's origin -> World::castRay (own robot visible, as with the real
//   mirror) -> colour of the surface label (ground, walls, robot parts), shaded by the surface normal
//   and darkened with distance; nothing hit = sky.
//   Lit LEDs of every robot (Environment LED rings, blinking evaluated at the World's time) and the
//   lamps are drawn on top as small discs in their colours where a ray to them is not blocked.
//
// Rendering happens at an internal resolution (`internal_width` x `internal_height`, default 1/4 of
// the output) and is upscaled (nearest neighbour) to `width` x `height` (default 640 x 448 RGB8,
// Table 2.6). Cost ~ internal pixels ray casts per frame: render only when someone looks.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sbot_sim/core/types.h"

namespace sbot {

class World;
class Robot;

namespace sensors {

class Environment;

struct RawCameraParams {
  int width = 640, height = 448;                ///< output [px], Table 2.6
  int internal_width = 160, internal_height = 112;  ///< rendered [px]
  double horizon_margin = 0.35;                 ///< [rad] above the horizon at the image circle edge
  double max_range = 5.0;                       ///< [m] rays longer than this see the sky
  double led_radius_px = 1.5;                   ///< [internal px] LED disc
  double lamp_radius_px = 3.0;                  ///< [internal px] lamp disc
};

class RawCamera {
 public:
  RawCamera(const World& world, const Robot& robot, const Environment& env,
            const RawCameraParams& params = RawCameraParams());
  /// Render one frame: `rgb` gets width x height x 3 bytes, row-major, top row first.
  void render(std::vector<std::uint8_t>& rgb) const;
  const RawCameraParams& params() const { return params_; }
  /// Unit ray direction (world) of a normalised image point; false outside the image circle.
  bool rayFor(double rho, double azimuth, const Pose& turret, Vec3* dir) const;
  /// Image position (internal px) of a world direction; false if outside the circle.
  bool project(const Vec3& dir_world, const Pose& turret, double* u, double* v) const;

 private:
  Vec3 surfaceColour(const std::string& surface, bool robot) const;
  const World& world_;
  const Robot& robot_;
  const Environment& env_;
  RawCameraParams params_;
  std::string camera_link_;
};

}  // namespace sensors
}  // namespace sbot
