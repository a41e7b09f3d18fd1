#include "lockstep_gate.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include <sbot_msgs/TrackSpeed.h>
#include <std_msgs/Float64.h>

#include "publication_stamps.h"

namespace sbot_node {

namespace {

using SteadyClock = std::chrono::steady_clock;

double secondsBetween(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// The topics libsbot_ros's getters read (sbot_controllers/src/sbot_ros/latest.h, class Latest), and
/// ground_truth (random_walk_node), whose publishers note their stamps in publicationStamps().
const std::set<std::string>& trackedChannels() {
  static const std::set<std::string> channels = {"proximity", "ground", "light", "slope", "battery", "climate",
                                                 "track_state", "turret/state", "gripper/state", "side_arm/state",
                                                 "ground_truth"};
  return channels;
}

}  // namespace

LockstepGate::LockstepGate(ros::NodeHandle& nh, const LockstepParams& params, const std::vector<std::string>& robots,
                           RobotCheck check)
    : nh_(nh), params_(params), check_(std::move(check)) {
  for (const std::string& r : robots) attachRobot(r);
  sync_sub_ = nh_.subscribe("/sim/controller_sync", 100, &LockstepGate::onSync, this,
                            ros::TransportHints().tcpNoDelay());
  last_waiting_log_ = SteadyClock::now();
}

void LockstepGate::onSync(const ros::MessageEvent<const sbot_msgs::ControllerSync>& event) {
  const sbot_msgs::ControllerSync::ConstPtr& msg = event.getConstMessage();
  const std::string& robot = msg->robot;
  const std::string refused = robot.empty() || robot.find('/') != std::string::npos
                                  ? "robot '" + robot + "' is not a robot namespace such as sbot_0"
                                  : check_(robot);
  if (!refused.empty()) {
    if (refused_.insert(robot).second)
      ROS_WARN("simulator: lockstep: ignoring the syncs of a controller: %s", refused.c_str());
    return;
  }
  if (msg->channel.empty()) {  // the controller is leaving (shutdownSwarmBot)
    if (waiting_.erase(robot)) ROS_INFO("simulator: lockstep: the controller of %s left", robot.c_str());
    return;
  }
  if (announced_.insert(robot).second) {
    if (!robots_.count(robot)) {
      // A robot spawned after the start: what its controller sent before now is taken as arrived.
      attachRobot(robot);
      robots_[robot].speed = msg->speed_commands;
      robots_[robot].speaker = msg->speaker_commands;
    }
    ROS_INFO("simulator: lockstep: the controller of %s joined (%zu of %d awaited)", robot.c_str(),
             announced_.size(), params_.controllers);
  }
  watch(robot, msg->channel);
  waiting_[robot] = Waiter{*msg, event.getPublisherName(), SteadyClock::now()};
}

void LockstepGate::attachRobot(const std::string& robot) {
  RobotState& r = robots_[robot];
  r.hold_pub = nh_.advertise<sbot_msgs::LockstepHold>("/" + robot + "/lockstep_hold", 10, /*latch=*/true);
  const std::string ns = "/" + robot + "/";
  // Counted beside the robot interface's own subscriptions: one connection delivers to both.
  r.subs.push_back(nh_.subscribe<sbot_msgs::TrackSpeed>(ns + "cmd_speed", 100,
      [this, robot](const sbot_msgs::TrackSpeed::ConstPtr&) { ++robots_[robot].speed; }));
  r.subs.push_back(nh_.subscribe<std_msgs::Float64>(ns + "speaker", 100,
      [this, robot](const std_msgs::Float64::ConstPtr&) { ++robots_[robot].speaker; }));
}

void LockstepGate::watch(const std::string& robot, const std::string& channel) {
  std::vector<std::string>& channels = robots_[robot].channels;
  if (std::find(channels.begin(), channels.end(), channel) != channels.end()) return;
  if (!trackedChannels().count(channel)) {
    if (unknown_channels_.insert(channel).second) {
      std::string known;
      for (const std::string& c : trackedChannels()) known += (known.empty() ? "" : ", ") + c;
      ROS_WARN("simulator: lockstep: a controller waits on '%s', which the simulator does not track; "
               "it is not held for (known: %s)", channel.c_str(), known.c_str());
    }
    return;
  }
  channels.push_back(channel);
}

void LockstepGate::publishHold(const std::string& robot, const ros::Time& stamp) {
  RobotState& r = robots_[robot];
  if (r.hold_sent >= stamp) return;
  r.hold_sent = stamp;
  sbot_msgs::LockstepHold h;
  h.stamp = stamp;
  for (const std::string& c : r.channels) {
    h.topics.push_back(c);
    h.latest.push_back(publicationStamps().latest(robot, c));
  }
  r.hold_pub.publish(h);
}

LockstepGate::Hold LockstepGate::holdFor(const Waiter& w, ros::Time* published) const {
  const sbot_msgs::ControllerSync& s = w.sync;
  *published = publicationStamps().latest(s.robot, s.channel);
  const auto r = robots_.find(s.robot);
  if (r != robots_.end() && (r->second.speed < s.speed_commands || r->second.speaker < s.speaker_commands))
    return Hold::Commands;
  if (*published > s.after) return Hold::Message;
  return s.new_subscription && !publicationStamps().listened(s.robot, s.channel, w.node) ? Hold::Subscribing
                                                                                        : Hold::None;
}

std::string LockstepGate::describe(const Waiter& w, Hold why, const ros::Time& published) const {
  const sbot_msgs::ControllerSync& s = w.sync;
  char text[256];
  if (why == Hold::Commands) {
    const RobotState& r = robots_.at(s.robot);
    std::snprintf(text, sizeof(text), "commands in flight (cmd_speed %llu of %llu, speaker %llu of %llu received)",
                  static_cast<unsigned long long>(r.speed), static_cast<unsigned long long>(s.speed_commands),
                  static_cast<unsigned long long>(r.speaker), static_cast<unsigned long long>(s.speaker_commands));
  } else if (why == Hold::Subscribing) {
    std::snprintf(text, sizeof(text), "has subscribed to %s, but the simulator's publisher has not seen %s "
                  "connect", s.channel.c_str(), w.node.c_str());
  } else {
    std::snprintf(text, sizeof(text), "has %s stamped %.3f s to read (it last read %.3f s)", s.channel.c_str(),
                  published.toSec(), s.after.toSec());
  }
  return text;
}

bool LockstepGate::mayStep() {
  const auto now = SteadyClock::now();
  bool hold = static_cast<int>(announced_.size()) < params_.controllers;
  if (hold && secondsBetween(last_waiting_log_, now) > 5.0) {
    last_waiting_log_ = now;
    std::string joined;
    for (const std::string& r : announced_) joined += (joined.empty() ? "" : ", ") + r;
    ROS_WARN("simulator: lockstep: not stepping until %d controllers have announced themselves (~lockstep_controllers); "
             "%zu so far (%s)", params_.controllers, announced_.size(), joined.empty() ? "none" : joined.c_str());
  }
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    // A controller that was connected to the topic it waits on and no longer is has ended: its
    // process closed the connection (kill -9 included), and it will never sync again.
    const Waiter& w = it->second;
    std::set<std::string>& connected = robots_[it->first].connected;
    const std::string link = w.node + " " + w.sync.channel;
    if (publicationStamps().listened(w.sync.robot, w.sync.channel, w.node)) {
      connected.insert(link);
    } else if (connected.erase(link)) {
      ROS_WARN("simulator: lockstep: dropping the controller of %s (%s): its connection to %s/%s closed (its "
               "process ended); the simulation no longer waits for it", it->first.c_str(), w.node.c_str(),
               it->first.c_str(), w.sync.channel.c_str());
      ++dropped_;
      it = waiting_.erase(it);
      continue;
    }
    ros::Time published;
    const Hold why = holdFor(it->second, &published);
    if (why == Hold::None) {
      ++it;
      continue;
    }
    if (secondsBetween(it->second.since, now) > params_.timeout) {
      ROS_WARN("simulator: lockstep: dropping the controller of %s: no sync for %.1f s wall while it %s; "
               "the simulation no longer waits for it (~lockstep_timeout %.1f s)", it->first.c_str(),
               secondsBetween(it->second.since, now), describe(it->second, why, published).c_str(), params_.timeout);
      ++dropped_;
      it = waiting_.erase(it);
      continue;
    }
    hold = true;
    // Holding for a new message: the controller wakes at its stamp and acts there.
    if (published > it->second.sync.after) publishHold(it->first, published);
    ++it;
  }
  if (hold && !was_holding_) {
    hold_start_ = now;
    ++holds_;
  } else if (!hold && was_holding_) {
    held_wall_ += secondsBetween(hold_start_, now);
  }
  was_holding_ = hold;
  return !hold;
}

std::string LockstepGate::summary() const {
  char line[200];
  std::snprintf(line, sizeof(line), "lockstep: %zu controllers, held %llu times for %.2f s wall, %d dropped",
                announced_.size(), static_cast<unsigned long long>(holds_), held_wall_, dropped_);
  return line;
}

}  // namespace sbot_node
