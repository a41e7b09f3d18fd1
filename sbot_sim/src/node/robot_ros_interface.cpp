#include "robot_ros_interface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <nav_msgs/Odometry.h>
#include <sbot_msgs/ModelLevel.h>
#include <sbot_msgs/TrackState.h>
#include <sbot_msgs/TurretState.h>
#include <sensor_msgs/JointState.h>

#include "ros_conversions.h"

namespace sbot_node {

namespace {

constexpr std::uint32_t kStateQueue = 100;

int clampInt(long v, int lo, int hi) { return static_cast<int>(std::min<long>(hi, std::max<long>(lo, v))); }

}  // namespace

bool WarnThrottle::ready() {
  auto now = std::chrono::steady_clock::now();
  if (fired_ && std::chrono::duration<double>(now - last_).count() < period_) return false;
  fired_ = true;
  last_ = now;
  return true;
}

RobotRosInterface::RobotRosInterface(ros::NodeHandle nh, sbot::Robot& robot, bool set_description_params)
    : nh_(nh, robot.name()), name_(robot.name()), set_description_params_(set_description_params) {
  base_frame_ = name_ + "/base_link";
  // Deep queues: as fast as possible, the simulator outpaces subscribers such as rosbag in bursts.
  ground_truth_pub_ = nh_.advertise<nav_msgs::Odometry>("ground_truth", kStateQueue, ground_truth_subs_.connected(),
                                                         ground_truth_subs_.disconnected());
  joint_states_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", kStateQueue, joint_states_subs_.connected(),
                                                              joint_states_subs_.disconnected());
  track_state_pub_ = nh_.advertise<sbot_msgs::TrackState>("track_state", kStateQueue, track_state_subs_.connected(),
                                                          track_state_subs_.disconnected());
  turret_state_pub_ = nh_.advertise<sbot_msgs::TurretState>("turret/state", kStateQueue, turret_state_subs_.connected(),
                                                            turret_state_subs_.disconnected());
  model_level_pub_ = nh_.advertise<sbot_msgs::ModelLevel>("model_level", 1, /*latch=*/true);
  // A node on the roster is connected, and publishState() publishes when anyone is (a level without
  // a turret publishes no turret/state: nothing to wait for).
  publicationStamps().watchSubscribers(name_, "ground_truth", [this](const std::string& n) { return ground_truth_subs_.has(n); });
  publicationStamps().watchSubscribers(name_, "track_state", [this](const std::string& n) { return track_state_subs_.has(n); });
  publicationStamps().watchSubscribers(name_, "turret/state", [this](const std::string& n) {
    return turret_state_subs_.has(n) || !robot_ || robot_->description().turret.joint.empty();
  });
  bind(robot);
  // Subscribers and services last: callbacks only run from the simulator's loop, but keep the
  // object complete before anything can reach it.
  cmd_speed_sub_ = nh_.subscribe("cmd_speed", 10, &RobotRosInterface::onCmdSpeed, this,
                                 ros::TransportHints().tcpNoDelay());
  cmd_vel_sub_ = nh_.subscribe("cmd_vel", 10, &RobotRosInterface::onCmdVel, this,
                               ros::TransportHints().tcpNoDelay());
  set_turret_srv_ = nh_.advertiseService("set_turret", &RobotRosInterface::onSetTurret, this);
}

RobotRosInterface::~RobotRosInterface() {
  for (const char* topic : {"ground_truth", "track_state", "turret/state"}) publicationStamps().forgetSubscribers(name_, topic);
}

void RobotRosInterface::bind(sbot::Robot& robot) {
  robot_ = &robot;
  const sbot::RobotDescription& d = robot.description();
  root_link_ = d.root_link.empty() ? std::string("base_link") : d.root_link;
  root_frame_ = name_ + "/" + root_link_;

  track_separation_ = robot.trackWidth();
  ROS_DEBUG("%s: track separation %.4f m", name_.c_str(), track_separation_);

  if (d.level != level_) {
    level_ = d.level;
    sbot_msgs::ModelLevel m;
    m.robot = name_;
    m.level = level_;
    model_level_pub_.publish(m);
    if (set_description_params_) setDescriptionParams();
  }
}

void RobotRosInterface::setDescriptionParams() {
  // robot_state_publisher 1.15 in this namespace finds both (it looks tf_prefix up with searchParam
  // and prefixes every frame: sbot_0/base_link, ...). Not for URDFs whose links are prefixed already.
  const sbot::RobotDescription& d = robot_->description();
  if (!d.urdf_xml.empty()) nh_.setParam("robot_description", d.urdf_xml);
  nh_.setParam("tf_prefix", name_);
}

void RobotRosInterface::onCmdSpeed(const sbot_msgs::TrackSpeed::ConstPtr& msg) {
  if (!robot_) return;
  bool clamped = robot_->setSpeed(msg->left, msg->right);
  if (clamped && speed_clamp_warn_.ready()) {
    const double unit = robot_->description().treels.speed_unit;
    long l = std::lround(robot_->requestedLeft() / unit), r = std::lround(robot_->requestedRight() / unit);
    ROS_WARN("%s/cmd_speed (%d, %d) out of range: limited to (%ld, %ld) units (API range [-127, 127], "
             "simulator limit +-%d)", name_.c_str(), msg->left, msg->right, l, r,
             robot_->description().treels.speed_limit_units);
  }
}

