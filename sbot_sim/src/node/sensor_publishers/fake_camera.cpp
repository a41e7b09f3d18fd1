// camera/blobs (sbot_msgs/BlobArray, frame <robot>/fake_camera): the fake camera's blobs, colours
// in 0..15 as the LEDs'. Rate channel `camera`.
#include <algorithm>
#include <cmath>

#include <sbot_msgs/BlobArray.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class FakeCameraPublisher : public TopicPublisher<sbot_msgs::BlobArray> {
 public:
  FakeCameraPublisher() : TopicPublisher("camera/blobs", "camera", "fake_camera", false) {}

 protected:
  bool available(const RobotTopics& t) const override { return t.suite->available(sn::SensorChannel::FakeCamera); }
  void fill(RobotTopics& t, sbot_msgs::BlobArray& m) override {
    for (const sn::Blob& b : t.suite->getFakeCameraBlobs()) {
      sbot_msgs::Blob o;
      o.bearing = b.bearing_camera;
      o.distance = b.distance;
      o.elevation = b.elevation;
      o.r = static_cast<uint8_t>(std::lround(std::clamp(b.colour.x(), 0.0, 1.0) * 15));
      o.g = static_cast<uint8_t>(std::lround(std::clamp(b.colour.y(), 0.0, 1.0) * 15));
      o.b = static_cast<uint8_t>(std::lround(std::clamp(b.colour.z(), 0.0, 1.0) * 15));
      m.blobs.push_back(o);
    }
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(fakeCamera, FakeCameraPublisher, "camera", 10, nullptr)

}  // namespace sbot_node
