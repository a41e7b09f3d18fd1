// sbot.h front gripper: elevation, aperture, torque, optical barrier.
#include "api.h"

#include <sbot_msgs/SetGripper.h>

namespace {

using namespace sbot_api;

void gripperCommand(const char* fn) {
  sbot_msgs::SetGripper srv;
  srv.request.elevation = static_cast<int16_t>(g->gripper_elevation);
  srv.request.aperture = static_cast<int16_t>(g->gripper_aperture);
  if (call("set_gripper", srv, fn) && srv.response.clamped) {
    g->gripper_elevation = srv.response.applied_elevation;
    g->gripper_aperture = srv.response.applied_aperture;
  }
}

void knowGripper() {
  if (g->gripper_known) return;
  sbot_msgs::GripperState s;
  if (g->gripper.get(*g->nh, &s)) {
    g->gripper_elevation = s.elevation;
    g->gripper_aperture = s.aperture;
  }
  g->gripper_known = true;
}

/// setGripperElevation / setGripperAperture: one of the two commanded values, sent with the other.
void setGripper(int Api::*field, int value, const char* fn) {
  if (!ready(fn)) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowGripper();
  (*g).*field = toInt16(value);
  gripperCommand(fn);
}

}  // namespace

using namespace sbot_api;

extern "C" {

void setGripperElevation(int elevation) { setGripper(&Api::gripper_elevation, elevation, "setGripperElevation"); }

int getGripperElevation(void) {
  return readField("getGripperElevation", &Api::gripper, &sbot_msgs::GripperState::elevation);
}

void setGripperAperture(int aperture) { setGripper(&Api::gripper_aperture, aperture, "setGripperAperture"); }

int getGripperAperture(void) { return readField("getGripperAperture", &Api::gripper, &sbot_msgs::GripperState::aperture); }

int getGripperElevationTorque(void) {
  return readField("getGripperElevationTorque", &Api::gripper, &sbot_msgs::GripperState::elevation_torque);
}

void getGripperOpticalBarrier(unsigned* internal, unsigned* external, unsigned* combined) {
  using M = sbot_msgs::GripperState;
  readFields("getGripperOpticalBarrier", &Api::gripper, false, into(internal, &M::barrier_internal),
             into(external, &M::barrier_external), into(combined, &M::barrier_combined));
}

}  // extern "C"
