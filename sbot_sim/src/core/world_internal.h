// What World's own files (world*.cpp) share: the ODE helpers of its collision and query passes.
// Private to the core: no public header includes it.
#pragma once

#include <deque>
#include <string>
#include <vector>

#include <ode/ode.h>

#include "sbot_sim/core/geom_info.h"
#include "sbot_sim/core/world.h"

namespace sbot {

struct World::WheelContact {
  dJointFeedback feedback{};
  Vec3 normal = Vec3::UnitZ();
  Robot* wheel_of_body1 = nullptr;  ///< the robot whose driven wheel is the contact's body 1
  Robot* wheel_of_body2 = nullptr;
  bool body1_static = false;        ///< ODE then stores the joint reversed (see updateDriveWheelLoads)
  bool on_wheel1 = false, on_wheel2 = false;  ///< the geom is a driven wheel itself, not the body drive's chassis
};

/// The material of static geoms without one of their own, and what the ground plane is made of.
inline const std::string kGround = "ground";

/// The robot, material and link of a geom (every robot and terrain geom carries one).
inline const GeomInfo* infoOf(dGeomID g) { return static_cast<const GeomInfo*>(dGeomGetData(g)); }

/// ODE's bounding-box overlap test (collideAABBs): boxes that touch meet.
inline bool boxesMeet(const dReal* a, const dReal* b) {
  return !(a[0] > b[1] || a[1] < b[0] || a[2] > b[3] || a[3] < b[2] || a[4] > b[5] || a[5] < b[4]);
}

/// The geoms of `space` with their boxes, in the space's own list order (ODE's, newest first; the
/// order its collide2 visits them).
inline void readBoxedGeoms(dSpaceID space, std::vector<World::BoxedGeom>& out) {
  const int n = dSpaceGetNumGeoms(space);
  out.resize(n);
  for (int i = 0; i < n; ++i) {
    out[i].geom = dSpaceGetGeom(space, i);
    dGeomGetAABB(out[i].geom, out[i].aabb);
  }
}

/// The broad phase's callback for World's collision passes: World::handlePair (world_contacts.cpp).
void nearCallback(void* data, dGeomID a, dGeomID b);

}  // namespace sbot
