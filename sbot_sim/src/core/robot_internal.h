// What Robot's own files (robot.cpp, robot_build.cpp) share: conversions between the core's
// poses and ODE's bodies. Private to the core: no public header includes it.
#pragma once

#include <ode/ode.h>

#include "sbot_sim/core/types.h"

namespace sbot {

inline void toOde(const Quat& q, dQuaternion out) {
  out[0] = q.w(); out[1] = q.x(); out[2] = q.y(); out[3] = q.z();
}
inline Pose bodyPose(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);
  return Pose(Vec3(p[0], p[1], p[2]), Quat(q[0], q[1], q[2], q[3]));
}
inline void setBodyPose(dBodyID b, const Pose& pose) {
  dBodySetPosition(b, pose.position.x(), pose.position.y(), pose.position.z());
  dQuaternion q;
  toOde(pose.orientation, q);
  dBodySetQuaternion(b, q);
}
inline Vec3 vec(const dReal* v) { return Vec3(v[0], v[1], v[2]); }

}  // namespace sbot
