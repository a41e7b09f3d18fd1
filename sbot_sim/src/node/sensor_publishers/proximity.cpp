// proximity (sbot_msgs/ProximityArray, frame <robot>/turret) and, for whoever subscribes,
// proximity/ir_<k> (sensor_msgs/Range, frame <robot>/ir_<k>), k = 0..14.
#include <algorithm>
#include <cmath>

#include <sbot_msgs/ProximityArray.h>
#include <sensor_msgs/Range.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class ProximityPublisher
    : public SensorRingPublisher<sbot_msgs::ProximityArray, sensor_msgs::Range, sn::kProximitySensors> {
 public:
  ProximityPublisher() : SensorRingPublisher("proximity", sn::SensorChannel::Proximity, "proximity/ir_", "ir_") {}

 protected:
  std::array<unsigned, sn::kProximitySensors> readAll(RobotTopics& t) override {
    return t.suite->getAllProximitySensors();
  }
  bool hasSingles(const RobotTopics& t) const override { return t.suite->proximity() != nullptr; }
  void fillSingle(const RobotTopics& t, unsigned reading, sensor_msgs::Range& rg) override {
    const sn::ProximitySensors& ir = *t.suite->proximity();
    rg.radiation_type = sensor_msgs::Range::INFRARED;
    rg.field_of_view = 0.5;
    rg.min_range = static_cast<float>(ir.rayModel().range_min);
    rg.max_range = static_cast<float>(ir.rayModel().range_max);
    // Distance equivalent of the (noisy) reading; +inf when nothing is detected (REP 117).
    rg.range = reading == 0 ? INFINITY : static_cast<float>(std::min(ir.response().distance(reading), 1e3));
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(proximity, ProximityPublisher, "proximity", 10, "proximity")

}  // namespace sbot_node
