// climate (sbot_msgs/Climate, frame <robot>/turret): temperature and humidity, left and right.
#include <sbot_msgs/Climate.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

class ClimatePublisher : public TopicPublisher<sbot_msgs::Climate> {
 public:
  ClimatePublisher() : TopicPublisher("climate", "climate", "turret", true) {}

 protected:
  void fill(RobotTopics& t, sbot_msgs::Climate& m) override {
    t.suite->getTemperatureAndHumidityLeft(&m.temperature_left, &m.humidity_left);
    t.suite->getTemperatureAndHumidityRight(&m.temperature_right, &m.humidity_right);
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(climate, ClimatePublisher, "climate", 1, "climate")

}  // namespace sbot_node
