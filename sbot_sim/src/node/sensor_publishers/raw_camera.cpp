// camera/image_raw (sensor_msgs/Image rgb8, frame <robot>/camera, image_transport) and
// camera/camera_info: the omnidirectional camera (sensors/raw_camera.h), ray-cast in software,
// ~camera/width x ~camera/height (640 x 448), rendered at 1/~camera/internal_scale (4) and
// upscaled; rendered only while the image has a subscriber. Rate channel `raw_camera`.
#include <algorithm>

#include <image_transport/image_transport.h>
#include <sensor_msgs/CameraInfo.h>

#include "sbot_sim/core/sensors/raw_camera.h"
#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;

class RawCameraPublisher : public SensorPublisher {
 public:
  void advertise(RobotTopics& t) override {
    int width = 640, height = 448, scale = 4;
    t.pnh().param("camera/width", width, 640);
    t.pnh().param("camera/height", height, 448);
    t.pnh().param("camera/internal_scale", scale, 4);
    if (width < 16 || height < 16 || scale < 1)
      ROS_WARN_ONCE("simulator: ~camera/width and ~camera/height must be >= 16 px and ~camera/internal_scale >= 1, "
                    "got %d, %d, %d: using %d, %d, %d", width, height, scale, std::max(16, width),
                    std::max(16, height), std::max(1, scale));
    params_.width = std::max(16, width);
    params_.height = std::max(16, height);
    params_.internal_width = std::max(8, params_.width / std::max(1, scale));
    params_.internal_height = std::max(8, params_.height / std::max(1, scale));
    // The image and its camera_info apart: a subscriber to camera_info alone (`rosbag record -a -x
    // '.*image_raw.*'`) must not make every robot ray-cast an image nobody takes.
    image_transport::ImageTransport it(t.nh());
    image_pub_ = it.advertise("camera/image_raw", 1);
    info_pub_ = t.nh().advertise<sensor_msgs::CameraInfo>("camera/camera_info", 1);
  }

  void bind(RobotTopics& t) override { camera_ = std::make_unique<sn::RawCamera>(*t.world, *t.robot, *t.env, params_); }
  void unbind() override { camera_.reset(); }

  void publish(RobotTopics& t, double sim_time, const ros::Time& stamp) override {
    Rate& r = t.rates()["raw_camera"];
    if (sim_time + 1e-9 < r.next) return;
    r.next += 1.0 / r.hz;
    if (r.next <= sim_time) r.next = sim_time + 1.0 / r.hz;
    const bool image = image_pub_.getNumSubscribers() > 0;
    if (image || info_pub_.getNumSubscribers() > 0) publishFrame(t, stamp, image);
  }

 private:
  /// camera_info always, the image if asked.
  void publishFrame(const RobotTopics& t, const ros::Time& stamp, bool with_image) {
    sensor_msgs::ImagePtr img = boost::make_shared<sensor_msgs::Image>();
    img->header.stamp = stamp;
    img->header.frame_id = t.frame("camera");
    img->width = static_cast<uint32_t>(params_.width);
    img->height = static_cast<uint32_t>(params_.height);
    img->encoding = "rgb8";
    img->step = img->width * 3;
    // Rendered only for an image subscriber; camera_info alone is cheap.
    if (with_image) camera_->render(img->data);
    sensor_msgs::CameraInfoPtr info = boost::make_shared<sensor_msgs::CameraInfo>();
    info->header = img->header;
    info->width = img->width;
    info->height = img->height;
    // Not a pinhole camera: the polar mapping is documented in sensors/raw_camera.h; K holds the
    // image circle (centre cx, cy and radius as fx = fy) for consumers that want it.
    info->distortion_model = "plumb_bob";
    info->D.assign(5, 0.0);
    const double radius = 0.5 * std::min(params_.width, params_.height);
    info->K = {radius, 0, 0.5 * params_.width, 0, radius, 0.5 * params_.height, 0, 0, 1};
    info->R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    info->P = {radius, 0, 0.5 * params_.width, 0, 0, radius, 0.5 * params_.height, 0, 0, 0, 1, 0};
    if (with_image) image_pub_.publish(img);
    info_pub_.publish(info);
  }

  sn::RawCameraParams params_;
  std::unique_ptr<sn::RawCamera> camera_;
  image_transport::Publisher image_pub_;
  ros::Publisher info_pub_;
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(rawCamera, RawCameraPublisher, "raw_camera", 5, nullptr)

}  // namespace sbot_node
