// Lock-step with the sbot.h controllers (~lockstep true): the simulator holds its clock while a
// controller has not yet read the sensor message it is waiting for, or its commands are still in
// flight, so a run with ROS-node controllers is repeatable whatever the machine's load.
//
// Protocol (sbot_msgs/ControllerSync on /sim/controller_sync, sent by libsbot_ros whenever a getter
// blocks): "robot R waits for a message on R/<channel> stamped later than <after>; it has published
// <speed_commands> cmd_speed and <speaker_commands> speaker messages so far". The gate listens to the
// commands inside the simulator (a subscriber of cmd_speed receives exactly what the robot interface
// applied), reads what the node published from publicationStamps(), and:
//   * holds while fewer than ~lockstep_controllers controllers have announced themselves;
//   * holds while the simulator has published R/<channel> later than <after> (the controller has a
//     message to read and will answer with a new sync), or fewer commands have arrived than the
//     controller says it sent (ROS orders messages per topic, not across topics);
//   * holds, for a sync marked new_subscription, until the node's publisher of R/<channel> has the
//     controller (the sync's sender) among its subscribers (publicationStamps().listened): the sync
//     can overtake the new connection, and topics are published only to subscribers, so otherwise
//     the first message the controller gets would depend on how fast its connection completed (a
//     phototaxis run differed by 12.5 mm about once in 8 full test suites);
//   * when it starts holding for a new message, tells the controller on R/lockstep_hold
//     (sbot_msgs/LockstepHold) what it has published on each topic the controller reads up to then:
//     the controller's getters wait for exactly that, whatever order the topics' messages arrive in;
//   * drops a controller whose process has ended (killed, crashed) as soon as its connection to the
//     topic it waits on closes: the node's publisher of R/<channel> loses it from its subscribers
//     (publicationStamps().listened; a kill -9'ed controller is dropped within a fraction of a
//     second, test/lockstep/test_lockstep_repeatable.py), with a warning naming it;
//   * drops a controller that holds the clock for ~lockstep_timeout wall seconds without a new sync
//     (hung, or busy-looping without reading a sensor), with a warning naming it.
// Between two sensor messages the controllers are blocked and the simulator runs freely, so every
// command a controller computes from the message stamped t applies at the first step after t.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sbot_msgs/ControllerSync.h>
#include <sbot_msgs/LockstepHold.h>

namespace sbot_node {

struct LockstepParams {
  bool enabled = false;     ///< ~lockstep
  int controllers = 0;      ///< ~lockstep_controllers: announcements awaited before the first step
  double timeout = 10.0;    ///< ~lockstep_timeout [s wall]: a controller holding longer is dropped
};

class LockstepGate {
 public:
  /// Why a robot name is not in the simulation ("" when it is), e.g. "unknown robot 'sbot_99' (robots:
  /// sbot_0..sbot_2)".
  using RobotCheck = std::function<std::string(const std::string& robot)>;

  /// `robots`: the robots present at start; their commands are counted from now on, before any
  /// controller connects. `check`: syncs naming a robot it refuses are ignored, with a warning.
  LockstepGate(ros::NodeHandle& nh, const LockstepParams& params, const std::vector<std::string>& robots,
               RobotCheck check);

  /// May the simulator take its next step? Call after serving the callback queue.
  bool mayStep();

  /// For the run summary, e.g. "lockstep: 3 controllers, held 1200 times for 4.2 s wall, 0 dropped".
  std::string summary() const;

 private:
  struct Waiter {
    sbot_msgs::ControllerSync sync;
    std::string node;  ///< the controller's ROS name (the sync's publisher)
    std::chrono::steady_clock::time_point since;  ///< when this sync arrived
  };
  struct RobotState {
    std::uint64_t speed = 0, speaker = 0;  ///< cmd_speed / speaker messages received
    std::vector<ros::Subscriber> subs;     ///< their counters
    std::vector<std::string> channels;     ///< topics under the robot its controller reads
    ros::Publisher hold_pub;               ///< <robot>/lockstep_hold (latched)
    ros::Time hold_sent;                   ///< stamp of the last hold told
    /// "<controller node> <channel>" pairs seen connected: the node's publisher of robot/channel
    /// has had that controller among its subscribers.
    std::set<std::string> connected;
  };
  enum class Hold { None, Commands, Subscribing, Message };

  void onSync(const ros::MessageEvent<const sbot_msgs::ControllerSync>& event);
  /// Count the cmd_speed and speaker messages that reach `robot` and advertise its lockstep_hold
  /// (once per robot).
  void attachRobot(const std::string& robot);
  /// Tell the controller of `robot` that the simulator holds at `stamp`.
  void publishHold(const std::string& robot, const ros::Time& stamp);
  /// Include robot/channel in the robot's holds (once); warn about a topic the node does not track.
  void watch(const std::string& robot, const std::string& channel);
  /// Whether the controller of `w` holds the clock, and why; `published` gets the stamp of the
  /// latest message on the topic it waits for.
  Hold holdFor(const Waiter& w, ros::Time* published) const;
  /// `why` in words, for the warning when the controller of `w` is dropped.
  std::string describe(const Waiter& w, Hold why, const ros::Time& published) const;

  ros::NodeHandle nh_;
  LockstepParams params_;
  RobotCheck check_;
  std::set<std::string> refused_;                     ///< robot names warned about once each
  ros::Subscriber sync_sub_;
  std::map<std::string, Waiter> waiting_;             ///< robot -> its controller's last sync
  std::map<std::string, RobotState> robots_;          ///< robot -> commands received, topics read
  std::set<std::string> announced_;                   ///< robots whose controller ever synced
  std::set<std::string> unknown_channels_;            ///< warned once each
  bool was_holding_ = false;
  std::chrono::steady_clock::time_point hold_start_;
  std::uint64_t holds_ = 0;
  double held_wall_ = 0;
  int dropped_ = 0;
  std::chrono::steady_clock::time_point last_waiting_log_;
};

}  // namespace sbot_node
