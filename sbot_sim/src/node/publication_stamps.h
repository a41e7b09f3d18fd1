// The stamp of the latest message the simulator node published on each robot topic that sbot.h
// getters read (proximity, turret/state, ...), noted by the publishers themselves, and whether each
// of those publishers knows a subscriber (they publish only then). The lock-step gate
// (lockstep_gate.h) reads both: a subscription of the node to its own topics would connect
// asynchronously and miss the first messages after it is made. The node is single-threaded
// (sim_ros_interface.h), so there is no locking. No stamp is recorded until enable() (lock-step
// only): the publishers' hot path stays as it was otherwise.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>

#include <ros/publisher.h>
#include <ros/single_subscriber_publisher.h>
#include <ros/time.h>

namespace sbot_node {

class PublicationStamps {
 public:
  void enable() { enabled_ = true; }
  void note(const std::string& robot, const std::string& topic, const ros::Time& stamp) {
    if (enabled_) latest_[robot + "/" + topic] = stamp;
  }
  /// 0 when nothing was published on robot/topic.
  ros::Time latest(const std::string& robot, const std::string& topic) const {
    const auto it = latest_.find(robot + "/" + topic);
    return it == latest_.end() ? ros::Time(0) : it->second;
  }

  /// Whether the publisher of robot/topic will deliver its next message to the node named by its
  /// ROS name (e.g. /sbot_0/sbot_api_123_456): `listened(node)` answers from the publisher's
  /// SubscriberRoster. The registering object forgets it before it goes.
  using Listened = std::function<bool(const std::string& node)>;
  void watchSubscribers(const std::string& robot, const std::string& topic, Listened listened) {
    listened_[robot + "/" + topic] = std::move(listened);
  }
  void forgetSubscribers(const std::string& robot, const std::string& topic) { listened_.erase(robot + "/" + topic); }
  /// True when robot/topic's next message reaches `node` (also when nobody registered the topic:
  /// then there is nothing to wait for).
  bool listened(const std::string& robot, const std::string& topic, const std::string& node) const {
    const auto it = listened_.find(robot + "/" + topic);
    return it == listened_.end() || it->second(node);
  }

 private:
  bool enabled_ = false;
  std::map<std::string, ros::Time> latest_;
  std::map<std::string, Listened> listened_;
};

/// The subscribers of one publication, by node name, as its connect / disconnect callbacks report
/// them. Those run in the simulator's callback queue, so the roster changes only between steps, and
/// a node on it has its connection in place: what is published next reaches it. (Also cheaper than
/// Publisher::getNumSubscribers, which looks the topic up among all the node's publications.)
class SubscriberRoster {
 public:
  ros::SubscriberStatusCallback connected() {
    return [this](const ros::SingleSubscriberPublisher& p) { names_.insert(p.getSubscriberName()); };
  }
  ros::SubscriberStatusCallback disconnected() {
    return [this](const ros::SingleSubscriberPublisher& p) {
      const auto it = names_.find(p.getSubscriberName());
      if (it != names_.end()) names_.erase(it);
    };
  }
  bool any() const { return !names_.empty(); }
  /// `node` among them; an empty name (unknown) asks for anyone.
  bool has(const std::string& node) const { return node.empty() ? any() : names_.count(node) > 0; }

 private:
  std::multiset<std::string> names_;
};

/// The node's one record.
inline PublicationStamps& publicationStamps() {
  static PublicationStamps stamps;
  return stamps;
}

/// Publish `msg` (a message with a header) on robot/topic and note its stamp.
template <class M>
void publishNoted(const ros::Publisher& pub, const std::string& robot, const std::string& topic, const M& msg) {
  pub.publish(msg);
  publicationStamps().note(robot, topic, msg.header.stamp);
}

}  // namespace sbot_node
