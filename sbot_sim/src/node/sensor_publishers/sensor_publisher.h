// One robot's sensor topics, a publisher type per sensor family (one file each in this folder,
// registered by one line in table.h), and what they share: RobotTopics, the robot's node handle,
// its subscriber rosters, its rate channels and its modules while it is bound.
//
// Adding a sensor family: a file here defining a SensorPublisher and its SensorPublisherType
// (`const SensorPublisherType& <name>Publisher()`), and the line SBOT_SENSOR_PUBLISHER(<name>) in
// table.h, at the place its topic is to be published within a step.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <std_msgs/Header.h>

#include "../publication_stamps.h"
#include "sbot_sim/core/actuators/gripper.h"
#include "sbot_sim/core/actuators/side_arm.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sbot_sim/core/world.h"

namespace sbot_node {

/// A rate channel (~rates/<channel>, <robot>/set_sampling_rate): its rate and next due time.
struct Rate {
  double hz = 10;
  double next = 0;  ///< [s, sim time]
};

/// The robot and its modules while it is bound (RobotModulesRos::bind), null while unbound.
struct RobotModules {
  sbot::World* world = nullptr;
  sbot::sensors::Environment* env = nullptr;
  sbot::Robot* robot = nullptr;
  sbot::sensors::SensorSuite* suite = nullptr;
  sbot::actuators::FrontGripper* gripper = nullptr;
  sbot::actuators::SideArm* side_arm = nullptr;
};

/// What every publisher of one robot shares: its modules (RobotModules), node handle, subscriber
/// rosters and rate channels.
class RobotTopics : public RobotModules {
 public:
  RobotTopics(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& name, bool per_sensor_topics)
      : nh_(nh, name), pnh_(pnh), name_(name), per_sensor_topics_(per_sensor_topics) {}

  ros::NodeHandle& nh() { return nh_; }  ///< the robot's namespace
  const ros::NodeHandle& pnh() const { return pnh_; }  ///< the simulator's private namespace
  const std::string& name() const { return name_; }
  /// ~per_sensor_topics: false leaves out the per-sensor topics (proximity/ir_<k>, light/sensor_<k>).
  bool perSensorTopics() const { return per_sensor_topics_; }

  /// Advertise `topic` in the robot's namespace with its subscribers kept in roster(key).
  /// Subscribers are kept by connect/disconnect callbacks (SubscriberRoster):
  /// Publisher::getNumSubscribers() looks the topic up among all the node's publications (linear in
  /// their number: ~20 per robot), far too slow to ask every step for 100 robots.
  template <class M>
  ros::Publisher advertise(const std::string& topic, const std::string& key, uint32_t queue = 10) {
    SubscriberRoster& r = roster(key);
    return nh_.advertise<M>(topic, queue, r.connected(), r.disconnected(), ros::VoidConstPtr(), false);
  }
  SubscriberRoster& roster(const std::string& key) { return subs_[key]; }

  std::map<std::string, Rate>& rates() { return rates_; }
  /// The channel's period has come (its next due time advanced) and anyone listens to its topic.
  bool due(const std::string& channel, double t);
  /// A channel with a compact array topic (key `channel`) and optional per-sensor topics (keys
  /// single_prefix + k, k < count): true when its period has come and anyone listens to either;
  /// any_single says whether the per-sensor messages are wanted.
  bool dueWithSingles(const std::string& channel, const std::string& single_prefix, int count, double t,
                      bool& any_single);

  static std_msgs::Header header(const std::string& frame, const ros::Time& stamp) {
    std_msgs::Header h;
    h.stamp = stamp;
    h.frame_id = frame;
    return h;
  }
  /// The robot's frames <name>/<link>.
  std::string frame(const char* link) const { return name_ + "/" + link; }

 private:
  ros::NodeHandle nh_, pnh_;
  std::string name_;
  bool per_sensor_topics_ = true;
  /// Subscribers per roster key; they outlive the publishers (RobotModulesRos destroys those first).
  std::map<std::string, SubscriberRoster> subs_;
  std::map<std::string, Rate> rates_;
};

/// One sensor family's topics of one robot.
class SensorPublisher {
 public:
  virtual ~SensorPublisher() = default;
  /// Advertise the topics (once, when the robot's modules are made).
  virtual void advertise(RobotTopics& topics) = 0;
  /// After the robot's modules are (re)built, and before they go.
  virtual void bind(RobotTopics& /*topics*/) {}
  virtual void unbind() {}
  /// At every step at which some channel is due (RobotModulesRos::update): publish if this one is.
  virtual void publish(RobotTopics& topics, double sim_time, const ros::Time& stamp) = 0;
};

/// A row of the publisher table.
struct SensorPublisherType {
  const char* channel;      ///< rate channel, also the roster key of its main topic
  double default_hz;        ///< ~rates/<channel> default (sbot.h has none; 10 Hz = SAMPLING_RATE_10)
  const char* noted_topic;  ///< topic whose stamps the lock-step gate reads (publishNoted), or nullptr
  std::unique_ptr<SensorPublisher> (*make)();
};

template <class P>
std::unique_ptr<SensorPublisher> makePublisher() {
  return std::make_unique<P>();
}

/// Defines `const SensorPublisherType& <name>Publisher()`, the row table.h's line names.
#define SBOT_SENSOR_PUBLISHER_TYPE(name, Class, channel, default_hz, noted_topic)                      \
  const SensorPublisherType& name##Publisher() {                                                      \
    static const SensorPublisherType type{channel, default_hz, noted_topic, &makePublisher<Class>};   \
    return type;                                                                                      \
  }

