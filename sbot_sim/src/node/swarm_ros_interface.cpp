#include "swarm_ros_interface.h"

#include "robot_lookup.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <sbot_msgs/SwarmGraph.h>
#include <visualization_msgs/MarkerArray.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/swarm/swarm_graph.h"

namespace sbot_node {

namespace {

std_msgs::ColorRGBA rgba(float r, float g, float b, float a = 1.0f) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

geometry_msgs::Point point(const sbot::Vec3& v, double dz = 0) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z() + dz;
  return p;
}

/// Hue per component (golden-angle steps), full saturation.
std_msgs::ColorRGBA componentColour(std::uint32_t c) {
  const double h = std::fmod(c * 0.618033988749895, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  const int i = static_cast<int>(h);
  const double rgb[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
  return rgba(rgb[i][0], rgb[i][1], rgb[i][2], 0.9f);
}

constexpr double kMarkerHeight = 0.12;  // [m] above base_link: above the turret, below the camera top

}  // namespace

SwarmRosInterface::SwarmRosInterface(ros::NodeHandle nh, ros::NodeHandle pnh, std::unique_ptr<sbot::World>& world,
                                     std::vector<std::unique_ptr<RobotRosInterface>>& robots,
                                     bool set_description_params)
    : nh_(nh), world_(world), robots_(robots), set_description_params_(set_description_params) {
  pnh.param("graph_rate", rate_, 10.0);
  if (!std::isfinite(rate_) || rate_ < 0) {
    ROS_WARN("simulator: ~graph_rate must be >= 0 Hz (0 = off), got %g: using 10", rate_);
    rate_ = 10;
  }
  if (rate_ > 0) {
    graph_pub_ = nh_.advertise<sbot_msgs::SwarmGraph>("/swarm/graph", 10);
    markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("/swarm/graph_markers", 2);
  }
  ros::NodeHandle sim(nh_, "sim");
  set_level_srv_ = sim.advertiseService("set_model_level", &SwarmRosInterface::onSetModelLevel, this);
  spawn_srv_ = sim.advertiseService("spawn", &SwarmRosInterface::onSpawn, this);
  delete_srv_ = sim.advertiseService("delete", &SwarmRosInterface::onDelete, this);
}

void SwarmRosInterface::update(double sim_time) {
  if (rate_ <= 0 || !world_) return;
  const auto tick = static_cast<std::int64_t>(std::floor(sim_time * rate_ + 1e-6));
  if (tick == last_tick_) return;
  last_tick_ = tick;
  publish(sim_time);
}

void SwarmRosInterface::publish(double sim_time) {
  const sbot::swarm::SwarmGraph g = sbot::swarm::computeSwarmGraph(*world_);
  const ros::Time stamp(sim_time);
  sbot_msgs::SwarmGraph m;
  m.header.stamp = stamp;
  m.header.frame_id = "world";
  m.n = static_cast<std::uint32_t>(g.n);
  m.names = g.names;
  for (std::size_t i = 0; i < g.n; ++i) m.positions.push_back(point(g.positions[i]));
  m.headings = g.headings;
  m.connections = g.connections;
  m.component = g.component;
  graph_pub_.publish(m);

  if (markers_pub_.getNumSubscribers() == 0) return;
  visualization_msgs::MarkerArray arr;
  auto lines = [&](int id, const char* ns, std::uint8_t kind, const std_msgs::ColorRGBA& colour) {
    visualization_msgs::Marker mk;
    mk.header.stamp = stamp;
    mk.header.frame_id = "world";
    mk.ns = ns;
    mk.id = id;
    mk.type = visualization_msgs::Marker::LINE_LIST;
    mk.action = visualization_msgs::Marker::ADD;
    mk.pose.orientation.w = 1;
    mk.scale.x = 0.012;
    mk.color = colour;
    for (std::size_t i = 0; i < g.n; ++i)
      for (std::size_t j = 0; j < g.n; ++j)
        if (g.connection(i, j) == kind) {
          mk.points.push_back(point(g.positions[i], kMarkerHeight));
          mk.points.push_back(point(g.positions[j], kMarkerHeight));
        }
    // An empty LINE_LIST is invalid for rviz: delete instead.
    if (mk.points.empty()) mk.action = visualization_msgs::Marker::DELETE;
    arr.markers.push_back(mk);
  };
  lines(0, "swarm_front_gripper", sbot::swarm::kFrontGripper, rgba(1.0f, 0.55f, 0.0f));
  lines(1, "swarm_side_arm", sbot::swarm::kSideArm, rgba(0.0f, 0.8f, 1.0f));
  visualization_msgs::Marker nodes;
  nodes.header.stamp = stamp;
  nodes.header.frame_id = "world";
  nodes.ns = "swarm_nodes";
  nodes.id = 2;
  nodes.type = visualization_msgs::Marker::SPHERE_LIST;
  nodes.action = g.n ? visualization_msgs::Marker::ADD : visualization_msgs::Marker::DELETE;
  nodes.pose.orientation.w = 1;
  nodes.scale.x = nodes.scale.y = nodes.scale.z = 0.03;
  for (std::size_t i = 0; i < g.n; ++i) {
    nodes.points.push_back(point(g.positions[i], kMarkerHeight));
    nodes.colors.push_back(componentColour(g.component[i]));
  }
  nodes.color = rgba(1, 1, 1);
  arr.markers.push_back(nodes);
  markers_pub_.publish(arr);
}

bool SwarmRosInterface::knownLevel(const std::string& level) {
  const auto& levels = sbot::modelLevels();
  return std::find(levels.begin(), levels.end(), level) != levels.end();
}

std::string SwarmRosInterface::sensorSummary(const sbot::RobotDescription& d) {
  std::ostringstream s;
  s << "ir:" << d.extraOr("ir_model", "?");
  s << (d.extraOr("ground_sensors", "false") == "true" ? " ground" : "");
  s << " camera:" << d.extraOr("camera", "?");
  s << " light_ring:" << d.extraOr("light_ring", "?");
  s << " sound:" << d.extraOr("sound_model", "?");
  s << " gripper:" << d.extraOr("gripper", "none");
  s << (d.extraOr("side_arm", "false") == "true" ? " side_arm" : "");
  return s.str();
}

bool SwarmRosInterface::onSetModelLevel(sbot_msgs::SetModelLevel::Request& req,
                                        sbot_msgs::SetModelLevel::Response& res) {
  res.success = false;
  sbot::Robot* robot = lookupRobot(world_.get(), req.robot, res.message);
  if (!robot) return true;
  if (!knownLevel(req.level)) {
    res.message = "unknown model level '" + req.level + "' (levels: fast, simple, basic, medium, detailed)";
    return true;
  }
  const std::string from = robot->level();
  try {
    const sbot::RobotDescription& d = sbot::loadLevel(req.level);
    if (from != req.level) world_->switchLevel(req.robot, d);
  } catch (const std::exception& e) {
    res.message = e.what();
    ROS_WARN("simulator: /sim/set_model_level %s -> %s refused: %s", req.robot.c_str(), req.level.c_str(), e.what());
    return true;
  }
  for (auto& iface : robots_)
    if (iface->name() == req.robot) iface->bind(*robot);  // refresh; republishes <robot>/model_level
  if (from != req.level)
    for (auto& hook : after_switch) hook(*robot);
  res.success = true;
  res.message = req.robot + ": " + from + " -> " + req.level + (from == req.level ? " (unchanged)" : "") +
                "; available: " + sensorSummary(robot->description());
  ROS_INFO("simulator: t=%.3f s %s", world_->time(), res.message.c_str());
  republish();
  return true;
}

bool SwarmRosInterface::onSpawn(sbot_msgs::Spawn::Request& req, sbot_msgs::Spawn::Response& res) {
  res.success = false;
  if (!world_) {
    res.message = "no world (a reset failed)";
    return true;
  }
  const std::string name_problem = sbot::robotNameProblem(req.name);
  if (!name_problem.empty()) {
    res.message = name_problem;
    return true;
  }
  if (world_->findRobot(req.name)) {
    res.message = "a robot named '" + req.name + "' exists already";
    return true;
  }
  if (!knownLevel(req.level)) {
    res.message = "unknown model level '" + req.level + "' (levels: fast, simple, basic, medium, detailed)";
    return true;
  }
  for (const auto& f : {std::make_pair("x", req.x), std::make_pair("y", req.y), std::make_pair("yaw", req.yaw)}) {
    if (!std::isfinite(f.second)) {
      res.message = std::string("field ") + f.first + " is not finite";
      return true;
    }
  }
  if (const std::string problem = sbot::angleProblem(req.yaw); !problem.empty()) {
    res.message = "field yaw " + problem;
    return true;
  }
  sbot::Robot* robot = nullptr;
  try {
    const sbot::RobotDescription& level = sbot::loadLevel(req.level);
    const std::string gravity = sbot::gravityProblem(level, world_->config().gravity);
    if (!gravity.empty()) {
      res.message = gravity;
      return true;
    }
    robot = &world_->addRobot(level, sbot::Pose2D{req.x, req.y, req.yaw}, req.name);
    // Spawned inside another robot, the contacts would throw the two apart.
    if (const sbot::World::Overlap o = world_->deepestOverlap(*robot, true); o.depth > sbot::World::kPlacementTolerance) {
      world_->removeRobot(req.name);
      std::ostringstream why;
      why << "'" << req.name << "' there would overlap " << o.with << " by " << std::fixed << std::setprecision(3)
          << o.depth << " m (at most " << sbot::World::kPlacementTolerance << " m): not spawned";
      res.message = why.str();
      return true;
    }
  } catch (const std::exception& e) {
    res.message = e.what();
    return true;
  }
  robots_.push_back(std::make_unique<RobotRosInterface>(nh_, *robot, set_description_params_));
  for (auto& hook : after_spawn) hook(*robot);
  res.success = true;
  res.message = "spawned " + req.name + " (" + req.level + ") at (" + std::to_string(req.x) + ", " +
                std::to_string(req.y) + "), yaw " + std::to_string(req.yaw);
  ROS_INFO("simulator: t=%.3f s %s", world_->time(), res.message.c_str());
  republish();
  return true;
}

bool SwarmRosInterface::onDelete(sbot_msgs::Delete::Request& req, sbot_msgs::Delete::Response& res) {
  res.success = false;
  sbot::Robot* robot = lookupRobot(world_.get(), req.name, res.message);
  if (!robot) return true;
  for (auto& hook : before_delete) hook(*robot);
  // Its topics and services go with it: kept, every robot ever spawned under a new name held ~50
  // topics and 200 kB for good. Subscribers keep their subscriptions by name, so a /sim/spawn of the
  // same name (or /sim/reset, for a robot of the scenario) brings the robot back on the same topics.
  robots_.erase(std::remove_if(robots_.begin(), robots_.end(),
                               [&](const std::unique_ptr<RobotRosInterface>& iface) { return iface->name() == req.name; }),
                robots_.end());
  try {
    world_->removeRobot(req.name);
  } catch (const std::exception& e) {
    res.message = e.what();
    return true;
  }
  res.success = true;
  res.message = "deleted " + req.name;
  ROS_INFO("simulator: t=%.3f s %s", world_->time(), res.message.c_str());
  republish();
  return true;
}

}  // namespace sbot_node
