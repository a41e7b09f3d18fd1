// slope (sbot_msgs/Slope, frame <robot>/base_link): the inclinometer's pitch and roll.
#include <sbot_msgs/Slope.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

class SlopePublisher : public TopicPublisher<sbot_msgs::Slope> {
 public:
  SlopePublisher() : TopicPublisher("slope", "slope", "base_link", true) {}

 protected:
  void fill(RobotTopics& t, sbot_msgs::Slope& m) override {
    int pitch = 0, roll = 0;
    t.suite->getSlope(&pitch, &roll);
    m.pitch = static_cast<int16_t>(pitch);
    m.roll = static_cast<int16_t>(roll);
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(slope, SlopePublisher, "slope", 10, "slope")

}  // namespace sbot_node
