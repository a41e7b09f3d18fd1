// battery (sbot_msgs/Battery, frame <robot>/base_link): sbot.h voltage units, volts, charge.
#include <sbot_msgs/Battery.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

class BatteryPublisher : public TopicPublisher<sbot_msgs::Battery> {
 public:
  BatteryPublisher() : TopicPublisher("battery", "battery", "base_link", true) {}

 protected:
  void fill(RobotTopics& t, sbot_msgs::Battery& m) override {
    m.voltage_units = static_cast<uint8_t>(t.suite->getBatteryVoltage());
    m.voltage = t.suite->battery().voltage();
    m.charge_mAh = t.suite->battery().stateOfCharge() * 1400.0;
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(battery, BatteryPublisher, "battery", 1, "battery")

}  // namespace sbot_node
