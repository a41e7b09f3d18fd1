// imu (sensor_msgs/Imu, frame <robot>/base_link): orientation and angular velocity; no linear
// acceleration (covariance[0] = -1).
#include <sensor_msgs/Imu.h>

#include "sensor_publisher.h"

namespace sbot_node {
namespace {

class ImuPublisher : public TopicPublisher<sensor_msgs::Imu> {
 public:
  ImuPublisher() : TopicPublisher("imu", "imu", "base_link", false) {}

 protected:
  void fill(RobotTopics& t, sensor_msgs::Imu& m) override {
    const sbot::Quat q = t.suite->imuOrientation();
    m.orientation.x = q.x();
    m.orientation.y = q.y();
    m.orientation.z = q.z();
    m.orientation.w = q.w();
    const sbot::Vec3 w = t.suite->imuAngularVelocity();
    m.angular_velocity.x = w.x();
    m.angular_velocity.y = w.y();
    m.angular_velocity.z = w.z();
    m.linear_acceleration_covariance[0] = -1;  // not provided
  }
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(imu, ImuPublisher, "imu", 10, nullptr)

}  // namespace sbot_node
