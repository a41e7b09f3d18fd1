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
#include <string>
#include <utility>

#include <ros/publisher.h>
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

  /// `listened` tells whether the publisher of robot/topic knows a subscriber, by the same test it
  /// uses to decide to publish (its connect callbacks or its link count), so "true" means the topic
  /// is published when it is next due. The registering object forgets it before it goes.
  void watchSubscribers(const std::string& robot, const std::string& topic, std::function<bool()> listened) {
    listened_[robot + "/" + topic] = std::move(listened);
  }
  void forgetSubscribers(const std::string& robot, const std::string& topic) { listened_.erase(robot + "/" + topic); }
  /// True when robot/topic will be published when due (also when nobody registered it: nothing to wait for).
  bool listened(const std::string& robot, const std::string& topic) const {
    const auto it = listened_.find(robot + "/" + topic);
    return it == listened_.end() || it->second();
  }

 private:
  bool enabled_ = false;
  std::map<std::string, ros::Time> latest_;
  std::map<std::string, std::function<bool()>> listened_;
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
