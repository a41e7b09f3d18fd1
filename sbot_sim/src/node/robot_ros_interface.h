// The ROS face of one simulated s-bot: its command topics, state topics and per-robot services, all
// in the namespace <robot name> (e.g. sbot_0/cmd_speed). Physics stays in sbot::Robot; this class only
// converts messages to API calls and back. It outlives the sbot::Robot it wraps: after /sim/reset the
// simulator rebuilds the world and re-binds every interface to the new robot of the same name.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sbot_msgs/SetTurret.h>
#include <sbot_msgs/TrackSpeed.h>

#include "publication_stamps.h"
#include "sbot_sim/core/robot.h"

namespace sbot_node {

/// Rate-limits one kind of warning of one robot, in wall time (ROS_WARN_THROTTLE is per call site,
/// so it would hide robot 2's warning behind robot 1's, and it follows sim time).
class WarnThrottle {
 public:
  explicit WarnThrottle(double period_s = 1.0) : period_(period_s) {}
  bool ready();

 private:
  double period_;
  std::chrono::steady_clock::time_point last_{};
  bool fired_ = false;
};

class RobotRosInterface {
 public:
  /// `nh` is the simulator's public node handle; topics live in nh/<robot name>/. With
  /// `set_description_params` the interface also sets <robot name>/robot_description (the level's
  /// URDF) and <robot name>/tf_prefix for a robot_state_publisher started in that namespace.
  RobotRosInterface(ros::NodeHandle nh, sbot::Robot& robot, bool set_description_params = false);
  ~RobotRosInterface();
  RobotRosInterface(const RobotRosInterface&) = delete;
  RobotRosInterface& operator=(const RobotRosInterface&) = delete;

  const std::string& name() const { return name_; }
  /// Point at a (new) robot of the same name, e.g. after the world was rebuilt.
  void bind(sbot::Robot& robot);
  /// Forget the robot (its world is about to be destroyed); commands are ignored until bind().
  void unbind() { robot_ = nullptr; }

  /// Publish ground_truth, joint_states, track_state, turret/state stamped `stamp`, and append the
  /// world -> <name>/<root link> transform to `transforms` (the simulator sends them all at once).
  void publishState(const ros::Time& stamp, std::vector<geometry_msgs::TransformStamped>& transforms);

  /// Track separation used by cmd_vel [m].
  double trackSeparation() const { return track_separation_; }

 private:
  void onCmdSpeed(const sbot_msgs::TrackSpeed::ConstPtr& msg);
  void onCmdVel(const geometry_msgs::Twist::ConstPtr& msg);
  bool onSetTurret(sbot_msgs::SetTurret::Request& req, sbot_msgs::SetTurret::Response& res);
  void setDescriptionParams();

  ros::NodeHandle nh_;  ///< in the robot's namespace
  sbot::Robot* robot_ = nullptr;
  std::string name_;
  std::string level_;
  std::string base_frame_;  ///< <name>/base_link
  std::string root_frame_;  ///< <name>/<URDF root link>, the child of the world -> robot transform
  std::string root_link_;
  double track_separation_ = 0.082;  ///< [m]
  bool set_description_params_ = false;

  ros::Subscriber cmd_speed_sub_, cmd_vel_sub_;
  /// Who subscribes to the state topics (publishState asks; for the three controllers read, the
  /// lock-step gate too). Declared before the publishers whose callbacks fill them, so they outlive them.
  SubscriberRoster ground_truth_subs_, joint_states_subs_, track_state_subs_, turret_state_subs_;
  ros::Publisher ground_truth_pub_, joint_states_pub_, track_state_pub_, turret_state_pub_;
  ros::Publisher model_level_pub_;
  ros::ServiceServer set_turret_srv_;
  WarnThrottle speed_clamp_warn_, vel_clamp_warn_, vel_invalid_warn_;
};

}  // namespace sbot_node
