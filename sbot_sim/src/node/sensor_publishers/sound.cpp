// sound (sbot_msgs/SoundState, frame <robot>/turret): the microphones' amplitudes and their sum.
#include <sbot_msgs/SoundState.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class SoundPublisher : public TopicPublisher<sbot_msgs::SoundState> {
 public:
  SoundPublisher() : TopicPublisher("sound", "sound", "turret", false) {}

 protected:
  bool available(const RobotTopics& t) const override { return t.suite->available(sn::SensorChannel::Sound); }
  void fill(RobotTopics& t, sbot_msgs::SoundState& m) override {
    const auto all = t.suite->getAllSoundIntensities();
    m.total = 0;
    for (int k = 0; k < sn::kMicrophones && k < 3; ++k) {
      m.amplitude[k] = all[k];
      m.total += all[k];
    }
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(sound, SoundPublisher, "sound", 10, nullptr)

}  // namespace sbot_node
