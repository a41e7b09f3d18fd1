// Plain geometric types shared by the ROS-free core. SI units, REP 103 axes (x forward, y left, z up).
#pragma once

#include <Eigen/Geometry>

namespace sbot {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
using Mat3 = Eigen::Matrix3d;

/// A rigid transform: position [m] and orientation (unit quaternion).
struct Pose {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();

  Pose() = default;
  Pose(const Vec3& p, const Quat& q) : position(p), orientation(q) {}
  /// Compose: (*this) * other, i.e. `other` expressed in this frame.
  Pose operator*(const Pose& other) const {
    return Pose(position + orientation * other.position, (orientation * other.orientation).normalized());
  }
  Pose inverse() const {
    Quat qi = orientation.conjugate();
    return Pose(-(qi * position), qi);
  }
  Vec3 transform(const Vec3& p) const { return position + orientation * p; }
  /// Heading about +z [rad].
  double yaw() const;
};

/// A pose on the ground plane: x, y [m], yaw [rad]. Robots are dropped onto the terrain at it.
struct Pose2D {
  double x = 0, y = 0, yaw = 0;
};

Quat quatFromRPY(double roll, double pitch, double yaw);
/// Roll, pitch, yaw [rad] (ZYX convention, as tf2's getRPY).
Vec3 rpyFromQuat(const Quat& q);

}  // namespace sbot
