#include "sbot_sim/core/sensors/fake_camera.h"

#include <algorithm>
#include <cmath>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/world.h"

namespace sbot::sensors {

FakeCamera::FakeCamera(World& world, Robot& robot, const Environment& env)
    : world_(world), robot_(robot), env_(env) {
  const RobotDescription& d = robot.description();
  params_.range = extraNumber(d, "fake_camera_range_m", params_.range);
  params_.vertical_angle = extraNumber(d, "fake_camera_vertical_angle_rad", params_.vertical_angle);
  link_ = robot.hasLink("fake_camera") ? "fake_camera" : (robot.hasLink("turret") ? "turret" : d.root_link);
}

std::vector<Blob> FakeCamera::blobs() const {
  const Pose cam = robot_.linkPose(link_);
  const Pose inv = cam.inverse();
  const double turret = robot_.turretAngle();
  // The sources within range and elevation, then one occlusion test for all their lines of sight
  // (World::castRaysOfLengths: the same answers as a castRay each, far cheaper across a swarm).
  std::vector<Blob> seen;
  std::vector<Vec3> sights;
  std::vector<double> lengths;
  auto consider = [&](const Vec3& p, const Vec3& colour, const std::string& source, int index, double clearance) {
    const Vec3 v = p - cam.position;
    const double d = v.norm();
    if (d > params_.range || d <= 0) return;
    const Vec3 local = inv.orientation * v;
    const double elevation = std::atan2(local.z(), std::hypot(local.x(), local.y()));
    if (std::abs(elevation) > params_.vertical_angle) return;
    Blob b;
    b.bearing_camera = std::atan2(local.y(), local.x());
    b.bearing = wrapPi(b.bearing_camera + turret);
    b.distance = d;
    b.elevation = elevation;
    b.colour = colour;
    b.source = source;
    b.index = index;
    seen.push_back(b);
    sights.push_back(v);
    lengths.push_back(d - clearance);  // <= 0: nothing between (castRaysOfLengths casts no ray)
  };
  for (const LedSource& led : litLeds(world_, env_, &robot_)) {
    if (!ledFaces(led, cam.position)) continue;  // hidden behind its own ring, no ray needed
    consider(led.position, Vec3(led.led->r, led.led->g, led.led->b) / static_cast<double>(kLedMaxUnits),
             led.robot->name(), led.group, params_.source_clearance);
  }
  if (params_.see_lamps) {
    const auto& lamps = env_.lamps();
    for (std::size_t i = 0; i < lamps.size(); ++i) {
      if (lamps[i].intensity > 0) consider(lamps[i].position, lamps[i].colour, "lamp", static_cast<int>(i), 0.0);
    }
  }
  const std::vector<RayHit> hits = world_.castRaysOfLengths(cam.position, sights, lengths, &robot_);
  std::vector<Blob> out;
  for (std::size_t i = 0; i < seen.size(); ++i)
    if (!hits[i].hit) out.push_back(std::move(seen[i]));
  std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) { return a.distance < b.distance; });
  return out;
}

}  // namespace sbot::sensors
