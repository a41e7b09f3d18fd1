// side_arm/state (sbot_msgs/SideArmState, frame <robot>/turret): Detailed only.
#include <sbot_msgs/SideArmState.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

class SideArmPublisher : public TopicPublisher<sbot_msgs::SideArmState> {
 public:
  SideArmPublisher() : TopicPublisher("side_arm/state", "side_arm", "turret", true) {}

 protected:
  bool available(const RobotTopics& t) const override { return t.side_arm->available(); }
  void fill(RobotTopics& t, sbot_msgs::SideArmState& m) override {
    const sbot::actuators::SideArm& a = *t.side_arm;
    int e = 0, r = 0, d = 0;
    a.getPos(&e, &r, &d);
    m.elevation = static_cast<int16_t>(e);
    m.rotation = static_cast<int16_t>(r);
    m.depth = static_cast<int16_t>(d);
    a.getTorque(&e, &r, &d);
    m.torque_elevation = static_cast<int16_t>(e);
    m.torque_rotation = static_cast<int16_t>(r);
    m.torque_depth = static_cast<int16_t>(d);
    m.jaws = a.jawsClosedCommanded() ? sbot_msgs::SideArmState::JAWS_CLOSED : sbot_msgs::SideArmState::JAWS_OPEN;
    fillGrip(m, a);
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(sideArm, SideArmPublisher, "side_arm", 10, "side_arm/state")

}  // namespace sbot_node
