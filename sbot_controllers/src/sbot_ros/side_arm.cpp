// sbot.h side arm (Detailed only): position, torque, jaws, optical barrier.
#include "api.h"

#include <sbot_msgs/SetSideArm.h>

namespace {

using namespace sbot_api;

void knowArm() {
  if (g->arm_known) return;
  sbot_msgs::SideArmState s;
  if (g->side_arm.get(*g->nh, &s)) {
    g->arm_e = s.elevation;
    g->arm_r = s.rotation;
    g->arm_d = s.depth;
  }
  g->arm_known = true;
}

void armCommand(uint8_t jaws, const char* fn) {
  sbot_msgs::SetSideArm srv;
  srv.request.elevation = static_cast<int16_t>(g->arm_e);
  srv.request.rotation = static_cast<int16_t>(g->arm_r);
  srv.request.depth = static_cast<int16_t>(g->arm_d);
  srv.request.jaws = jaws;
  call("set_side_arm", srv, fn);
}

}  // namespace

using namespace sbot_api;

extern "C" {

void setSideArmPos(int elevation, int rotation, int depth) {
  if (!ready("setSideArmPos")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  g->arm_known = true;
  g->arm_e = toInt16(elevation);  // the service's int16 (40000 became -25536: the opposite limit)
  g->arm_r = toInt16(rotation);
  g->arm_d = toInt16(depth);
  armCommand(sbot_msgs::SetSideArm::Request::JAWS_KEEP, "setSideArmPos");
}

void getSideArmPos(int* elevation, int* rotation, int* depth) {
  using M = sbot_msgs::SideArmState;
  readFields("getSideArmPos", &Api::side_arm, false, into(elevation, &M::elevation), into(rotation, &M::rotation),
             into(depth, &M::depth));
}

void getSideArmTorque(int* elevation, int* rotation, int* depth) {
  using M = sbot_msgs::SideArmState;
  readFields("getSideArmTorque", &Api::side_arm, false, into(elevation, &M::torque_elevation),
             into(rotation, &M::torque_rotation), into(depth, &M::torque_depth));
}

void setSideArmOpened(void) {
  if (!ready("setSideArmOpened")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowArm();
  armCommand(sbot_msgs::SetSideArm::Request::JAWS_OPEN, "setSideArmOpened");
}

void setSideArmClosed(void) {
  if (!ready("setSideArmClosed")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowArm();
  armCommand(sbot_msgs::SetSideArm::Request::JAWS_CLOSE, "setSideArmClosed");
}

void getSideArmOpticalBarrier(unsigned* internal, unsigned* external, unsigned* combined) {
  using M = sbot_msgs::SideArmState;
  readFields("getSideArmOpticalBarrier", &Api::side_arm, false, into(internal, &M::barrier_internal),
             into(external, &M::barrier_external), into(combined, &M::barrier_combined));
}

}  // extern "C"
