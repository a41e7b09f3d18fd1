// sensor_markers (visualization_msgs/MarkerArray, frame world) for rviz: IR rays coloured by
// reading (green = nothing, red = 8191), LED groups in their colours (dim when off / in the dark
// half of a blink), the world's lamps.
#include <algorithm>
#include <cmath>

#include <visualization_msgs/MarkerArray.h>

#include "../ros_conversions.h"
#include "sensor_publisher.h"

namespace sbot_node {
namespace {

namespace sn = sbot::sensors;
using visualization_msgs::Marker;

class MarkersPublisher : public SensorPublisher {
 public:
  void advertise(RobotTopics& t) override {
    pub_ = t.advertise<visualization_msgs::MarkerArray>("sensor_markers", "markers", 2);
  }

  void publish(RobotTopics& t, double sim_time, const ros::Time& stamp) override {
    if (!t.due("markers", sim_time)) return;
    visualization_msgs::MarkerArray arr;
    if (t.suite->available(sn::SensorChannel::Proximity) && t.suite->proximity())
      arr.markers.push_back(irRays(t, stamp));
    const sn::LedRing& ring = t.env->ledRing(t.name());
    for (int k = 0; k < sn::kLedGroups; ++k) {
      const std::string link = "light_" + std::to_string(k);
      if (!t.robot->hasLink(link)) continue;
      Marker led = base(t, stamp, "leds", k, Marker::SPHERE);
      led.pose.position = toPoint(t.robot->linkPose(link).position);
      led.scale.x = led.scale.y = led.scale.z = 0.012;
      const auto& gp = ring.groups[k];
      const bool lit = ring.isLit(k, t.env->time());
      led.color.r = gp.r / 15.0f;
      led.color.g = gp.g / 15.0f;
      led.color.b = gp.b / 15.0f;
      led.color.a = lit ? 1.0f : 0.25f;
      arr.markers.push_back(led);
    }
    int id = 0;
    for (const sn::Lamp& l : t.env->lamps()) {
      Marker lamp = base(t, stamp, "lamps", id++, Marker::SPHERE);
      lamp.pose.position = toPoint(l.position);
      lamp.scale.x = lamp.scale.y = lamp.scale.z = 0.05;
      lamp.color.r = static_cast<float>(l.colour.x());
      lamp.color.g = static_cast<float>(l.colour.y());
      lamp.color.b = static_cast<float>(l.colour.z());
      lamp.color.a = l.intensity > 0 ? 1.0f : 0.3f;
      arr.markers.push_back(lamp);
    }
    pub_.publish(arr);
  }

 private:
  static Marker base(const RobotTopics& t, const ros::Time& stamp, const char* ns, int id, int type) {
    Marker m;
    m.header.stamp = stamp;
    m.header.frame_id = "world";
    m.ns = t.name() + "/" + ns;
    m.id = id;
    m.type = type;
    m.action = Marker::ADD;
    m.pose.orientation.w = 1;
    m.lifetime = ros::Duration(1.0);
    return m;
  }

  static Marker irRays(RobotTopics& t, const ros::Time& stamp) {
    const auto all = t.suite->getAllProximitySensors();
    const auto& resp = t.suite->proximity()->response();
    const double range_max = t.suite->proximity()->rayModel().range_max;
    Marker rays = base(t, stamp, "ir", 0, Marker::LINE_LIST);
    rays.scale.x = 0.002;
    for (int k = 0; k < sn::kProximitySensors; ++k) {
      const std::string link = "ir_" + std::to_string(k);
      if (!t.robot->hasLink(link)) continue;
      const sbot::Pose p = t.robot->linkPose(link);
      const double d = all[k] == 0 ? range_max : std::min(range_max, resp.distance(all[k]));
      rays.points.push_back(toPoint(p.position));
      rays.points.push_back(toPoint(p.position + p.orientation * sbot::Vec3(d, 0, 0)));
      std_msgs::ColorRGBA c;
      const double level = std::min(1.0, std::log1p(static_cast<double>(all[k])) / std::log1p(8191.0));
      c.r = static_cast<float>(level);
      c.g = static_cast<float>(1.0 - level);
      c.b = 0;
      c.a = 0.9f;
      rays.colors.push_back(c);
      rays.colors.push_back(c);
    }
    return rays;
  }

  ros::Publisher pub_;
};

}  // namespace

SBOT_SENSOR_PUBLISHER_TYPE(markers, MarkersPublisher, "markers", 10, nullptr)

}  // namespace sbot_node