void RobotRosInterface::onCmdVel(const geometry_msgs::Twist::ConstPtr& msg) {
  if (!robot_) return;
  const std::pair<const char*, double> fields[] = {
      {"linear.x", msg->linear.x},   {"linear.y", msg->linear.y},   {"linear.z", msg->linear.z},
      {"angular.x", msg->angular.x}, {"angular.y", msg->angular.y}, {"angular.z", msg->angular.z}};
  for (const auto& f : fields) {
    if (!std::isfinite(f.second)) {
      if (vel_invalid_warn_.ready())
        ROS_WARN("%s/cmd_vel rejected: field %s is %f (the previous command stays in effect)",
                 name_.c_str(), f.first, f.second);
      return;
    }
  }
  // Differential drive: only linear.x and angular.z are meaningful for tracks.
  const double v = msg->linear.x, w = msg->angular.z;
  const double left = v - w * track_separation_ / 2.0;
  const double right = v + w * track_separation_ / 2.0;
  robot_->setTrackSpeeds(left, right);
  const auto& t = robot_->description().treels;
  const double limit = t.speed_limit_units * t.speed_unit;
  if ((std::abs(left) > limit + 1e-9 || std::abs(right) > limit + 1e-9) && vel_clamp_warn_.ready()) {
    ROS_WARN("%s/cmd_vel (v %.3f m/s, w %.3f rad/s) needs track speeds (%.3f, %.3f) m/s: limited to "
             "+-%.3f m/s (%d units)", name_.c_str(), v, w, left, right, limit, t.speed_limit_units);
  }
}

bool RobotRosInterface::onSetTurret(sbot_msgs::SetTurret::Request& req, sbot_msgs::SetTurret::Response& res) {
  if (!robot_) {
    res.success = false;
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  const auto& turret = robot_->description().turret;
  if (turret.joint.empty()) {
    res.success = false;
    res.message = name_ + " (level '" + level_ + "') has no turret joint";
    return true;
  }
  try {
    res.clamped = robot_->setTurretRotation(req.position);
    res.applied = static_cast<int16_t>(clampInt(req.position, -turret.range_units, turret.range_units));
    res.success = true;
    if (res.clamped)
      res.message = "position " + std::to_string(req.position) + " outside [-" +
                    std::to_string(turret.range_units) + ", " + std::to_string(turret.range_units) +
                    "]: clamped to " + std::to_string(res.applied);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

void RobotRosInterface::publishState(const ros::Time& stamp,
                                     std::vector<geometry_msgs::TransformStamped>& transforms) {
  if (!robot_) return;
  const sbot::Robot& r = *robot_;
  const sbot::Pose base = r.basePose();

  // Each state is built and sent only while subscribed (the rosters, not Publisher::getNumSubscribers,
  // whose look-up among all the node's publications cost 11 % of a 100-robot node's CPU, every step).
  // Ground truth: pose in `world`, twist of the base_link origin in base_link (REP 105).
  if (ground_truth_subs_.any()) {
    nav_msgs::Odometry odom;
    odom.header.stamp = stamp;
    odom.header.frame_id = "world";
    odom.child_frame_id = base_frame_;
    odom.pose.pose.position = toPoint(base.position);
    odom.pose.pose.orientation = toQuaternion(base.orientation);
    const sbot::Vec3 v_world = r.linearVelocity();
    const sbot::Quat q_inv = base.orientation.conjugate();
    odom.twist.twist.linear = toVector3(q_inv * v_world);
    odom.twist.twist.angular = toVector3(q_inv * r.angularVelocity());
    publishNoted(ground_truth_pub_, name_, "ground_truth", odom);
  }

  if (joint_states_subs_.any()) {
    sensor_msgs::JointState js;
    js.header.stamp = stamp;
    for (const sbot::JointState& s : r.jointStates()) {
      js.name.push_back(s.name);
      js.position.push_back(s.position);
      js.velocity.push_back(s.velocity);
      js.effort.push_back(s.effort);
    }
    joint_states_pub_.publish(js);
  }

  if (track_state_subs_.any()) {
    sbot_msgs::TrackState ts;
    ts.header.stamp = stamp;
    ts.header.frame_id = base_frame_;
    const double unit = r.description().treels.speed_unit;
    ts.requested_left = static_cast<int16_t>(clampInt(std::lround(r.requestedLeft() / unit), -127, 127));
    ts.requested_right = static_cast<int16_t>(clampInt(std::lround(r.requestedRight() / unit), -127, 127));
    int ml = 0, mr = 0, tl = 0, tr = 0;
    r.getSpeed(&ml, &mr);
    r.getTrackTorque(&tl, &tr);
    ts.measured_left = static_cast<int16_t>(ml);
    ts.measured_right = static_cast<int16_t>(mr);
    ts.torque_left = static_cast<int16_t>(tl);
    ts.torque_right = static_cast<int16_t>(tr);
    publishNoted(track_state_pub_, name_, "track_state", ts);
  }

  if (turret_state_subs_.any() && !r.description().turret.joint.empty()) {
    sbot_msgs::TurretState tu;
    tu.header.stamp = stamp;
    tu.header.frame_id = base_frame_;
    tu.rotation = static_cast<int16_t>(r.getTurretRotation());
    tu.torque = static_cast<int16_t>(r.getTurretRotationTorque());
    tu.angle = r.turretAngle();
    publishNoted(turret_state_pub_, name_, "turret/state", tu);
  }

  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = "world";
  tf.child_frame_id = root_frame_;
  const sbot::Pose root = root_link_ == "base_link" ? base : r.linkPose(root_link_);
  tf.transform.translation = toVector3(root.position);
  tf.transform.rotation = toQuaternion(root.orientation);
  transforms.push_back(tf);
}

}  // namespace sbot_node
