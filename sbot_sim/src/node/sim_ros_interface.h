// The simulator node's wiring: parameters, the sbot::World built from a scenario, the fixed-step loop
// with /clock, the /sim/* control services and one RobotRosInterface per robot.
//
// Threading: none. The loop alternates ros::getGlobalCallbackQueue()->callAvailable() and
// World::step(), so every command received between two steps applies at the next step and a run
// depends only on what arrived before which step.
#pragma once

#include <chrono>
#include <csignal>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sbot_msgs/SetPose.h>
#include <sbot_msgs/Step.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>

#include "lockstep_gate.h"
#include "marker_publisher.h"
#include "robot_ros_interface.h"
#include "swarm_ros_interface.h"
#include "modules_ros_interface.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/world.h"

namespace sbot_node {

struct NodeParams {
  std::string scenario;          ///< ~scenario: path of the scenario YAML (required)
  int robots = -1;               ///< ~robots: robot count, -1 = the scenario's
  std::string level;             ///< ~level: model level of every robot, "" = the scenario's
  double real_time_factor = 1.0; ///< ~real_time_factor: 0 = as fast as possible, 1 = real time
  double duration = 0;           ///< ~duration [s simulated]: 0 = the scenario's (0 there = unlimited)
  double publish_rate = 50;      ///< ~publish_rate [Hz sim]: ground truth, joint/track/turret state, tf
  bool paused = false;           ///< ~paused: start paused
  std::string effects;           ///< ~effects: effects file (sbot_calibrate fit); replaces the scenario's `effects`
  /// ~set_description_params: also set <robot>/robot_description and <robot>/tf_prefix
  bool set_description_params = false;
  LockstepParams lockstep;       ///< ~lockstep, ~lockstep_controllers, ~lockstep_timeout (lockstep_gate.h)
};

class SimRosInterface {
 public:
  SimRosInterface();
  ~SimRosInterface();

  /// Read parameters, load the scenario, build the world, advertise everything. On error logs
  /// ROS_FATAL (naming file and field for scenario errors) and returns false.
  bool init();
  /// The simulation loop. Returns the process exit code.
  int run();
  /// Signal handler (SIGINT, SIGTERM): the loop stops after the current step.
  static void requestStop(int signal);

 private:
  bool readParams();
  /// Build a fresh world from scenario_ (initial state is a function of the scenario alone).
  std::unique_ptr<sbot::World> buildWorld() const;
  void stepOnce();
  void publishClock();
  void publishStates();
  double simTime() const { return time_offset_ + (world_ ? world_->time() : 0.0); }
  ros::Time stamp() const { return ros::Time(simTime()); }
  bool durationReached() const;
  void resetPacing();
  double wallUntilNextStep();
  void logSummary(const std::string& reason) const;

  bool onPause(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onUnpause(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onStep(sbot_msgs::Step::Request& req, sbot_msgs::Step::Response& res);
  bool onSetPose(sbot_msgs::SetPose::Request& req, sbot_msgs::SetPose::Response& res);

  static volatile std::sig_atomic_t stop_requested_;

  ros::NodeHandle nh_, pnh_;
  NodeParams params_;
  sbot::Scenario scenario_;
  double end_time_ = 0;  ///< [s] ROS sim time at which to stop, 0 = never

  std::unique_ptr<sbot::World> world_;
  std::vector<std::unique_ptr<RobotRosInterface>> robots_;

  // ROS time = time_offset_ + world time. /sim/reset restarts the world at 0 but keeps ROS time
  // monotonic (tf buffers, rosbag and rospy.Rate dislike a clock that jumps back).
  double time_offset_ = 0;
  std::uint64_t total_steps_ = 0;      ///< steps since start, over resets (+1 per reset)
  std::int64_t last_publish_tick_ = 0; ///< floor(total_steps_ * step * publish_rate) last published
  bool paused_ = false;
  std::uint64_t reset_count_ = 0;

  // Real-time pacing.
  std::chrono::steady_clock::time_point pace_wall_;
  double pace_sim_ = 0;
  std::chrono::steady_clock::time_point run_start_;
  double run_start_sim_ = 0;
  double paused_wall_ = 0;  ///< [s wall] spent paused (stepping through /sim/step included)

  ros::Publisher clock_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  std::unique_ptr<MarkerPublisher> markers_;  ///< /sim/markers (~marker_rate, ~trail_length)
  /// /swarm/graph(_markers) (~graph_rate), /sim/set_model_level, /sim/spawn, /sim/delete
  std::unique_ptr<SwarmRosInterface> swarm_;
  /// Sensors and actuator modules of every robot (+ /sim/set_lamp, /sim/set_ambient_light)
  std::unique_ptr<ModulesRosInterface> modules_;
  /// Holds the clock for the sbot.h controllers (~lockstep); null when off
  std::unique_ptr<LockstepGate> lockstep_;
  ros::ServiceServer pause_srv_, unpause_srv_, reset_srv_, step_srv_, set_pose_srv_;
};

}  // namespace sbot_node
