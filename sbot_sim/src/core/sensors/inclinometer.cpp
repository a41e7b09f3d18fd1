#include "sbot_sim/core/sensors/inclinometer.h"

#include <cmath>

#include "sbot_sim/core/robot.h"

namespace sbot::sensors {

Slope slopeOf(const Quat& orientation) {
  const Vec3 rpy = rpyFromQuat(orientation);
  Slope s;
  s.pitch = -rpy.y() * 180.0 / M_PI;
  s.roll = rpy.x() * 180.0 / M_PI;
  return s;
}

Slope Inclinometer::slope() const { return slopeOf(robot_.basePose().orientation); }

void Inclinometer::getSlope(int* pitch, int* roll) const {
  const Slope s = slope();
  auto clampRound = [](double deg) {
    const long v = std::lround(deg);
    return static_cast<int>(v > 180 ? 180 : (v < -180 ? -180 : v));
  };
  if (pitch) *pitch = clampRound(s.pitch);
  if (roll) *roll = clampRound(s.roll);
}

Quat Inclinometer::orientation() const { return robot_.basePose().orientation; }

Vec3 Inclinometer::angularVelocity() const {
  return robot_.basePose().orientation.conjugate() * robot_.angularVelocity();
}

}  // namespace sbot::sensors