/// A sensor family with one topic of message type M (which has a header), published at its rate
/// channel's rate while anyone subscribes: a subclass names the topic, the channel and the frame,
/// and fills the message.
template <class M>
class TopicPublisher : public SensorPublisher {
 public:
  /// `link`: the header's frame <robot>/<link>; `noted`: published with publishNoted (a topic the
  /// lock-step gate waits for; its row in the table names it).
  TopicPublisher(const char* topic, const char* channel, const char* link, bool noted)
      : topic_(topic), channel_(channel), link_(link), noted_(noted) {}
  void advertise(RobotTopics& t) override { pub_ = t.advertise<M>(topic_, channel_); }
  void publish(RobotTopics& t, double sim_time, const ros::Time& stamp) override {
    if (!t.due(channel_, sim_time) || !available(t)) return;
    M m;
    m.header = RobotTopics::header(t.frame(link_), stamp);
    fill(t, m);
    if (noted_) {
      publishNoted(pub_, t.name(), topic_, m);
    } else {
      pub_.publish(m);
    }
  }

 protected:
  /// Whether the robot's level has the sensor (asked when the channel is due and listened to).
  virtual bool available(const RobotTopics& /*t*/) const { return true; }
  virtual void fill(RobotTopics& t, M& m) = 0;

 private:
  const char* topic_;
  const char* channel_;
  const char* link_;
  bool noted_;
  ros::Publisher pub_;
};

/// Every sensor publisher type, in table.h's order (advertising and publishing order).
const std::vector<const SensorPublisherType*>& sensorPublisherTable();

/// The optical barrier and grip fields sbot_msgs/GripperState and SideArmState share.
template <class M, class Device>
void fillGrip(M& m, const Device& d) {
  const auto b = d.getOpticalBarrier();
  m.barrier_internal = static_cast<uint16_t>(b.internal);
  m.barrier_external = static_cast<uint16_t>(b.external);
  m.barrier_combined = static_cast<uint16_t>(b.combined);
  m.gripping = d.gripping();
  m.gripped = d.gripped();
}

/// A sensor ring with a compact array topic (message Array with readings[N], frame <robot>/turret,
/// topic and rate channel `channel`, noted for the lock-step gate) and, for whoever subscribes, one
/// topic of message Single per sensor (single_topic + k, roster key and frame <robot>/single_key + k;
/// with ~per_sensor_topics false never advertised, so their rosters never fill and the per-sensor
/// messages are never built).
template <class Array, class Single, int N>
class SensorRingPublisher : public SensorPublisher {
 public:
  SensorRingPublisher(const char* channel, sbot::sensors::SensorChannel sensor, const char* single_topic,
                      const char* single_key)
      : channel_(channel), sensor_(sensor), single_topic_(single_topic), single_key_(single_key) {}
  void advertise(RobotTopics& t) override {
    array_ = t.advertise<Array>(channel_, channel_);
    for (int k = 0; t.perSensorTopics() && k < N; ++k)
      singles_.push_back(t.advertise<Single>(single_topic_ + std::to_string(k), single_key_ + std::to_string(k)));
  }
  void publish(RobotTopics& t, double sim_time, const ros::Time& stamp) override {
    bool any_single = false;
    const bool want = t.dueWithSingles(channel_, single_key_, N, sim_time, any_single);
    if (!want || !t.suite->available(sensor_)) return;
    const std::array<unsigned, N> all = readAll(t);
    Array m;
    m.header = RobotTopics::header(t.frame("turret"), stamp);
    for (int k = 0; k < N; ++k) m.readings[k] = static_cast<uint16_t>(all[k]);
    publishNoted(array_, t.name(), channel_, m);
    if (!any_single || !hasSingles(t)) return;
    for (int k = 0; k < N; ++k) {
      if (!t.roster(single_key_ + std::to_string(k)).any()) continue;
      Single s;
      s.header = RobotTopics::header(t.name() + "/" + single_key_ + std::to_string(k), stamp);
      fillSingle(t, all[k], s);
      singles_[k].publish(s);
    }
  }

 protected:
  virtual std::array<unsigned, N> readAll(RobotTopics& t) = 0;
  /// Whether the per-sensor messages can be made (the sensor model is there).
  virtual bool hasSingles(const RobotTopics& t) const = 0;
  virtual void fillSingle(const RobotTopics& t, unsigned reading, Single& s) = 0;

 private:
  const char* channel_;
  sbot::sensors::SensorChannel sensor_;
  std::string single_topic_, single_key_;
  ros::Publisher array_;
  std::vector<ros::Publisher> singles_;
};

}  // namespace sbot_node
