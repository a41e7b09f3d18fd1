#include "sbot_sim/core/actuators/gripper.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>

#include "sbot_sim/core/geom_info.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace actuators {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kServoGain = 10.0;     ///< [1/s] position error to velocity
constexpr double kProbeRadius = 0.008;  ///< [m] around the grip point
constexpr double kJawProbeRadius = 0.015;  ///< [m] the jaws reach around the ring

struct ProbeData {
  const Robot* self;
  dGeomID probe;
  std::string who;
  dBodyID body = nullptr;
};

void probeCallback(void* data, dGeomID a, dGeomID b) {
  auto* d = static_cast<ProbeData*>(data);
  if (d->body) return;
  dGeomID other = a == d->probe ? b : a;
  if (dGeomIsSpace(other)) {
    dSpaceCollide2(d->probe, other, data, &probeCallback);
    return;
  }
  const auto* info = static_cast<const GeomInfo*>(dGeomGetData(other));
  if (!info || !info->robot || info->robot == d->self || info->material != "stickable") return;
  dContactGeom c;
  if (dCollide(d->probe, other, 1, &c, sizeof(dContactGeom)) > 0) {
    d->who = info->robot->name();
    d->body = dGeomGetBody(other);
  }
}

}  // namespace

unsigned barrierValue(bool hit, double distance, double lo, double hi) {
  if (!hit || distance >= hi) return 700;
  if (distance <= lo) return 0;
  return static_cast<unsigned>(std::lround(700.0 * (distance - lo) / (hi - lo)));
}

FrontGripper::FrontGripper(World& world, Robot& robot) : world_(world), robot_(robot) {
  const RobotDescription& d = robot.description();
  const YAML::Node g = d.sidecar["gripper"];
  std::string type = g && g["type"] ? g["type"].as<std::string>() : "none";
  if (g && g["link"]) link_ = g["link"].as<std::string>();
  if (g && g["tip_frame"]) tip_ = g["tip_frame"].as<std::string>();
  if (g && g["elevation_joint"]) elevation_joint_ = g["elevation_joint"].as<std::string>();
  elevation_torque_ = sidecarNumber(d, "gripper", "elevation_torque", elevation_torque_);
  elevation_speed_ = sidecarNumber(d, "gripper", "elevation_speed", elevation_speed_);
  elevation_lower_ = sidecarNumber(d, "gripper", "elevation_lower", elevation_lower_);
  elevation_upper_ = sidecarNumber(d, "gripper", "elevation_upper", elevation_upper_);
  jaw_speed_ = sidecarNumber(d, "gripper", "jaw_speed", jaw_speed_);
  jaw_torque_ = sidecarNumber(d, "gripper", "jaw_torque", jaw_torque_);
  if (g && g["jaw_joints"] && g["jaw_joints"].size() == 2) {
    jaw_upper_ = g["jaw_joints"][0].as<std::string>();
    jaw_lower_ = g["jaw_joints"][1].as<std::string>();
  }
  const bool has_elevation = !elevation_joint_.empty() && robot.hingeJoint(elevation_joint_);
  if (type == "sticky" && has_elevation) {
    type_ = Type::Sticky;
  } else if (type == "jaws" && has_elevation && robot.hingeJoint(jaw_upper_) && robot.hingeJoint(jaw_lower_)) {
    type_ = Type::Jaws;
  } else {
    type_ = Type::None;
  }
}

const char* FrontGripper::typeName() const {
  switch (type_) {
    case Type::Sticky: return "sticky";
    case Type::Jaws: return "jaws";
    default: return "none";
  }
}

bool FrontGripper::setElevation(int degrees) {
  const int v = std::clamp(degrees, kElevationMin, kElevationMax);
  if (v != cmd_elevation_) robot_.wake();
  cmd_elevation_ = v;
  return v != degrees;
}

bool FrontGripper::setAperture(int degrees) {
  const int v = std::clamp(degrees, kApertureMin, kApertureMax);
  robot_.wake();  // opening releases a grip, closing may take one: the robot is solved again
  cmd_aperture_ = v;
  if (v > 0) {
    closing_ = false;
    world_.connections().release(robot_.name(), Connection::FrontGripper);
  } else {
    closing_ = true;  // seed: the connection is decided by the closing command
    stall_.reset();
    close_elapsed_ = 0;
    close_delay_ = type_ == Type::Jaws ? getAperture() * kDeg / 2.0 / jaw_speed_ : 0.0;
  }
  return v != degrees;
}

int FrontGripper::getElevation() const {
  if (type_ == Type::None) return cmd_elevation_;
  return std::clamp(static_cast<int>(std::lround(robot_.jointAngle(elevation_joint_) / kDeg)), kElevationMin,
                    kElevationMax);
}

int FrontGripper::getAperture() const {
  if (type_ != Type::Jaws) return cmd_aperture_;
  const double a = robot_.jointAngle(jaw_upper_) + robot_.jointAngle(jaw_lower_);
  return std::clamp(static_cast<int>(std::lround(a / kDeg)), kApertureMin, kApertureMax);
}

