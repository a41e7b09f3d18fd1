// Dynamic model switching (seed 2.1.3): Robot::switchDescription rebuilds one robot from another
// level's description in place, between two steps, carrying its state over.
//
// What carries over and how:
//  * base_link pose, base linear velocity (of the base_link origin) and angular velocity;
//  * every hinge both levels have (turret_joint, left/right_wheel_joint, gripper_elevation_joint,
//    side-arm joints): angle and rate. The new bodies are first built at the zero configuration
//    (so ODE's hinge references and stops are the URDF zero), then moved by forward kinematics to
//    the carried joint angles; the unwrapped angle bookkeeping (turret +-200 deg) is restored;
//  * driven wheels: every driven hinge of the new level spins at the old track's measured surface
//    speed / its radius (Medium's front/rear wheels, absent in Simple, start at the track speed);
//  * body velocities follow from the base twist plus the joint rates (rigid-body kinematics);
//  * commands: requested track speeds, passive mode and the turret target are members that are
//    simply not touched (the turret target is clamped to the new level's range);
//  * joints other code attached to this robot (connections: World::connections(), or any other
//    non-contact joint to another robot or the world) keep their dJointID and are re-attached to
//    the new body that carries the same link. For a ConnectionManager connection the link is the
//    grip point (holder, FrontGripper: gripper_tip; SideArm: side_arm_tip_a or the turret if the
//    new level has no side arm) or the turret (held: the stickable ring). Fixed joints keep the
//    current relative pose (which the switch does not change); ball/hinge anchors are re-set at the
//    same world point.
// The same rebuild welds a settled turret to the treels and frees it again (Robot::turretLocked):
// the welded model is the level's description with the turret joint fixed at the turret's angle.
// Not carried: joint motor states of modules (the gripper / side-arm modules re-apply their targets
// every step) and anything a module cached from the old bodies.
#include <cmath>

#include <ode/ode.h>
#include <map>
#include <set>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace {

void setOdeBodyPose(dBodyID b, const Pose& pose) {
  dBodySetPosition(b, pose.position.x(), pose.position.y(), pose.position.z());
  const Quat& q = pose.orientation;
  dQuaternion oq{q.w(), q.x(), q.y(), q.z()};
  dBodySetQuaternion(b, oq);
}

struct ExternalJoint {
  dJointID joint = nullptr;
  int slot = 0;              ///< this robot's body is body `slot` (0 or 1) of the joint
  dBodyID other = nullptr;   ///< the other body (another robot's, or null = the static world)
  std::string link;          ///< link of this robot the joint belongs to
  int type = 0;
  Vec3 anchor = Vec3::Zero(), axis = Vec3::UnitZ();  ///< world frame (ball / hinge)
};

}  // namespace

void Robot::switchDescription(const RobotDescription& d) {
  const RobotDescription& old = *description_;
  // Fast is a half-size, 1/20-mass robot in 1/50 gravity: it cannot stand in for a full-size one.
  const double m_old = old.totalMass(), m_new = d.totalMass();
  if (!(m_new > 0) || std::abs(m_new - m_old) > 0.25 * std::max(m_old, m_new)) {
    throw ConfigError(d.sidecar_path, "level",
                      "cannot switch " + name_ + " from '" + old.level + "' (" + std::to_string(m_old) +
                          " kg) to '" + d.level + "' (" + std::to_string(m_new) +
                          " kg): levels of different scale (Fast is half size in 1/50 gravity)");
  }
  description_ = &d;
  // A welded turret stays welded at the same angle if the new level welds idle turrets too.
  welds_turret_ = weldsIdleTurret(world_.config(), d);
  std::unique_ptr<RobotDescription> welded;
  if (turret_locked_ && welds_turret_) welded = withTurretWelded(d, locked_angle_);
  rebuild(welded ? *welded : d);
  turret_joint_ = d.turret.joint;
  turret_locked_ = welded != nullptr;
  welded_model_ = std::move(welded);
}

