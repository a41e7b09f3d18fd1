#include "sbot_sim/core/actuators/side_arm.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>

#include "sbot_sim/core/world.h"

namespace sbot {
namespace actuators {

namespace {
// A held connection lets go when the force on it, low-passed over kForceFilter, exceeds kBreakMargin
// times the jaws' grasping force (side_arm.h: Table 2.5's 1 N with a friction-cone margin).
constexpr double kBreakMargin = 5.0;
constexpr double kForceFilter = 0.1;  ///< [s]
constexpr double kProbeRadius = 0.012;  ///< [m] around the grip point between the jaws

}  // namespace

SideArm::SideArm(World& world, Robot& robot) : world_(world), robot_(robot) {
  const RobotDescription& d = robot.description();
  const YAML::Node a = d.sidecar["side_arm"];
  if (!a || !a.IsMap() || !a["servos"]) return;
  const YAML::Node s = a["servos"];
  auto str = [&](const char* k) { return s[k] ? s[k].as<std::string>() : std::string(); };
  j_elev_ = str("elevation");
  j_left_ = str("rotation_left");
  j_right_ = str("rotation_right");
  j_jaw_a_ = str("jaw_a");
  j_jaw_b_ = str("jaw_b");
  tip_link_ = a["tip_link"] ? a["tip_link"].as<std::string>() : "side_arm_tip_a";
  unit_ = sidecarNumber(d, "side_arm", "unit", unit_);
  s_ = sidecarNumber(d, "side_arm", "link_length", s_);
  rhombi_ = static_cast<int>(sidecarNumber(d, "side_arm", "rhombi", rhombi_));
  a0_ = sidecarNumber(d, "side_arm", "rest_half_angle", a0_);
  a_min_ = sidecarNumber(d, "side_arm", "half_angle_min", a_min_);
  a_max_ = sidecarNumber(d, "side_arm", "half_angle_max", a_max_);
  rotation_range_ = sidecarNumber(d, "side_arm", "rotation_range", rotation_range_);
  elevation_torque_ = sidecarNumber(d, "side_arm", "elevation_torque", elevation_torque_);
  horizontal_torque_ = sidecarNumber(d, "side_arm", "horizontal_torque", horizontal_torque_);
  servo_speed_ = sidecarNumber(d, "side_arm", "servo_speed", servo_speed_);
  jaw_force_ = sidecarNumber(d, "side_arm", "jaw_force", jaw_force_);
  jaw_torque_ = sidecarNumber(d, "side_arm", "jaw_torque", jaw_torque_);
  jaw_speed_ = sidecarNumber(d, "side_arm", "jaw_speed", jaw_speed_);
  aperture_max_ = sidecarNumber(d, "side_arm", "aperture_max", aperture_max_);
  if (const JointDescription* j = robot.description().findJoint(j_elev_)) elev_range_ = std::min(-j->lower, j->upper);
  available_ = robot.hingeJoint(j_elev_) && robot.hingeJoint(j_left_) && robot.hingeJoint(j_right_);
  if (available_ && a["loop_joints"]) closeLoops(a["loop_joints"]);
  elev_limit_units_ = static_cast<int>(std::floor(elev_range_ / unit_ + 1e-9));
  rot_limit_units_ = static_cast<int>(std::floor(rotation_range_ / unit_ + 1e-9));
  const double reach = 2.0 * rhombi_ * s_;
  depth_min_mm_ = static_cast<int>(std::ceil(reach * std::cos(a_max_) * 1000.0 - 1e-9));
  depth_max_mm_ = static_cast<int>(std::floor(reach * std::cos(a_min_) * 1000.0 + 1e-9));
  cmd_d_ = static_cast<int>(std::lround(reach * std::cos(a0_) * 1000.0));
}

SideArm::~SideArm() {
  for (dJointID j : loop_joints_) dJointDestroy(j);
}

void SideArm::closeLoops(const YAML::Node& loops) {
  for (const YAML::Node& l : loops) {
    const std::string name = l["name"] ? l["name"].as<std::string>() : "";
    if (robot_.hingeJoint(name)) continue;  // the robot built it already
    const std::string parent = l["parent"].as<std::string>(), child = l["child"].as<std::string>();
    dBodyID bp = robot_.linkBody(parent), bc = robot_.linkBody(child);
    if (!bp || !bc || bp == bc) continue;
    auto v3 = [](const YAML::Node& n) { return Vec3(n[0].as<double>(), n[1].as<double>(), n[2].as<double>()); };
    const Pose pp = robot_.linkPose(parent);
    const Vec3 anchor = pp.transform(v3(l["anchor_in_parent"]));
    const Vec3 axis = pp.orientation * v3(l["axis"]);
    dJointID j = dJointCreateHinge(world_.odeWorld(), nullptr);
    dJointAttach(j, bc, bp);
    dJointSetHingeAnchor(j, anchor.x(), anchor.y(), anchor.z());
    dJointSetHingeAxis(j, axis.x(), axis.y(), axis.z());
    loop_joints_.push_back(j);
  }
}

void SideArm::inverse(double elevation, double rotation, double depth, double* qe, double* ql, double* qr) const {
  const double reach = 2.0 * rhombi_ * s_;
  const double a = std::clamp(std::acos(std::clamp(depth / reach, -1.0, 1.0)), a_min_, a_max_);
  *qe = elevation;
  *ql = rotation + (a - a0_);
  *qr = rotation - (a - a0_);
}

void SideArm::forward(double qe, double ql, double qr, double* elevation, double* rotation, double* depth) const {
  *elevation = qe;
  *rotation = (ql + qr) / 2.0;
  *depth = 2.0 * rhombi_ * s_ * std::cos(a0_ + (ql - qr) / 2.0);
}

bool SideArm::setPos(int elevation, int rotation, int depth) {
  if (!available_) return false;
  const int e = std::clamp(elevation, -elev_limit_units_, elev_limit_units_);
  const int r = std::clamp(rotation, -rot_limit_units_, rot_limit_units_);
  const int d = std::clamp(depth, depth_min_mm_, depth_max_mm_);
  if (e != cmd_e_ || r != cmd_r_ || d != cmd_d_) robot_.wake();
  cmd_e_ = e;
  cmd_r_ = r;
  cmd_d_ = d;
  inverse(e * unit_, r * unit_, d / 1000.0, &t_qe_, &t_ql_, &t_qr_);
  return e != elevation || r != rotation || d != depth;
}

void SideArm::getPos(int* elevation, int* rotation, int* depth) const {
  double e = 0, r = 0, d = 0;
  if (available_)
    forward(robot_.jointAngle(j_elev_), robot_.jointAngle(j_left_), robot_.jointAngle(j_right_), &e, &r, &d);
  if (elevation) *elevation = available_ ? static_cast<int>(std::lround(e / unit_)) : 0;
  if (rotation) *rotation = available_ ? static_cast<int>(std::lround(r / unit_)) : 0;
  if (depth) *depth = available_ ? static_cast<int>(std::lround(d * 1000.0)) : 0;
}

void SideArm::getTorque(int* elevation, int* rotation, int* depth) const {
  auto units = [](double t, double max) {
    return std::clamp(static_cast<int>(std::lround(t / (max / 127.0))), -127, 127);
  };
  const double tl = available_ ? robot_.jointEffort(j_left_) : 0, tr = available_ ? robot_.jointEffort(j_right_) : 0;
  if (elevation) *elevation = available_ ? units(robot_.jointEffort(j_elev_), elevation_torque_) : 0;
  if (rotation) *rotation = units((tl + tr) / 2.0, horizontal_torque_);
  if (depth) *depth = units(tl - tr, horizontal_torque_);
}

void SideArm::setOpened() {
  if (!available_) return;
  robot_.wake();
  closed_cmd_ = false;
  closing_ = false;
  world_.connections().release(robot_.name(), Connection::SideArm);
}

void SideArm::setClosed() {
  if (!available_) return;
  robot_.wake();
  closed_cmd_ = true;
  closing_ = true;
  stall_.reset();
}

BarrierReading SideArm::getOpticalBarrier() const {
  BarrierReading r;
  if (!available_ || !robot_.hasLink(tip_link_)) return r;
  const Pose tip = robot_.linkPose(tip_link_);
  const Vec3 dir = tip.orientation * Vec3::UnitX();
  const RayHit ext = world_.castRay(tip.position, dir, FrontGripper::kBarrierMax, &robot_);
  r.external = barrierValue(ext.hit, ext.distance, FrontGripper::kBarrierMin, FrontGripper::kBarrierMax);
  const RayHit in = world_.castRay(tip.position, dir, 0.01, &robot_);
  r.internal = in.hit ? static_cast<unsigned>(std::lround(700.0 * std::clamp(in.distance / 0.01, 0.0, 1.0))) : 700;
  r.combined = std::min(r.internal, r.external);
  return r;
}

void SideArm::update(double dt) {
  if (!available_) return;
  driveHinge(robot_, j_elev_, t_qe_, servo_speed_, elevation_torque_);
  driveHinge(robot_, j_left_, t_ql_, servo_speed_, horizontal_torque_);
  driveHinge(robot_, j_right_, t_qr_, servo_speed_, horizontal_torque_);
  const double jaw = closed_cmd_ ? 0.0 : aperture_max_;
  driveHinge(robot_, j_jaw_a_, jaw, jaw_speed_, jaw_torque_);
  driveHinge(robot_, j_jaw_b_, jaw, jaw_speed_, jaw_torque_);
  if (closing_) {
    const double moving = std::max(std::abs(robot_.jointRate(j_jaw_a_)), std::abs(robot_.jointRate(j_jaw_b_)));
    const bool reached = robot_.jointAngle(j_jaw_a_) < 0.02 && robot_.jointAngle(j_jaw_b_) < 0.02;
    const bool stalled = stall_.update(moving, dt);
    if (reached || stalled) {
      closing_ = false;
      // Probe at the tip with the front gripper's contact test.
      // The grip point: between the two jaws (else the tip link), probed like the front gripper's.
      dBodyID own = robot_.linkBody(tip_link_);
      Vec3 p = robot_.linkPose(tip_link_).position;
      if (robot_.hasLink("side_arm_jaw_a") && robot_.hasLink("side_arm_jaw_b"))
        p = 0.5 * (robot_.linkPose("side_arm_jaw_a").position + robot_.linkPose("side_arm_jaw_b").position);
      std::string who;
      dBodyID held = nullptr;
      if (own && probeStickable(world_, robot_, p, kProbeRadius, &who, &held))
        world_.connections().connect(robot_.name(), own, who, held, Connection::SideArm);
      force_lp_ = 0;
    }
  }
  if (const Connection* c = world_.connections().find(robot_.name(), Connection::SideArm)) {
    const double f = world_.connections().force(*c);
    force_lp_ += (f - force_lp_) * std::min(1.0, dt / kForceFilter);
    if (force_lp_ > jaw_force_ * kBreakMargin) world_.connections().release(robot_.name(), Connection::SideArm);
  }
}

bool SideArm::gripping() const {
  return world_.connections().find(robot_.name(), Connection::SideArm) != nullptr;
}

std::string SideArm::gripped() const {
  return world_.connections().heldBy(robot_.name(), Connection::SideArm);
}

}  // namespace actuators
}  // namespace sbot