int FrontGripper::getElevationTorque() const {
  if (type_ == Type::None) return 0;
  const double unit = elevation_torque_ / 127.0;
  return std::clamp(static_cast<int>(std::lround(robot_.jointEffort(elevation_joint_) / unit)), -127, 127);
}

BarrierReading FrontGripper::getOpticalBarrier() const {
  BarrierReading r;
  if (!robot_.hasLink(link_) || !robot_.hasLink(tip_)) return r;
  const Vec3 hinge = robot_.linkPose(link_).position;
  const Vec3 tip = robot_.linkPose(tip_).position;
  Vec3 dir = tip - hinge;
  const double len = dir.norm();
  if (len < 1e-6) return r;
  dir /= len;
  const RayHit ext = world_.castRay(tip, dir, kBarrierMax, &robot_);
  r.external = barrierValue(ext.hit, ext.distance, kBarrierMin, kBarrierMax);
  const RayHit in = world_.castRay(hinge, dir, len, &robot_);
  r.internal = in.hit ? static_cast<unsigned>(std::lround(700.0 * std::clamp(in.distance / len, 0.0, 1.0))) : 700;
  r.combined = std::min(r.internal, r.external);
  return r;
}

void driveHinge(const Robot& robot, const std::string& joint, double target, double speed, double fmax) {
  dJointID j = robot.hingeJoint(joint);
  if (!j) return;
  const double err = target - robot.jointAngle(joint);
  dJointSetHingeParam(j, dParamVel, std::clamp(kServoGain * err, -speed, speed));
  dJointSetHingeParam(j, dParamFMax, fmax);
}

bool probeStickable(World& world, const Robot& self, const Vec3& p, double radius, std::string* who, dBodyID* body) {
  dGeomID probe = dCreateSphere(nullptr, radius);
  dGeomSetPosition(probe, p.x(), p.y(), p.z());
  ProbeData data{&self, probe, {}, nullptr};
  for (Robot* other : world.robots()) {
    if (other == &self) continue;
    dSpaceCollide2(probe, reinterpret_cast<dGeomID>(other->space()), &data, &probeCallback);
    if (data.body) break;
  }
  dGeomDestroy(probe);
  if (!data.body) return false;
  if (who) *who = data.who;
  if (body) *body = data.body;
  return true;
}

bool FrontGripper::touchingStickable(std::string* who, dBodyID* body) const {
  if (!robot_.hasLink(tip_)) return false;
  return probeStickable(world_, robot_, robot_.linkPose(tip_).position,
                        type_ == Type::Jaws ? kJawProbeRadius : kProbeRadius, who, body);
}

void FrontGripper::tryConnect() {
  std::string who;
  dBodyID held = nullptr;
  dBodyID own = robot_.linkBody(link_);
  if (own && touchingStickable(&who, &held))
    world_.connections().connect(robot_.name(), own, who, held, Connection::FrontGripper);
}

void FrontGripper::update(double dt) {
  if (type_ == Type::None) {
    closing_ = false;
    return;
  }
  // Elevation servo.
  driveHinge(robot_, elevation_joint_, std::clamp(cmd_elevation_ * kDeg, elevation_lower_, elevation_upper_),
             elevation_speed_, elevation_torque_);
  if (type_ == Type::Sticky) {
    if (closing_ && !gripping()) tryConnect();
    closing_ = false;
    return;
  }
  // Jaws: each to aperture / 2, or held where they closed on the ring while connected.
  const double half = cmd_aperture_ * kDeg / 2.0;
  jaws_holding_ = jaws_holding_ && gripping();
  double moving = 0;
  for (const std::string& jn : {jaw_upper_, jaw_lower_}) {
    const double target = !jaws_holding_ ? half : jn == jaw_upper_ ? jaw_hold_upper_ : jaw_hold_lower_;
    driveHinge(robot_, jn, target, jaw_speed_, jaw_torque_);
    moving = std::max(moving, std::abs(robot_.jointRate(jn)));
  }
  if (closing_) {
    // The seed's time delay: the jaws need (current half-aperture) / jaw_speed to close; they are
    // done when they reach the target, stall on the ring, or that time (+0.1 s) has passed.
    const bool reached = getAperture() <= cmd_aperture_ + 1;
    const bool stalled = stall_.update(moving, dt);
    close_elapsed_ += dt;
    if (reached || stalled || close_elapsed_ >= close_delay_ + JawStall::kTime) {
      if (!gripping()) tryConnect();
      closing_ = false;
      jaws_holding_ = gripping();
      jaw_hold_upper_ = robot_.jointAngle(jaw_upper_);
      jaw_hold_lower_ = robot_.jointAngle(jaw_lower_);
    }
  }
}

bool FrontGripper::gripping() const {
  return world_.connections().find(robot_.name(), Connection::FrontGripper) != nullptr;
}

std::string FrontGripper::gripped() const {
  return world_.connections().heldBy(robot_.name(), Connection::FrontGripper);
}

}  // namespace actuators
}  // namespace sbot
