#include "sbot_sim/core/sensors/ground.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world.h"

namespace sbot::sensors {

IrRayModel groundRayModel(const RobotDescription& d) {
  IrRayModel m;
  m.range_min = extraNumber(d, "ground_range_min_m", 0.001);  // Table 2.9: 0.1 cm
  m.range_max = extraNumber(d, "ground_range_max_m", 0.06);   // Table 2.9: 6 cm
  m.cone_angle = extraNumber(d, "ground_cone_angle_rad", 0.52359878);
  m.rays = extraCount(d, "ground_rays", 5, 1, 1000);
  if (m.rays < 1 || !(m.range_max > m.range_min) || !(m.range_min > 0)) {
    throw ConfigError(d.sidecar_path, "extra/ground_*",
                      "need ground_rays >= 1 and 0 < ground_range_min_m < ground_range_max_m");
  }
  return m;
}

LogLogResponse groundResponse(const IrRayModel& model) {
  // sbot.h getGroundSensor: "1 is 6mm, 25 is 2mm, 100 is 1mm. [0;255]".
  return LogLogResponse({{0.001, 100.0}, {0.002, 25.0}, {0.006, 1.0}}, model.range_min, model.range_max, 255.0);
}

GroundSensors::GroundSensors(World& world, Robot& robot)
    : world_(world),
      robot_(robot),
      model_(groundRayModel(robot.description())),
      directions_(model_.directions()),
      response_(groundResponse(model_)),
      noise_(extraNumber(robot.description(), "ground_noise", 0.1)) {
  for (int i = 0; i < kGroundSensors; ++i) {
    links_[i] = LinkRef("ground_" + std::to_string(i));
    if (!robot.hasLink(links_[i].name())) {
      throw ConfigError(robot.description().urdf_path, "link " + links_[i].name(), "missing (needed by the ground sensors)");
    }
  }
}

double GroundSensors::rawDistance(int sensor) const {
  if (sensor < 0 || sensor >= kGroundSensors) throw std::out_of_range("ground sensor must be in [0,3]");
  return traceBundle(world_, robot_.linkPose(links_[sensor]), directions_, model_.range_min, model_.range_max,
                     &robot_)
      .mean_distance;
}

unsigned GroundSensors::read(int sensor) {
  if (sensor < 0 || sensor >= kGroundSensors) throw std::out_of_range("ground sensor must be in [0,3]");
  return finish(sensor, traceBundle(world_, robot_.linkPose(links_[sensor]), directions_, model_.range_min,
                                    model_.range_max, &robot_));
}

unsigned GroundSensors::finish(int sensor, const BundleHit& hit) {
  if (hit.hits == 0) return 0;
  SensorSample s;
  s.channel = "ground";
  s.index = sensor;
  s.value = hit.mean_distance;
  s.surface = hit.nearest.surface;
  s.incidence = hit.incidence;
  double d = applyEffects(world_, robot_, s);
  if (std::isnan(d) || d == std::numeric_limits<double>::infinity()) return 0;
  if (noise_ > 0) d *= 1.0 + robot_.random().uniform("ground", -noise_, noise_);
  return static_cast<unsigned>(std::lround(response_.signal(d)));
}

std::array<unsigned, kGroundSensors> GroundSensors::readAll() {
  // The four bundles with one search of the spaces (traceBundles); the readings, and the order of
  // their noise draws, are those of read(0..3).
  std::vector<Pose> poses;
  poses.reserve(kGroundSensors);
  for (const auto& link : links_) poses.push_back(robot_.linkPose(link));
  const std::vector<BundleHit> hits =
      traceBundles(world_, poses, directions_, model_.range_min, model_.range_max, &robot_);
  std::array<unsigned, kGroundSensors> out{};
  for (int i = 0; i < kGroundSensors; ++i) out[i] = finish(i, hits[i]);
  return out;
}

}  // namespace sbot::sensors
