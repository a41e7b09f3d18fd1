#include "sbot_sim/core/types.h"

#include <cmath>

namespace sbot {

double Pose::yaw() const { return rpyFromQuat(orientation).z(); }

Quat quatFromRPY(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
          Eigen::AngleAxisd(roll, Vec3::UnitX()))
      .normalized();
}

Vec3 rpyFromQuat(const Quat& q) {
  const Mat3 r = q.normalized().toRotationMatrix();
  // ZYX decomposition; pitch kept in [-pi/2, pi/2] like tf2::Matrix3x3::getRPY.
  const double pitch = std::asin(std::max(-1.0, std::min(1.0, -r(2, 0))));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return Vec3(roll, pitch, yaw);
}

}  // namespace sbot
