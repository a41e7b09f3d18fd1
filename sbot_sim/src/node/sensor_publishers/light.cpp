// light (sbot_msgs/LightArray, frame <robot>/turret) and, for whoever subscribes,
// light/sensor_<k> (sensor_msgs/Illuminance, frame <robot>/light_<k>): the same noisy, saturating
// reading converted to lux (1 mcd/cm^2 = 10 lx).
#include <sbot_msgs/LightArray.h>
#include <sensor_msgs/Illuminance.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class LightPublisher : public SensorRingPublisher<sbot_msgs::LightArray, sensor_msgs::Illuminance, sn::kLightSensors> {
 public:
  LightPublisher() : SensorRingPublisher("light", sn::SensorChannel::Light, "light/sensor_", "light_") {}

 protected:
  std::array<unsigned, sn::kLightSensors> readAll(RobotTopics& t) override { return t.suite->getAllLightSensors(); }
  bool hasSingles(const RobotTopics& t) const override { return t.suite->light() != nullptr; }
  void fillSingle(const RobotTopics& t, unsigned reading, sensor_msgs::Illuminance& il) override {
    const sn::LightSensorParams& lp = t.suite->light()->params();
    constexpr double kLuxPerMcdPerCm2 = 10.0;  // 1e-3 cd / 1e-4 m^2
    il.illuminance = reading * lp.unit * kLuxPerMcdPerCm2;
    // Uniform relative noise +-noise has variance (noise * value)^2 / 3; 0 = unknown (REP).
    const double sd = lp.noise * il.illuminance;
    il.variance = sd * sd / 3.0;
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(light, LightPublisher, "light", 10, "light")

}  // namespace sbot_node
