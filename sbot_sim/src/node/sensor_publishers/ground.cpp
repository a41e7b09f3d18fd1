// ground (sbot_msgs/GroundArray, frame <robot>/base_link): Medium and Detailed.
#include <sbot_msgs/GroundArray.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class GroundPublisher : public TopicPublisher<sbot_msgs::GroundArray> {
 public:
  GroundPublisher() : TopicPublisher("ground", "ground", "base_link", true) {}

 protected:
  bool available(const RobotTopics& t) const override { return t.suite->available(sn::SensorChannel::Ground); }
  void fill(RobotTopics& t, sbot_msgs::GroundArray& m) override {
    const auto all = t.suite->getAllGroundSensors();
    for (int k = 0; k < sn::kGroundSensors; ++k) m.readings[k] = static_cast<uint16_t>(all[k]);
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(ground, GroundPublisher, "ground", 10, "ground")

}  // namespace sbot_node
