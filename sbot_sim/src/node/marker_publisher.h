// /sim/markers: a visualization_msgs/MarkerArray of the simulated world for rviz, in frame `world`.
//
//  - every robot's model: one marker per collision shape of every link (sphere, cylinder, box) at the
//    link's simulated pose, coloured with the URDF visual material of the link (grey if none);
//  - every robot's trail: a LINE_STRIP of its last ~trail_length base positions, sampled at the
//    marker rate, one hue per robot;
//  - the terrain: the static boxes (walls, steps, ramps) and, for rough terrain, the height map as a
//    TRIANGLE_LIST. The terrain does not move, so it is not sent every time: each new subscriber gets
//    it once on connecting, and every subscriber again every kTerrainRefresh seconds (sim time).
//
// Parameters (private, of the simulator node):
//   ~marker_rate   [Hz, sim time] default 10; 0 disables the topic
//   ~trail_length  [samples] default 200; 0 = no trails
//
// The message is only built when /sim/markers has subscribers; trails are sampled regardless (one
// pose per robot at the marker rate), so a late rviz still shows where the robots have been.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>

#include <ros/ros.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include "sbot_sim/core/world.h"

namespace sbot_node {

class MarkerPublisher {
 public:
  /// Reads ~marker_rate and ~trail_length from `pnh` and, unless disabled, advertises /sim/markers.
  MarkerPublisher(ros::NodeHandle nh, ros::NodeHandle pnh);

  bool enabled() const { return rate_ > 0; }
  double rate() const { return rate_; }

  /// Call after every step with the world and the ROS time of its state [s]: samples the trails and
  /// publishes whenever `sim_time` crosses a multiple of 1 / marker_rate.
  void update(sbot::World& world, double sim_time);
  /// Forget the trails (the world was rebuilt: robots jumped back to their start poses).
  void clearTrails() { trails_.clear(); }
  std::size_t trailPoints(const std::string& robot) const;

  /// The full marker array of `world` at `stamp` (models, trails, and the terrain if requested).
  visualization_msgs::MarkerArray build(sbot::World& world, const ros::Time& stamp, bool with_terrain);
  /// The terrain's static markers only (built once: the terrain of a scenario never changes).
  const visualization_msgs::MarkerArray& terrain(const sbot::World& world);

 private:
  struct Trail {
    std::deque<geometry_msgs::Point> points;
    int index = 0;  ///< the robot's index, for its hue
  };
  const std::map<std::string, std_msgs::ColorRGBA>& linkColours(const sbot::RobotDescription& d);
  void onConnect(const ros::SingleSubscriberPublisher& pub);

  double rate_ = 10;
  int trail_length_ = 200;
  std::string frame_ = "world";
  ros::Publisher pub_;
  std::int64_t last_tick_ = -1;
  double last_terrain_time_ = -1e9;
  std::map<std::string, Trail> trails_;  ///< by robot name
  std::map<std::string, std::map<std::string, std_msgs::ColorRGBA>> colours_;  ///< by URDF path/level
  // The terrain markers, cached for the connect callback, which sends them to a new subscriber.
  visualization_msgs::MarkerArray terrain_;
  bool terrain_built_ = false;
  ros::Time last_stamp_;
};

}  // namespace sbot_node
