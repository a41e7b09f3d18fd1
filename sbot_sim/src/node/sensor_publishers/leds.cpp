// leds/state (sbot_msgs/LedState, frame <robot>/turret): the LED ring's colours, blink codes and
// which groups are lit now.
#include <sbot_msgs/LedState.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class LedsPublisher : public TopicPublisher<sbot_msgs::LedState> {
 public:
  LedsPublisher() : TopicPublisher("leds/state", "leds", "turret", false) {}

 protected:
  void fill(RobotTopics& t, sbot_msgs::LedState& m) override {
    const sn::LedRing& ring = t.env->ledRing(t.name());
    for (int k = 0; k < sn::kLedGroups; ++k) {
      m.r[k] = static_cast<uint8_t>(ring.groups[k].r);
      m.g[k] = static_cast<uint8_t>(ring.groups[k].g);
      m.b[k] = static_cast<uint8_t>(ring.groups[k].b);
      m.blink[k] = static_cast<uint8_t>(ring.groups[k].blink);
      m.lit[k] = ring.isLit(k, t.env->time());
    }
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(leds, LedsPublisher, "leds", 10, nullptr)

}  // namespace sbot_node
