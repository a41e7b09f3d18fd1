// A controller node's side of the simulator's lock-step (simulator ~lockstep true; the protocol is
// described in sbot_sim/src/node/lockstep_gate.h and docs/ros_api.md, "Lock-step").
//
// The simulator holds its clock while a controller has a message to read on the topic it said it
// waits for, or while commands it said it sent are still in flight. A controller therefore calls
// waitingFor() each time it is done with the present and waits for its next message, with the
// number of cmd_speed / speaker messages it has published so far, and leaving() when it stops.
// Used by libsbot_ros (every sbot.h controller) and by random_walk_node.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>

#include <ros/ros.h>
#include <sbot_msgs/ControllerSync.h>

namespace sbot_controllers {

/// Poll `done` every 5 ms until it holds, `deadline` passes or ROS shuts down; returns done().
/// (Connections and latched messages arrive on roscpp's own threads.)
template <class Done>
bool pollUntil(Done done, std::chrono::steady_clock::time_point deadline) {
  while (!done() && std::chrono::steady_clock::now() < deadline && ros::ok()) usleep(5000);
  return done();
}

class LockstepClient {
 public:
  /// `nh`: a node handle in the robot's namespace. Reads /sim/lockstep (set by the simulator, which
  /// must be up); when true, advertises /sim/controller_sync and waits up to 10 s wall for the
  /// simulator to listen.
  explicit LockstepClient(ros::NodeHandle& nh) {
    ros::param::param("/sim/lockstep", enabled_, false);
    if (!enabled_) return;
    robot_ = nh.getNamespace();
    while (!robot_.empty() && robot_.front() == '/') robot_.erase(0, 1);
    pub_ = nh.advertise<sbot_msgs::ControllerSync>("/sim/controller_sync", 100);
    pollUntil([this] { return pub_.getNumSubscribers() > 0; },
              std::chrono::steady_clock::now() + std::chrono::seconds(10));
  }

  bool enabled() const { return enabled_; }
  /// The robot's namespace without slashes, e.g. sbot_0 (empty when not in lock-step).
  const std::string& robot() const { return robot_; }
  /// True once the simulator listens (false if it did not within 10 s of construction).
  bool connected() const { return enabled_ && pub_.getNumSubscribers() > 0; }

  /// This controller now waits for a message on `topic` (under the robot) stamped later than `after`,
  /// having published `speed_commands` cmd_speed and `speaker_commands` speaker messages so far.
  /// `new_subscription`: it subscribed to `topic` since its last call (the simulator then also holds
  /// until its publisher knows the subscriber).
  void waitingFor(const std::string& topic, const ros::Time& after, std::uint64_t speed_commands,
                  std::uint64_t speaker_commands, bool new_subscription) {
    if (!enabled_) return;
    sbot_msgs::ControllerSync m;
    m.robot = robot_;
    m.channel = topic;
    m.after = after;
    m.speed_commands = speed_commands;
    m.speaker_commands = speaker_commands;
    m.new_subscription = new_subscription;
    pub_.publish(m);
  }
  /// This controller stops: the simulator no longer holds for it.
  void leaving() { waitingFor("", ros::Time(0), 0, 0, false); }

 private:
  bool enabled_ = false;
  std::string robot_;
  ros::Publisher pub_;
};

}  // namespace sbot_controllers
