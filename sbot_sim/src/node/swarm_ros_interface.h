// The swarm side of the simulator node (seed 2.1.3, 2.3):
//
//   /swarm/graph          sbot_msgs/SwarmGraph at ~graph_rate [Hz, sim time] (default 10; 0 = off):
//                         names, positions, headings, connection matrix (0 none, 1 front gripper,
//                         2 side arm), connected components (core/swarm/swarm_graph.h)
//   /swarm/graph_markers  visualization_msgs/MarkerArray, frame world, same rate, only built while
//                         subscribed: a LINE_LIST per connection kind between connected robots'
//                         turrets (front gripper orange, side arm cyan) and a sphere per robot
//                         coloured by component
//   /sim/set_model_level  sbot_msgs/SetModelLevel: switch a robot's model level in place, within
//                         the step (sbot::Robot::switchDescription: pose, velocities, joint angles,
//                         commands and connections carry over). Republishes the latched
//                         <robot>/model_level; the response names the sensors the new level has.
//   /sim/spawn            sbot_msgs/Spawn: add a robot resting on the terrain at (x, y, yaw)
//   /sim/delete           sbot_msgs/Delete: remove a robot (and its connections); its topics stay
//                         advertised but silent until /sim/reset or a /sim/spawn of that name
//
// Unknown robots or levels, duplicate names, non-finite poses and incompatible levels (Fast with a
// full-size level) give success=false with a message; nothing is changed then. Spawned robots are
// not part of the scenario: /sim/reset rebuilds the scenario's robots only.
//
// Other per-robot parts of the node (sensors, actuators) that keep a reference to an sbot::Robot
// register hooks: before_delete runs before the robot is destroyed, after_spawn once it exists,
// after_switch once it was rebuilt at a new level (the sbot::Robot object is the same; its bodies
// and joints are new).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sbot_msgs/Delete.h>
#include <sbot_msgs/SetModelLevel.h>
#include <sbot_msgs/Spawn.h>

#include "robot_ros_interface.h"
#include "sbot_sim/core/world.h"

namespace sbot_node {

class SwarmRosInterface {
 public:
  using RobotHook = std::function<void(sbot::Robot&)>;

  /// `world` and `robots` are the simulator's own (the world may be rebuilt by /sim/reset).
  SwarmRosInterface(ros::NodeHandle nh, ros::NodeHandle pnh, std::unique_ptr<sbot::World>& world,
                    std::vector<std::unique_ptr<RobotRosInterface>>& robots, bool set_description_params);

  /// Call after every step with the ROS time of the state [s]: publishes at ~graph_rate.
  void update(double sim_time);
  /// Publish at the next update (after a reset).
  void republish() { last_tick_ = -1; }
  double rate() const { return rate_; }

  std::vector<RobotHook> before_delete, after_spawn, after_switch;

  /// What a level offers (from its sidecar), e.g. "ir:raytrace ground camera:raw gripper:jaws side_arm".
  static std::string sensorSummary(const sbot::RobotDescription& d);

 private:
  bool onSetModelLevel(sbot_msgs::SetModelLevel::Request& req, sbot_msgs::SetModelLevel::Response& res);
  bool onSpawn(sbot_msgs::Spawn::Request& req, sbot_msgs::Spawn::Response& res);
  bool onDelete(sbot_msgs::Delete::Request& req, sbot_msgs::Delete::Response& res);
  void publish(double sim_time);
  static bool knownLevel(const std::string& level);

  ros::NodeHandle nh_;
  std::unique_ptr<sbot::World>& world_;
  std::vector<std::unique_ptr<RobotRosInterface>>& robots_;
  bool set_description_params_;
  double rate_ = 10;
  std::int64_t last_tick_ = -1;
  ros::Publisher graph_pub_, markers_pub_;
  ros::ServiceServer set_level_srv_, spawn_srv_, delete_srv_;
};

}  // namespace sbot_node
