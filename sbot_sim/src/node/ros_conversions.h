// Core geometry (Eigen, plain doubles) to geometry_msgs, for the node's publishers.
#pragma once

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Vector3.h>

#include "sbot_sim/core/types.h"

namespace sbot_node {

/// Any message with x, y, z fields (Point, Vector3) from a vector.
template <class Msg>
Msg toXYZ(const sbot::Vec3& v) {
  Msg m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}
inline geometry_msgs::Point toPoint(const sbot::Vec3& v) { return toXYZ<geometry_msgs::Point>(v); }
inline geometry_msgs::Vector3 toVector3(const sbot::Vec3& v) { return toXYZ<geometry_msgs::Vector3>(v); }

inline geometry_msgs::Quaternion toQuaternion(const sbot::Quat& q) {
  geometry_msgs::Quaternion m;
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  m.w = q.w();
  return m;
}

inline geometry_msgs::Pose toPose(const sbot::Pose& pose) {
  geometry_msgs::Pose p;
  p.position = toPoint(pose.position);
  p.orientation = toQuaternion(pose.orientation);
  return p;
}

}  // namespace sbot_node