void Robot::rebuild(const RobotDescription& d) {
  const RobotDescription& old = *model_;
  // ---- 1. capture the state -----------------------------------------------------------------------
  const Pose base = basePose();
  const Vec3 v_base = linearVelocity();
  const Vec3 w_base = angularVelocity();
  std::map<std::string, double> q, qd;
  for (const auto& h : hinges_) {
    q[h.name] = hingeAngle(h);
    qd[h.name] = hingeRate(h);
  }
  if (turret_locked_) q[turret_joint_] = locked_angle_, qd[turret_joint_] = 0;  // welded: no hinge
  const double track_left = trackSpeedLeft(), track_right = trackSpeedRight();

  // Link names per old body (to re-attach external joints to the same link).
  std::vector<std::string> first_link(bodies_.size());
  for (const auto& [link, frame] : link_index_)
    if (frame.body >= 0 && first_link[frame.body].empty()) first_link[frame.body] = link;
  for (const auto& j : old.joints) {
    // Prefer the group's first link (the link a moving joint carries) over merged frames.
    if (j.type == JointDescription::Type::Fixed) continue;
    auto it = link_index_.find(j.child);
    if (it != link_index_.end() && it->second.body >= 0) first_link[it->second.body] = j.child;
  }
  if (!bodies_.empty()) first_link[0] = old.root_link;

  std::set<dBodyID> mine(bodies_.begin(), bodies_.end());
  std::set<dJointID> own;
  for (const auto& h : hinges_) own.insert(h.id);
  for (dJointID j : loop_joints_) own.insert(j);
  for (dJointID j : {drive_linear_, drive_angular_})
    if (j) own.insert(j);
  std::vector<ExternalJoint> externals;
  std::set<dJointID> seen;
  const auto& conns = world_.connections().list();
  for (std::size_t bi = 0; bi < bodies_.size(); ++bi) {
    dBodyID b = bodies_[bi];
    for (int k = 0; k < dBodyGetNumJoints(b); ++k) {
      dJointID j = dBodyGetJoint(b, k);
      const int type = dJointGetType(j);
      if (type == dJointTypeContact || own.count(j) || !seen.insert(j).second) continue;
      ExternalJoint e;
      e.joint = j;
      e.type = type;
      e.slot = dJointGetBody(j, 0) == b ? 0 : 1;
      e.other = dJointGetBody(j, 1 - e.slot);
      if (e.other && mine.count(e.other)) {
        // Another module's joint between two of this robot's own bodies: it cannot survive the
        // rebuild (the bodies change); leave it detached for its owner to destroy.
        dJointAttach(j, nullptr, nullptr);
        continue;
      }
      e.link = first_link[bi];
      for (const auto& c : conns) {
        if (c.joint != j) continue;
        if (c.held == name_ && c.holder != name_) e.link = "turret";
        else if (c.kind == Connection::FrontGripper) e.link = "gripper_tip";
        else e.link = "side_arm_tip_a";
      }
      if (type == dJointTypeBall) {
        dVector3 a;
        dJointGetBallAnchor(j, a);
        e.anchor = Vec3(a[0], a[1], a[2]);
      } else if (type == dJointTypeHinge) {
        dVector3 a, ax;
        dJointGetHingeAnchor(j, a);
        dJointGetHingeAxis(j, ax);
        e.anchor = Vec3(a[0], a[1], a[2]);
        e.axis = Vec3(ax[0], ax[1], ax[2]);
      }
      externals.push_back(e);
    }
  }
  for (auto& e : externals) dJointAttach(e.joint, nullptr, nullptr);  // limbo while rebuilding

  // ---- 2. tear the old model down (as ~Robot, without touching other joints) ----------------------
  destroyModel();

  // ---- 3. build the new one at the zero configuration -----------------------------------------------
  model_ = &d;
  build(base);

  // ---- 4. forward kinematics to the carried joint angles and rates ---------------------------------
  std::map<std::string, double> rate;  // new hinge rates
  for (const auto& h : hinges_) {
    auto it = qd.find(h.name);
    rate[h.name] = it == qd.end() ? 0.0 : it->second;
  }
  for (int i : left_hinges_) rate[hinges_[i].name] = track_left / d.wheelRadius(hinges_[i].name);
  for (int i : right_hinges_) rate[hinges_[i].name] = track_right / d.wheelRadius(hinges_[i].name);

  struct LinkState {
    Pose pose;
    Vec3 v, w;
  };
  std::map<std::string, LinkState> ls;
  ls[d.root_link] = {base, v_base, w_base};
  for (const auto& j : d.joints) {
    const LinkState& p = ls.at(j.parent);
    Pose child = p.pose * j.origin;
    Vec3 w = p.w;
    if (j.type != JointDescription::Type::Fixed) {
      auto it = q.find(j.name);
      const double angle = it == q.end() ? 0.0 : it->second;
      child = child * Pose(Vec3::Zero(), Quat(Eigen::AngleAxisd(angle, j.axis)));
      w += (child.orientation * j.axis) * rate[j.name];
    }
    // The child frame's origin is a point of the parent (the joint sits there).
    const Vec3 v = p.v + p.w.cross(child.position - p.pose.position);
    ls[j.child] = {child, v, w};
  }
  std::vector<bool> placed(bodies_.size(), false);
  for (const auto& [link, frame] : link_index_) {
    if (frame.body < 0 || placed[frame.body] || !ls.count(link)) continue;
    placed[frame.body] = true;
    const LinkState& s = ls.at(link);
    const Pose body_pose = s.pose * frame.body_T_link.inverse();
    dBodyID b = bodies_[frame.body];
    setOdeBodyPose(b, body_pose);
    const Vec3 v = s.v + s.w.cross(body_pose.position - s.pose.position);
    dBodySetLinearVel(b, v.x(), v.y(), v.z());
    dBodySetAngularVel(b, s.w.x(), s.w.y(), s.w.z());
    dBodyEnable(b);
  }
  // ODE measures hinge angles from the configuration at creation (zero): now it reads the carried
  // angle (wrapped); the unwrapped value is the carried one.
  for (auto& h : hinges_) {
    h.raw_angle = dJointGetHingeAngle(h.id);
    auto it = q.find(h.name);
    h.angle = it == q.end() ? h.raw_angle : it->second;
    h.effort = 0;
  }
  if (!description_->turret.joint.empty()) {
    const double lim = description_->turret.range_units * description_->turret.unit;
    turret_target_ = std::max(-lim, std::min(lim, turret_target_));
  }

  // ---- 5. re-attach the external joints ------------------------------------------------------------
  for (auto& e : externals) {
    dBodyID nb = linkBody(e.link);
    if (!nb && e.link == "side_arm_tip_a") nb = linkBody("turret");
    if (!nb) nb = linkBody(d.root_link);
    if (e.slot == 0) dJointAttach(e.joint, nb, e.other);
    else dJointAttach(e.joint, e.other, nb);
    switch (e.type) {
      case dJointTypeFixed: dJointSetFixed(e.joint); break;
      case dJointTypeBall: dJointSetBallAnchor(e.joint, e.anchor.x(), e.anchor.y(), e.anchor.z()); break;
      case dJointTypeHinge:
        dJointSetHingeAnchor(e.joint, e.anchor.x(), e.anchor.y(), e.anchor.z());
        dJointSetHingeAxis(e.joint, e.axis.x(), e.axis.y(), e.axis.z());
        break;
      default: break;  // other joint types keep their body-relative parameters
    }
  }
}

}  // namespace sbot
