#include "sbot_sim/core/sensors/raw_camera.h"

#include <algorithm>
#include <cmath>

#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace sensors {

namespace {
constexpr double kStart = 0.015;  ///< [m] rays start this far from the camera origin
}  // namespace

RawCamera::RawCamera(const World& world, const Robot& robot, const Environment& env, const RawCameraParams& params)
    : world_(world), robot_(robot), env_(env), params_(params) {
  camera_link_ = robot.hasLink("camera") ? "camera" : (robot.hasLink("turret") ? "turret" : "base_link");
  params_.internal_width = std::max(8, std::min(params_.internal_width, params_.width));
  params_.internal_height = std::max(8, std::min(params_.internal_height, params_.height));
}

bool RawCamera::rayFor(double rho, double azimuth, const Pose& turret, Vec3* dir) const {
  if (rho > 1.0) return false;
  const double elevation = -M_PI / 2 + rho * (M_PI / 2 + params_.horizon_margin);
  const Vec3 local(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                   std::sin(elevation));
  // Azimuth follows the turret's heading; elevation is measured from the world horizontal (the
  // mirror axis is the turret axis, vertical when the robot stands level).
  *dir = (turret.orientation * local).normalized();
  return true;
}

bool RawCamera::project(const Vec3& dir_world, const Pose& turret, double* u, double* v) const {
  const Vec3 d = turret.orientation.conjugate() * dir_world.normalized();
  const double elevation = std::asin(std::clamp(d.z(), -1.0, 1.0));
  const double rho = (elevation + M_PI / 2) / (M_PI / 2 + params_.horizon_margin);
  if (rho > 1.0) return false;
  const double az = std::atan2(d.y(), d.x());
  const double r_px = 0.5 * std::min(params_.internal_width, params_.internal_height);
  // image up (-v) = forward (+x); image left (-u) = left (+y)
  *u = 0.5 * params_.internal_width - rho * r_px * std::sin(az);
  *v = 0.5 * params_.internal_height - rho * r_px * std::cos(az);
  return true;
}

Vec3 RawCamera::surfaceColour(const std::string& s, bool robot) const {
  if (robot) {
    if (s == "track") return Vec3(0.12, 0.12, 0.12);
    if (s == "stickable") return Vec3(0.75, 0.75, 0.78);  // turret ring (translucent plastic)
    if (s == "sticky") return Vec3(0.55, 0.5, 0.2);
    return Vec3(0.35, 0.35, 0.4);                          // chassis, gripper, arm
  }
  if (s == "wall") return Vec3(0.85, 0.85, 0.8);
  if (s == "white_paper") return Vec3(0.95, 0.95, 0.95);
  if (s == "black_paper") return Vec3(0.08, 0.08, 0.08);
  return Vec3(0.55, 0.5, 0.45);  // ground and anything else
}

void RawCamera::render(std::vector<std::uint8_t>& rgb) const {
  const int iw = params_.internal_width, ih = params_.internal_height;
  std::vector<Vec3> img(static_cast<std::size_t>(iw) * ih, Vec3::Zero());
  const Pose turret = robot_.linkPose(robot_.hasLink("turret") ? "turret" : "base_link");
  const Vec3 origin = robot_.linkPose(camera_link_).position;
  const double r_px = 0.5 * std::min(iw, ih);
  const Vec3 sky(0.15, 0.18, 0.3);
  for (int y = 0; y < ih; ++y) {
    for (int x = 0; x < iw; ++x) {
      const double du = (x + 0.5 - 0.5 * iw) / r_px, dv = (y + 0.5 - 0.5 * ih) / r_px;
      const double rho = std::hypot(du, dv);
      Vec3 dir;
      if (!rayFor(rho, std::atan2(-du, -dv), turret, &dir)) continue;  // outside the circle: black
      // Start past the camera pole (r 12 mm) so the ray does not begin inside the own geometry.
      const RayHit h = world_.castRay(origin + dir * kStart, dir, params_.max_range, nullptr);
      Vec3 c = sky;
      if (h.hit) {
        const double shade = 0.55 + 0.45 * std::abs(h.normal.normalized().dot(Vec3(0.3, 0.2, 0.93).normalized()));
        const double fog = std::exp(-h.distance / (2.0 * params_.max_range));
        c = surfaceColour(h.surface, h.robot != nullptr) * shade * fog + sky * (1 - fog) * 0.3;
      }
      img[static_cast<std::size_t>(y) * iw + x] = c;
    }
  }
  // Light sources on top: lamps and lit LEDs, where the line of sight is clear.
  auto disc = [&](const Vec3& p, const Vec3& colour, double radius, double clearance) {
    Vec3 d = p - origin;
    const double dist = d.norm();
    if (dist < 1e-6) return;
    d /= dist;
    double u, v;
    if (!project(d, turret, &u, &v)) return;
    const RayHit h = world_.castRay(origin + d * kStart, d, std::max(0.0, dist - clearance - kStart), nullptr);
    if (h.hit) return;
    for (int y = static_cast<int>(v - radius - 1); y <= static_cast<int>(v + radius + 1); ++y)
      for (int x = static_cast<int>(u - radius - 1); x <= static_cast<int>(u + radius + 1); ++x)
        if (x >= 0 && y >= 0 && x < iw && y < ih && std::hypot(x + 0.5 - u, y + 0.5 - v) <= radius)
          img[static_cast<std::size_t>(y) * iw + x] = colour;
  };
  for (const Lamp& l : env_.lamps())
    if (l.intensity > 0) disc(l.position, l.colour, params_.lamp_radius_px, 0.01);
  const double t = env_.time();
  for (const auto& [name, ring] : env_.ledRings()) {
    const Robot* other = const_cast<World&>(world_).findRobot(name);
    if (!other) continue;
    for (int k = 0; k < kLedGroups; ++k) {
      if (!ring.isLit(k, t)) continue;
      const std::string link = "light_" + std::to_string(k);
      if (!other->hasLink(link)) continue;
      const auto& g = ring.groups[k];
      disc(other->linkPose(link).position, Vec3(g.r, g.g, g.b) / 15.0, params_.led_radius_px, 0.004);
    }
  }
  // Upscale (nearest neighbour) to the output size.
  const int w = params_.width, hgt = params_.height;
  rgb.assign(static_cast<std::size_t>(w) * hgt * 3, 0);
  for (int y = 0; y < hgt; ++y) {
    const int sy = std::min(ih - 1, y * ih / hgt);
    for (int x = 0; x < w; ++x) {
      const int sx = std::min(iw - 1, x * iw / w);
      const Vec3& c = img[static_cast<std::size_t>(sy) * iw + sx];
      std::uint8_t* px = &rgb[(static_cast<std::size_t>(y) * w + x) * 3];
      for (int i = 0; i < 3; ++i) px[i] = static_cast<std::uint8_t>(std::lround(std::clamp(c[i], 0.0, 1.0) * 255));
    }
  }
}

}  // namespace sensors
}  // namespace sbot
