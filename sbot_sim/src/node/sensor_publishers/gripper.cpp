// gripper/state (sbot_msgs/GripperState, frame <robot>/gripper): the front gripper's position,
// torque, optical barrier and grip.
#include <sbot_msgs/GripperState.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

class GripperPublisher : public TopicPublisher<sbot_msgs::GripperState> {
 public:
  GripperPublisher() : TopicPublisher("gripper/state", "gripper", "gripper", true) {}

 protected:
  void fill(RobotTopics& t, sbot_msgs::GripperState& m) override {
    const sbot::actuators::FrontGripper& g = *t.gripper;
    m.elevation = static_cast<int16_t>(g.getElevation());
    m.aperture = static_cast<int16_t>(g.getAperture());
    m.elevation_torque = static_cast<int16_t>(g.getElevationTorque());
    fillGrip(m, g);
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(gripper, GripperPublisher, "gripper", 10, "gripper/state")

}  // namespace sbot_node
