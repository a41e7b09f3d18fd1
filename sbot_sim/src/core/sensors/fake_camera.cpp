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
  // The sources within range and elevation, then one occlusion test for all their lines of sight
  // (World::castRaysOfLengths: the same answers as a castRay each, far cheaper across a swarm);
  // only the visible ones are then made blobs (their angles and names), since in a swarm most
  // candidates are hidden behind nearer robots.
  struct Candidate {
    Vec3 local;  ///< camera frame [m]
    double distance;
    Vec3 colour;
    const std::string* source;
    int index;
  };
  // |elevation| > vertical_angle, without the atan2: |z| > tan(vertical_angle) * hypot(x, y)
  // (no limit from pi/2 on: every elevation is within it).
  const bool limited = params_.vertical_angle < M_PI / 2;
  const double tan_limit = limited ? std::tan(params_.vertical_angle) : 0.0;
  std::vector<Candidate> candidates;
  std::vector<Vec3> sights;
  std::vector<double> lengths;
  auto consider = [&](const Vec3& p, const Vec3& colour, const std::string& source, int index, double clearance) {
    const Vec3 v = p - cam.position;
    const double d = v.norm();
    if (d > params_.range || d <= 0) return;
    const Vec3 local = inv.orientation * v;
    const double z2 = local.z() * local.z(), plan2 = local.x() * local.x() + local.y() * local.y();
    if (limited && z2 > tan_limit * tan_limit * plan2) return;
    candidates.push_back(Candidate{local, d, colour, &source, index});
    sights.push_back(v);
    lengths.push_back(d - clearance);  // <= 0: nothing between (castRaysOfLengths casts no ray)
  };
  for (const LedSource& led : litLeds(world_, env_, &robot_)) {
    if (!ledFaces(led, cam.position)) continue;  // hidden behind its own ring, no ray needed
    consider(led.position, Vec3(led.led->r, led.led->g, led.led->b) / static_cast<double>(kLedMaxUnits),
             led.robot->name(), led.group, params_.source_clearance);
  }
  static const std::string kLamp = "lamp";
  if (params_.see_lamps) {
    const auto& lamps = env_.lamps();
    for (std::size_t i = 0; i < lamps.size(); ++i) {
      if (lamps[i].intensity > 0) consider(lamps[i].position, lamps[i].colour, kLamp, static_cast<int>(i), 0.0);
    }
  }
  const std::vector<RayHit> hits = world_.castRaysOfLengths(cam.position, sights, lengths, &robot_);
  const double turret = robot_.turretAngle();
  std::vector<Blob> out;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (hits[i].hit) continue;
    const Candidate& c = candidates[i];
    Blob b;
    b.bearing_camera = std::atan2(c.local.y(), c.local.x());
    b.bearing = wrapPi(b.bearing_camera + turret);
    b.distance = c.distance;
    b.elevation = std::atan2(c.local.z(), std::hypot(c.local.x(), c.local.y()));
    b.colour = c.colour;
    b.source = *c.source;
    b.index = c.index;
    out.push_back(std::move(b));
  }
  std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) { return a.distance < b.distance; });
  return out;
}

}  // namespace sbot::sensors
