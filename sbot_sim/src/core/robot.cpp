#include "sbot_sim/core/robot.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>

#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace {

constexpr int kApiLimit = 127;  // sbot.h: every track/torque value is in [-127,127]

int clampInt(int v, int lo, int hi) { return std::max(lo, std::min(hi, v)); }
int roundToUnits(double v, int limit) {
  if (!std::isfinite(v)) return 0;
  return clampInt(static_cast<int>(std::lround(v)), -limit, limit);
}

void toOde(const Quat& q, dQuaternion out) {
  out[0] = q.w(); out[1] = q.x(); out[2] = q.y(); out[3] = q.z();
}
Pose bodyPose(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);
  return Pose(Vec3(p[0], p[1], p[2]), Quat(q[0], q[1], q[2], q[3]));
}
void setBodyPose(dBodyID b, const Pose& pose) {
  dBodySetPosition(b, pose.position.x(), pose.position.y(), pose.position.z());
  dQuaternion q;
  toOde(pose.orientation, q);
  dBodySetQuaternion(b, q);
}
Vec3 vec(const dReal* v) { return Vec3(v[0], v[1], v[2]); }

// The hinge rate is no test of rest: quickstep leaves it jittering by +-0.07 rad/s at the target.
constexpr double kTurretSettleTime = 0.2;                   // [s] within tolerance before welding
}  // namespace

Robot::Robot(World& world, const RobotDescription& description, const std::string& name, int index,
             const Pose& base_pose)
    : world_(world), description_(&description), model_(&description), name_(name), index_(index),
      random_(world.config().seed, name) {
  turret_joint_ = description.turret.joint;
  welds_turret_ = weldsIdleTurret(world.config(), description);
  if (welds_turret_) {  // at rest on its zero at the start
    welded_model_ = withTurretWelded(description, 0.0);
    model_ = welded_model_.get();
    turret_locked_ = true;
  }
  build(base_pose);
}

Robot::~Robot() { destroyModel(); }

void Robot::destroyModel() {
  for (auto& h : hinges_) dJointDestroy(h.id);
  for (dJointID j : loop_joints_) dJointDestroy(j);
  for (dJointID j : {drive_linear_, drive_angular_})
    if (j) dJointDestroy(j);
  for (dGeomID g : geoms_) dGeomDestroy(g);
  if (space_) dSpaceDestroy(space_);
  for (dBodyID b : bodies_) dBodyDestroy(b);
  bodies_.clear();
  geoms_.clear();
  geom_infos_.clear();
  space_ = nullptr;
  hinges_.clear();
  loop_joints_.clear();
  loop_index_.clear();
  hinge_index_.clear();
  link_index_.clear();
  left_hinges_.clear();
  right_hinges_.clear();
  turret_hinge_ = -1;
  drive_linear_ = drive_angular_ = nullptr;
  drive_torque_[0] = drive_torque_[1] = 0;
}

void Robot::build(const Pose& base_pose) {
  static std::atomic<std::uint64_t> last_build_id{0};
  build_id_ = ++last_build_id;
  const RobotDescription& d = *model_;
  // 1. Group links into rigid bodies: a fixed joint merges the child into its parent's body.
  //    group_T_link is each link's frame in its group's frame (the group's first link).
  struct Group {
    std::string first_link;
    std::vector<std::pair<std::string, Pose>> links;  // (link, group_T_link)
  };
  std::vector<Group> groups{{d.root_link, {{d.root_link, Pose()}}}};
  std::map<std::string, std::pair<int, Pose>> link_group{{d.root_link, {0, Pose()}}};
  std::map<std::string, Pose> world_T_link{{d.root_link, base_pose}};
  for (const auto& j : d.joints) {
    const auto& parent = link_group.at(j.parent);
    world_T_link[j.child] = world_T_link.at(j.parent) * j.origin;
    if (j.type == JointDescription::Type::Fixed) {
      Pose group_T_child = parent.second * j.origin;
      groups[parent.first].links.emplace_back(j.child, group_T_child);
      link_group[j.child] = {parent.first, group_T_child};
    } else {
      groups.push_back({j.child, {{j.child, Pose()}}});
      link_group[j.child] = {static_cast<int>(groups.size()) - 1, Pose()};
    }
  }

  // 2. One ODE body per group, its frame at the group's centre of mass (ODE requires that).
  const double inertia_floor = std::atof(d.extraOr("inertia_floor_kgm2", "0").c_str());
  space_ = dSimpleSpaceCreate(world_.space());
  dGeomSetData(reinterpret_cast<dGeomID>(space_), this);  // World::handlePair reads it
  std::vector<Pose> body_T_group(groups.size());
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    dMass total;
    dMassSetZero(&total);
    for (const auto& [link_name, group_T_link] : groups[gi].links) {
      const LinkDescription* link = d.findLink(link_name);
      if (!link || link->mass <= 0) continue;
      dMass m;
      const Mat3& I = link->inertia;
      dMassSetParameters(&m, link->mass, 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
      const Pose group_T_inertial = group_T_link * link->inertial_origin;
      dMatrix3 R;
      const Mat3 r = group_T_inertial.orientation.toRotationMatrix();
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) R[row * 4 + col] = r(row, col);
        R[row * 4 + 3] = 0;
      }
      dMassRotate(&m, R);
      dMassTranslate(&m, group_T_inertial.position.x(), group_T_inertial.position.y(),
                     group_T_inertial.position.z());
      dMassAdd(&total, &m);
    }
    if (total.mass <= 0) {
      throw ConfigError(d.urdf_path, "link " + groups[gi].first_link + "/inertial",
                        "a link moved by a joint needs mass (it and its fixed children have none)");
    }
    const Vec3 com(total.c[0], total.c[1], total.c[2]);
    dMassTranslate(&total, -com.x(), -com.y(), -com.z());
    // Inertia floor (sidecar extra inertia_floor_kgm2): the side arm's gram-sized links have
    // moments near 1e-8 kg m^2, which ODE's iterative solver cannot hold together at a 10 ms step
    // (the arm flails and explodes). Raising tiny principal moments to the floor keeps masses,
    // centres of mass and statics exact and only slows such links' own rotational response.
    if (inertia_floor > 0) {
      for (int k = 0; k < 3; ++k) total.I[k * 4 + k] = std::max(total.I[k * 4 + k], inertia_floor);
    }
    body_T_group[gi] = Pose(-com, Quat::Identity());

    dBodyID body = dBodyCreate(world_.odeWorld());
    dBodySetMass(body, &total);
    const Pose world_T_group = world_T_link.at(groups[gi].first_link);
    setBodyPose(body, world_T_group * body_T_group[gi].inverse());
    dBodySetData(body, this);
    bodies_.push_back(body);

    for (const auto& [link_name, group_T_link] : groups[gi].links) {
      const Pose body_T_link = body_T_group[gi] * group_T_link;
      link_index_[link_name] = {static_cast<int>(gi), body_T_link};
      const LinkDescription* link = d.findLink(link_name);
      if (!link) continue;
      for (const auto& shape : link->collisions) {
        dGeomID g = nullptr;
        switch (shape.type) {
          case CollisionShape::Type::Sphere: g = dCreateSphere(space_, shape.radius); break;
          case CollisionShape::Type::Cylinder: g = dCreateCylinder(space_, shape.radius, shape.length); break;
          case CollisionShape::Type::Box:
            g = dCreateBox(space_, shape.size.x(), shape.size.y(), shape.size.z());
            break;
        }
        dGeomSetBody(g, body);
        const Pose offset = body_T_link * shape.origin;
        dGeomSetOffsetPosition(g, offset.position.x(), offset.position.y(), offset.position.z());
        dQuaternion q;
        toOde(offset.orientation, q);
        dGeomSetOffsetQuaternion(g, q);
        geom_infos_.push_back(std::make_unique<GeomInfo>(GeomInfo{this, link->material, link_name}));
        dGeomSetData(g, geom_infos_.back().get());
        geoms_.push_back(g);
      }
    }
  }
  base_body_T_base_ = link_index_.at(d.root_link).body_T_link;

  // 3. Hinges for the moving joints. Body 1 = child, body 2 = parent, so the hinge angle is the
  //    child's rotation about the axis relative to its parent, as URDF defines it.
  for (const auto& j : d.joints) {
    if (j.type == JointDescription::Type::Fixed) continue;
    const int child = link_group.at(j.child).first;
    const int parent = link_group.at(j.parent).first;
    Hinge h;
    h.name = j.name;
    h.child_body = child;
    h.axis_in_child = j.axis;
    h.id = dJointCreateHinge(world_.odeWorld(), nullptr);
    dJointAttach(h.id, bodies_[child], bodies_[parent]);
    const Pose& w = world_T_link.at(j.child);
    const Vec3 axis = w.orientation * j.axis;
    dJointSetHingeAnchor(h.id, w.position.x(), w.position.y(), w.position.z());
    dJointSetHingeAxis(h.id, axis.x(), axis.y(), axis.z());
    // ODE hinge stops work within [-pi, pi]; wider ranges (the turret's +-200 deg) are kept by the
    // joint's servo instead.
    if (j.type == JointDescription::Type::Revolute && j.lower >= -M_PI && j.upper <= M_PI) {
      dJointSetHingeParam(h.id, dParamLoStop, j.lower);
      dJointSetHingeParam(h.id, dParamHiStop, j.upper);
    }
    dJointSetHingeParam(h.id, dParamFMax, 0);  // passive until a module drives it
    hinge_index_[j.name] = static_cast<int>(hinges_.size());
    hinges_.push_back(h);
  }
  for (auto& h : hinges_) dJointSetFeedback(h.id, &h.feedback);  // addresses are stable now

  for (const auto& jn : d.treels.left_joints) left_hinges_.push_back(hinge_index_.at(jn));
  for (const auto& jn : d.treels.right_joints) right_hinges_.push_back(hinge_index_.at(jn));
  for (int track : {0, 1}) {
    for (int i : track == 0 ? left_hinges_ : right_hinges_) {
      const dBodyID wheel = bodies_[hinges_[i].child_body];
      for (dGeomID g : geoms_) {
        if (dGeomGetBody(g) != wheel) continue;
        GeomInfo* info = static_cast<GeomInfo*>(dGeomGetData(g));
        info->drive_wheel = true;
        info->track = track;
      }
    }
  }
  if (!d.turret.joint.empty()) turret_hinge_ = hinge_index_.at(d.turret.joint);
  measureTrackWidth();
  if (d.treels.drive == "body") {
    // The chassis with its casters stands for the tracks here: its ground contacts carry the
    // load the drive's traction comes from (applyBodyDrive).
    for (dGeomID g : geoms_)
      if (dGeomGetBody(g) == baseBody()) static_cast<GeomInfo*>(dGeomGetData(g))->drive_wheel = true;
    buildBodyDrive();
  } else {
    addReflectedRotorInertia(left_hinges_);
    addReflectedRotorInertia(right_hinges_);
  }
  addLoopJoints(world_T_link, link_group);
}

void Robot::measureTrackWidth() {
  // The outermost driven wheel of each side, by its frame's lateral offset in base_link: the
  // treels turn on their centre wheels, "slightly outward and larger" (seed 2.2.1; Table 2.2: 8.2
  // cm apart, the front/back ones 4.2 cm). A mean over Medium's six wheels gave 5.5 cm, and
  // cmd_vel then turned a Medium at 58-68 % of the commanded rate.
  const Pose base_inv = basePose().inverse();
  auto outermost_y = [&](const std::vector<int>& side) {
    double best = 0;
    for (int i : side) {
      const JointDescription* j = description_->findJoint(hinges_[i].name);
      if (!j || !hasLink(j->child)) continue;
      const double y = (base_inv * linkPose(j->child)).position.y();
      if (std::abs(y) > std::abs(best)) best = y;
    }
    return best;
  };
  const double w = std::abs(outermost_y(left_hinges_) - outermost_y(right_hinges_));
  constexpr double kSeedTrackWidth = 0.082;  // [m] Table 2.2, centre wheels separation
  track_width_ = w > 1e-3 ? w : kSeedTrackWidth;
  wheels_apart_ = w > 1e-3;
}

void Robot::buildBodyDrive() {
  if (!wheels_apart_)
    throw ConfigError(description_->sidecar_path, "treels.drive",
                      "body drive needs left and right driven wheels apart; they are not in " + description_->urdf_path);
  dBodyID chassis = baseBody();
  drive_linear_ = dJointCreateLMotor(world_.odeWorld(), nullptr);
  dJointAttach(drive_linear_, chassis, nullptr);
  dJointSetLMotorNumAxes(drive_linear_, 2);
  // rel 1: the axes stay fixed in the chassis, but ODE takes them in world coordinates, as the
  // chassis lies now (given as (1, 0, 0), a robot spawned facing +y would drive sideways along +x).
  const Quat q = bodyPose(chassis).orientation;
  const Vec3 forward = q * Vec3::UnitX(), left = q * Vec3::UnitY(), up = q * Vec3::UnitZ();
  dJointSetLMotorAxis(drive_linear_, 0, 1, forward.x(), forward.y(), forward.z());
  dJointSetLMotorAxis(drive_linear_, 1, 1, left.x(), left.y(), left.z());
  dJointSetFeedback(drive_linear_, &drive_linear_fb_);
  drive_angular_ = dJointCreateAMotor(world_.odeWorld(), nullptr);
  dJointAttach(drive_angular_, chassis, nullptr);
  dJointSetAMotorMode(drive_angular_, dAMotorUser);
  dJointSetAMotorNumAxes(drive_angular_, 1);
  dJointSetAMotorAxis(drive_angular_, 0, 1, up.x(), up.y(), up.z());
  dJointSetFeedback(drive_angular_, &drive_angular_fb_);
  dJointSetLMotorParam(drive_linear_, dParamFMax, 0);  // until the first applyCommands
  dJointSetAMotorParam(drive_angular_, dParamFMax, 0);
}

double Robot::bodyDriveTrackSpeed(int side) const {
  // Chassis velocity in its own frame: forward component and yaw rate.
  dBodyID chassis = baseBody();
  const Quat q = bodyPose(chassis).orientation;
  const Vec3 v = q.inverse() * vec(dBodyGetLinearVel(chassis));
  const Vec3 w = q.inverse() * vec(dBodyGetAngularVel(chassis));
  return v.x() + (side == 0 ? -1 : 1) * 0.5 * track_width_ * w.z();
}

void Robot::addLoopJoints(const std::map<std::string, Pose>& world_T_link,
                          const std::map<std::string, std::pair<int, Pose>>& link_group) {
  // URDF is a tree: the pins closing the side arm's scissor loops come from the sidecar
  // (side_arm.loop_joints, see sbot_description/README.md). Each is a passive ODE hinge between
  // the two named links' bodies at the parent's anchor, axis given in the parent frame. The robot's
  // geoms never collide with each other, so no contact filtering is needed.
  const YAML::Node arm = description_->sidecar["side_arm"];
  if (!arm || !arm.IsMap() || !arm["loop_joints"]) return;
  for (const auto& lj : arm["loop_joints"]) {
    const std::string name = lj["name"].as<std::string>("loop_joint");
    const std::string parent = lj["parent"].as<std::string>(""), child = lj["child"].as<std::string>("");
    auto pg = link_group.find(parent), cg = link_group.find(child);
    if (pg == link_group.end() || cg == link_group.end()) {
      throw ConfigError(description_->sidecar_path, "side_arm.loop_joints." + name,
                        "unknown link '" + (pg == link_group.end() ? parent : child) + "'");
    }
    if (pg->second.first == cg->second.first) continue;  // merged into one rigid body: nothing to close
    auto vec3 = [](const YAML::Node& n, const Vec3& fallback) {
      return n && n.IsSequence() && n.size() == 3 ? Vec3(n[0].as<double>(), n[1].as<double>(), n[2].as<double>())
                                                   : fallback;
    };
    const Pose& w = world_T_link.at(parent);
    const Vec3 anchor = w.transform(vec3(lj["anchor_in_parent"], Vec3::Zero()));
    const Vec3 axis = w.orientation * vec3(lj["axis"], Vec3::UnitZ());
    dJointID j = dJointCreateHinge(world_.odeWorld(), nullptr);
    dJointAttach(j, bodies_[cg->second.first], bodies_[pg->second.first]);
    dJointSetHingeAnchor(j, anchor.x(), anchor.y(), anchor.z());
    dJointSetHingeAxis(j, axis.x(), axis.y(), axis.z());
    loop_joints_.push_back(j);
    loop_index_[name] = j;
  }
  // The scissor's own pins are passive; a small holding friction keeps the folded arm from
  // flopping at rest (the servos, driven by the side-arm module, are far stronger: 0.04-0.07 N m).
  constexpr double kHoldingTorque = 0.002;  // [N m]
  if (arm["passive_joints"]) {
    for (const auto& pj : arm["passive_joints"]) {
      const Hinge* h = hinge(pj.as<std::string>());
      if (!h) continue;
      dJointSetHingeParam(h->id, dParamVel, 0);
      dJointSetHingeParam(h->id, dParamFMax, kHoldingTorque);
    }
  }
  // Until the side-arm module drives them, the powered servos hold their (rest) position with
  // their own torque (URDF effort), as a real RC servo does: the arm stays folded.
  if (arm["servos"] && arm["servos"].IsMap()) {
    for (const auto& sv : arm["servos"]) {
      const std::string jn = sv.second.as<std::string>("");
      const Hinge* h = hinge(jn);
      const JointDescription* jd = description_->findJoint(jn);
      if (!h || !jd) continue;
      dJointSetHingeParam(h->id, dParamVel, 0);
      dJointSetHingeParam(h->id, dParamFMax, jd->effort > 0 ? jd->effort : kHoldingTorque);
    }
  }
  for (dJointID j : loop_joints_) {
    dJointSetHingeParam(j, dParamVel, 0);
    dJointSetHingeParam(j, dParamFMax, kHoldingTorque);
  }
}

void Robot::addReflectedRotorInertia(const std::vector<int>& track) {
  // The motor's rotor turns gear_ratio times faster than the axle, so at the axle it weighs
  // rotor_inertia * gear_ratio^2 — far more than the wheels themselves. Each wheel of the track
  // carries an equal share about its own axis.
  const TreelsSemantics& tr = description_->treels;
  if (track.empty() || tr.rotor_inertia <= 0) return;
  const double share = tr.rotor_inertia * tr.gear_ratio * tr.gear_ratio / track.size();
  for (int i : track) {
    dBodyID body = bodies_[hinges_[i].child_body];
    dMass m;
    dBodyGetMass(body, &m);
    const Vec3& a = hinges_[i].axis_in_child;  // child link frame == body frame orientation
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m.I[r * 4 + c] += share * a[r] * a[c];
    dBodySetMass(body, &m);
    // That inertia spins at the rotor's speed, not the wheel's: its gyroscopic torque is
    // gear_ratio times smaller than ODE would compute for the wheel body, i.e. negligible.
    dBodySetGyroscopicMode(body, 0);
  }
}

const Robot::Hinge* Robot::hinge(const std::string& joint) const {
  auto it = hinge_index_.find(joint);
  return it == hinge_index_.end() ? nullptr : &hinges_[it->second];
}

double Robot::hingeRate(const Hinge& h) const { return dJointGetHingeAngleRate(h.id); }
double Robot::hingeAngle(const Hinge& h) const { return h.angle; }

// ---- joint access for actuator modules ----------------------------------------------------------

dJointID Robot::hingeJoint(const std::string& joint) const {
  const Hinge* h = hinge(joint);
  if (h) return h->id;
  auto it = loop_index_.find(joint);  // side-arm loop closures built by addLoopJoints()
  return it == loop_index_.end() ? nullptr : it->second;
}

double Robot::jointAngle(const std::string& joint) const {
  if (turret_locked_ && joint == turret_joint_) return locked_angle_;
  const Hinge* h = hinge(joint);
  return h ? hingeAngle(*h) : 0.0;
}

double Robot::jointRate(const std::string& joint) const {
  const Hinge* h = hinge(joint);
  return h ? hingeRate(*h) : 0.0;
}

double Robot::jointEffort(const std::string& joint) const {
  const Hinge* h = hinge(joint);
  return h ? h->effort : 0.0;
}

dBodyID Robot::linkBody(const std::string& link) const {
  auto it = link_index_.find(link);
  if (it == link_index_.end() || it->second.body < 0) return nullptr;
  return bodies_[it->second.body];
}

// ---- s-bot API ---------------------------------------------------------------------------------

bool Robot::setSpeed(int left, int right) {
  passive_ = false;
  const int limit = description_->treels.speed_limit_units;
  const int l = clampInt(clampInt(left, -kApiLimit, kApiLimit), -limit, limit);
  const int r = clampInt(clampInt(right, -kApiLimit, kApiLimit), -limit, limit);
  req_left_ = l * description_->treels.speed_unit;
  req_right_ = r * description_->treels.speed_unit;
  return l != left || r != right;
}

void Robot::setTrackSpeeds(double left_mps, double right_mps) {
  passive_ = false;
  const double vmax = description_->treels.speed_limit_units * description_->treels.speed_unit;
  auto limit = [vmax](double v) { return std::isfinite(v) ? std::max(-vmax, std::min(vmax, v)) : 0.0; };
  req_left_ = limit(left_mps);
  req_right_ = limit(right_mps);
}

double Robot::trackSpeedLeft() const {
  if (drive_linear_) return bodyDriveTrackSpeed(0);
  double sum = 0;
  for (int i : left_hinges_) sum += hingeRate(hinges_[i]) * description_->wheelRadius(hinges_[i].name);
  return left_hinges_.empty() ? 0 : sum / left_hinges_.size();
}

double Robot::trackSpeedRight() const {
  if (drive_linear_) return bodyDriveTrackSpeed(1);
  double sum = 0;
  for (int i : right_hinges_) sum += hingeRate(hinges_[i]) * description_->wheelRadius(hinges_[i].name);
  return right_hinges_.empty() ? 0 : sum / right_hinges_.size();
}

void Robot::updateCreepSlip(const TrackCommand& cmd) {
  creep_slip_[0] = creep_slip_[1] = 0;
  const TreelsSemantics& tr = description_->treels;
  if (tr.creep_stiffness <= 0 || drive_linear_ || passive_ || drive_contacts_ == 0 || drive_wheel_load_ <= 0) return;
  // ODE lets a contact with force-dependent slip k slide at k x its friction force. The track's
  // contacts share one slip velocity s |v|; with k = |v| n / (C N) for each of the n contacts
  // carrying the load N, their friction forces add up to F = C N s, i.e. s = (F / N) / C however
  // the load is shared among them. |v|: the track's speed, but no more than its motor is asked
  // for, so that held tracks, which quickstep lets jitter, do not creep.
  const double turning[2] = {std::fabs(trackSpeedLeft()), std::fabs(trackSpeedRight())};
  const double motor[2] = {std::fabs(cmd.left), std::fabs(cmd.right)};
  for (int track : {0, 1})
    creep_slip_[track] = std::min(turning[track], motor[track]) * drive_contacts_ / (tr.creep_stiffness * drive_wheel_load_);
}

double Robot::encoderSpeed(int side) const {
  SensorSample sample{kTrackSpeedChannel, side, side == 0 ? trackSpeedLeft() : trackSpeedRight(), "", 0};
  for (const auto& e : world_.effects()) e->onSensor(*this, sample);
  return sample.value;
}

void Robot::getSpeed(int* left, int* right) const {
  const double unit = description_->treels.speed_unit;
  if (left) *left = roundToUnits(encoderSpeed(0) / unit, kApiLimit);
  if (right) *right = roundToUnits(encoderSpeed(1) / unit, kApiLimit);
}

double Robot::trackTorqueLeft() const {
  return torque_history_.empty() ? 0 : torque_sum_[0] / torque_history_.size();
}

double Robot::trackTorqueRight() const {
  return torque_history_.empty() ? 0 : torque_sum_[1] / torque_history_.size();
}

void Robot::getTrackTorque(int* left, int* right) const {
  const double unit = description_->treels.torque_unit;
  if (left) *left = roundToUnits(trackTorqueLeft() / unit, kApiLimit);
  if (right) *right = roundToUnits(trackTorqueRight() / unit, kApiLimit);
}

bool Robot::setTurretRotation(int pos) {
  const int range = description_->turret.range_units;
  const int p = clampInt(pos, -range, range);
  if (p * description_->turret.unit != turret_target_) wake();
  turret_target_ = p * description_->turret.unit;
  return p != pos;
}

double Robot::turretAngle() const {
  if (turret_locked_) return locked_angle_;
  return turret_hinge_ < 0 ? 0 : hingeAngle(hinges_[turret_hinge_]);
}

int Robot::getTurretRotation() const {
  return roundToUnits(turretAngle() / description_->turret.unit, description_->turret.range_units);
}

int Robot::getTurretRotationTorque() const {
  if (turret_hinge_ < 0) return 0;
  return roundToUnits(hinges_[turret_hinge_].effort / description_->turret.torque_unit, kApiLimit);
}

// ---- turret weld ---------------------------------------------------------------------------------


/// Whether a level's idle turret is welded in this world. Only quickstep needs it, and only for a
/// turret whose centre of mass is off its hinge axis (Basic, Medium, Detailed: 4 cm). dWorldStep
/// resolves the hinge (and its Dantzig LCP fails on the welded Medium/Detailed treels: "LCP internal
/// error", the robot veers 3-10 deg in 10 s). Simple's and Fast's turrets are balanced on the axis
/// and converge on their hinge (+-1 deg in 10 s); welded, the symmetric Simple robot rocks between
/// its casters (+-1.3 deg pitch) instead of resting on one, as it does on the hinge.
bool Robot::weldsIdleTurret(const WorldConfig& c, const RobotDescription& d) {
  if (!c.lock_idle_turret || c.solver != "quickstep" || d.turret.joint.empty()) return false;
  const JointDescription* j = d.findJoint(d.turret.joint);
  const LinkDescription* turret = j ? d.findLink(j->child) : nullptr;
  if (!turret) return false;
  constexpr double kOffAxis = 0.005;  // [m]
  const Vec3 com = turret->inertial_origin.position, axis = j->axis.normalized();
  return (com - axis * axis.dot(com)).norm() > kOffAxis;
}

std::unique_ptr<RobotDescription> Robot::withTurretWelded(const RobotDescription& d, double angle) {
  auto welded = std::make_unique<RobotDescription>(d);
  for (auto& j : welded->joints) {
    if (j.name != d.turret.joint) continue;
    j.type = JointDescription::Type::Fixed;
    j.origin = j.origin * Pose(Vec3::Zero(), Quat(Eigen::AngleAxisd(angle, j.axis.normalized())));
  }
  welded->turret.joint.clear();  // no turret hinge to look for
  return welded;
}

void Robot::updateTurretLock(double dt) {
  if (!welds_turret_) return;  // (switchDescription frees a welded turret the new level does not weld)
  const double tolerance = 0.5 * description_->turret.unit;  // half an API unit (1 deg)
  if (turret_locked_) {
    if (std::abs(turret_target_ - locked_angle_) > tolerance) setTurretLocked(false);
    return;
  }
  if (turret_hinge_ < 0) return;
  const Hinge& h = hinges_[turret_hinge_];
  const bool at_target = std::abs(turret_target_ - hingeAngle(h)) < tolerance;
  turret_settled_for_ = at_target ? turret_settled_for_ + dt : 0.0;
  if (turret_settled_for_ >= kTurretSettleTime) setTurretLocked(true);
}

void Robot::setTurretLocked(bool locked) {
  if (locked == turret_locked_ || turret_joint_.empty()) return;
  turret_settled_for_ = 0;
  if (locked) {
    const double angle = turretAngle();
    std::unique_ptr<RobotDescription> welded = withTurretWelded(*description_, angle);
    rebuild(*welded);  // captures the free turret's angle from its hinge
    welded_model_ = std::move(welded);
    turret_locked_ = true;
    locked_angle_ = angle;
  } else {
    rebuild(*description_);  // captures the welded angle (turret_locked_ still true)
    turret_locked_ = false;
    welded_model_.reset();
  }
}

// ---- state ---------------------------------------------------------------------------------------

dBodyID Robot::baseBody() const { return bodies_.front(); }

Pose Robot::basePose() const { return bodyPose(baseBody()) * base_body_T_base_; }

Pose Robot::linkPose(const std::string& link) const {
  auto it = link_index_.find(link);
  if (it == link_index_.end()) throw UnknownName("robot " + name_ + " has no link '" + link + "'");
  return bodyPose(bodies_[it->second.body]) * it->second.body_T_link;
}

bool Robot::resolve(const LinkRef& link) const {
  if (link.build_ != build_id_) {
    auto it = link_index_.find(link.name_);
    link.build_ = build_id_;
    link.body_ = it == link_index_.end() ? -1 : it->second.body;
    if (it != link_index_.end()) link.body_T_link_ = it->second.body_T_link;
  }
  return link.body_ >= 0;
}

Pose Robot::linkPose(const LinkRef& link) const {
  if (!resolve(link)) throw UnknownName("robot " + name_ + " has no link '" + link.name_ + "'");
  return bodyPose(bodies_[link.body_]) * link.body_T_link_;
}

Vec3 Robot::linearVelocity() const {
  // Velocity of the base_link origin, not of the body's centre of mass.
  dVector3 v;
  const Vec3 p = basePose().position;
  dBodyGetPointVel(baseBody(), p.x(), p.y(), p.z(), v);
  return Vec3(v[0], v[1], v[2]);
}

Vec3 Robot::angularVelocity() const { return vec(dBodyGetAngularVel(baseBody())); }

std::vector<JointState> Robot::jointStates() const {
  std::vector<JointState> out;
  out.reserve(hinges_.size());
  for (const auto& h : hinges_) out.push_back({h.name, hingeAngle(h), hingeRate(h), h.effort});
  if (turret_locked_) out.push_back({turret_joint_, locked_angle_, 0.0, 0.0});
  return out;
}

void Robot::setBasePose(const Pose& pose) {
  const std::string where = positionProblem(pose.position);
  if (!where.empty()) throw ConfigError("<world>", "robot " + name_, where);
  const Pose old_base_body = bodyPose(baseBody());
  const Pose new_base_body = pose * base_body_T_base_.inverse();
  for (dBodyID b : bodies_) {
    const Pose rel = old_base_body.inverse() * bodyPose(b);
    setBodyPose(b, new_base_body * rel);
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
    dBodyEnable(b);
  }
}

std::vector<Robot::BodyState> Robot::bodyStates() const {
  std::vector<BodyState> out;
  for (dBodyID b : bodies_) out.push_back({bodyPose(b), vec(dBodyGetLinearVel(b)), vec(dBodyGetAngularVel(b))});
  return out;
}

void Robot::setBodyStates(const std::vector<BodyState>& states) {
  for (std::size_t i = 0; i < bodies_.size() && i < states.size(); ++i) {
    setBodyPose(bodies_[i], states[i].pose);
    dBodySetLinearVel(bodies_[i], states[i].linear.x(), states[i].linear.y(), states[i].linear.z());
    dBodySetAngularVel(bodies_[i], states[i].angular.x(), states[i].angular.y(), states[i].angular.z());
    dBodyEnable(bodies_[i]);  // a sleeping robot moved by hand is awake (wakeIfDisturbed)
  }
}

// ---- sleeping at rest ----------------------------------------------------------------------------

void Robot::sleep() {
  for (dBodyID b : bodies_) {
    // At rest: what is left of the velocities is the solver's jitter, not motion.
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
    dBodyDisable(b);
  }
  asleep_ = true;
}

void Robot::wake() {
  wakeByTouch();
  last_command_wake_s_ = world_.time();
}

void Robot::wakeByTouch() {
  for (dBodyID b : bodies_) dBodyEnable(b);
  asleep_ = false;
  rest_watch_.reset();
}

void Robot::updateStanding() {
  standing_ = false;
  if (asleep_ || !commanded_still_ || world_.time() - last_command_wake_s_ < kServoSettle_s) return;
  if (world_.time() - rest_watch_.lastMoveAt() < kMovedRecently_s) return;  // pushed or dragged, not jittering
  constexpr double kTurretAtTarget = 0.02;  // [rad] the servo has settled
  if (turret_hinge_ >= 0 && std::abs(turretAngle() - turret_target_) > kTurretAtTarget) return;
  for (dBodyID b : bodies_) {
    const dReal* v = dBodyGetLinearVel(b);
    if (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > kStandingSpeed * kStandingSpeed) return;
  }
  standing_ = true;
}

void Robot::wakeIfDisturbed() {
  if (!asleep_) return;
  auto nonzero = [](const dReal* v) { return v[0] != 0 || v[1] != 0 || v[2] != 0; };
  for (dBodyID b : bodies_) {
    if (dBodyIsEnabled(b) || nonzero(dBodyGetForce(b)) || nonzero(dBodyGetTorque(b))) {
      wake();
      return;
    }
  }
}

void Robot::updateRest(const RestConfig& config) {
  rest_ready_ = false;
  if (asleep_) {
    if (dBodyIsEnabled(baseBody())) {
      wakeByTouch();  // ODE's island walk enabled it (and all it is jointed to): touched or held by an awake body
    } else {
      // The forces this robot's own command path added while it slept (rolling resistance, the
      // body drive) were not applied; clear them so that only new, external ones wake it.
      for (dBodyID b : bodies_) {
        dBodySetForce(b, 0, 0, 0);
        dBodySetTorque(b, 0, 0, 0);
      }
    }
    return;
  }
  if (!config.enabled || !commanded_still_) {
    rest_watch_.reset();
    return;
  }
  rest_ready_ = rest_watch_.stoodStill(bodies_, world_.time(), config);
  rest_watch_.addLoad(drive_wheel_load_, drive_contact_force_);
}

void Robot::sleepAtRest() {
  drive_wheel_load_ = rest_watch_.meanLoad();
  drive_contact_force_ = rest_watch_.meanForce();
  rest_ready_ = false;
  sleep();
}

// ---- stepping ------------------------------------------------------------------------------------

void Robot::applyCommands(double dt, const std::vector<EffectPtr>& effects) {
  updateTurretLock(dt);
  const TreelsSemantics& tr = description_->treels;
  TrackCommand cmd{req_left_, req_right_, tr.max_torque, tr.max_torque};
  for (const auto& e : effects) e->onCommand(*this, cmd, dt);

  auto drive = [this](const std::vector<int>& side, double speed, double max_torque) {
    // One motor per track drives all its wheels through the rubber band: each wheel turns at the
    // track speed and gets an equal share of the motor's torque.
    const double share = side.empty() ? 0 : std::max(0.0, max_torque) / side.size();
    for (int i : side) {
      const Hinge& h = hinges_[i];
      dJointSetHingeParam(h.id, dParamVel, speed / description_->wheelRadius(h.name));
      dJointSetHingeParam(h.id, dParamFMax, share);
    }
  };
  if (drive_linear_) {
    applyBodyDrive(cmd);
  } else if (passive_) {
    // Motors off: the gears resist rolling with back-drive friction; pulling the robot takes
    // backdrive_force in total, half of it on each track.
    const double holding = 0.5 * tr.backdrive_force * tr.wheel_radius;  // [N m] per track
    drive(left_hinges_, 0.0, holding);
    drive(right_hinges_, 0.0, holding);
  } else {
    drive(left_hinges_, cmd.left, cmd.max_torque_left);
    drive(right_hinges_, cmd.right, cmd.max_torque_right);
  }
  updateCreepSlip(cmd);  // once per step, for every terrain contact of the wheels that collision makes
  applyRollingResistance(cmd);
  // Standing is the command after the effects: a motor-noise effect that moves a "stopped" track
  // keeps the robot awake.
  commanded_still_ = cmd.left == 0 && cmd.right == 0;
  if (asleep_ && !commanded_still_) wake();

  if (turret_hinge_ >= 0) {
    // Position servo (the turret's PIC controller): proportional velocity demand capped at the
    // turret's rotation speed, torque capped at its motor torque.
    const TurretSemantics& ts = description_->turret;
    const Hinge& h = hinges_[turret_hinge_];
    constexpr double kGain = 8.0;  // [1/s]: settles within ~0.5 s, no overshoot at 10 ms steps
    const double err = turret_target_ - hingeAngle(h);
    dJointSetHingeParam(h.id, dParamVel, std::max(-ts.speed, std::min(ts.speed, kGain * err)));
    dJointSetHingeParam(h.id, dParamFMax, ts.max_torque);
  }
}

void Robot::applyRollingResistance(const TrackCommand& cmd) {
  if (cmd.resist_torque_left <= 0 && cmd.resist_torque_right <= 0) return;
  // Opposes the rotation with a smooth sign (tanh): a hard sign would chatter at standstill.
  constexpr double kRollingSpeed = 0.005;  // [m/s] below this the resistance fades out linearly
  const double r = description_->treels.wheel_radius;
  if (drive_linear_) {
    // Body drive (Fast): the two tracks' resistances as one force against the forward speed.
    const Quat q = bodyPose(baseBody()).orientation;
    const Vec3 heading = q * Vec3::UnitX();
    const double v = linearVelocity().dot(heading);
    const double f = (cmd.resist_torque_left + cmd.resist_torque_right) / r * std::tanh(v / kRollingSpeed);
    dBodyAddForce(baseBody(), -f * heading.x(), -f * heading.y(), -f * heading.z());
    return;
  }
  auto resist = [this](const std::vector<int>& side, double torque) {
    if (side.empty() || torque <= 0) return;
    for (int i : side) {
      const Hinge& h = hinges_[i];
      const double rim_speed = hingeRate(h) * description_->wheelRadius(h.name);
      // Between wheel and chassis, like bearing friction: the motor's constraint torque (the
      // torque reading) grows by the same amount.
      dJointAddHingeTorque(h.id, -torque / side.size() * std::tanh(rim_speed / kRollingSpeed));
    }
  };
  resist(left_hinges_, cmd.resist_torque_left);
  resist(right_hinges_, cmd.resist_torque_right);
}

void Robot::applyBodyDrive(const TrackCommand& cmd) {
  // (The wheel hinges stay as built: FMax 0, rolling freely.)
  const TreelsSemantics& tr = description_->treels;
  // Traction: mu(track, ground) times the load that pressed the chassis, casters and wheels onto
  // their support in the last step (driveContactForce along the chassis' up axis): nothing while
  // airborne or lifted by another robot, m g cos(slope) standing on a slope, and a wall or robot
  // pushing from the side adds none. The wheels are passive supports (frictionless, like casters:
  // friction at the wheel contacts would tip the light robot over in every turn); the drive's grip
  // is the track material's.
  const Quat q = bodyPose(baseBody()).orientation;
  const Vec3 up = q * Vec3::UnitZ();
  const double traction =
      world_.config().contact.muFor("track", "ground") * tr.friction_scale * std::max(0.0, driveContactForce().dot(up));
  drive_traction_ = traction;
  double v = 0, yaw_rate = 0, f_max = 0, t_max = 0;
  if (passive_) {
    f_max = std::min(traction, tr.backdrive_force);  // gear back-drive: the pull needed to move it
    t_max = 0.5 * f_max * track_width_;
  } else {
    const double f_left = std::max(0.0, cmd.max_torque_left) / tr.wheel_radius;  // [N] per track
    const double f_right = std::max(0.0, cmd.max_torque_right) / tr.wheel_radius;
    v = 0.5 * (cmd.left + cmd.right);
    yaw_rate = (cmd.right - cmd.left) / track_width_;
    f_max = std::min(traction, f_left + f_right);
    t_max = 0.5 * track_width_ * std::min(traction, std::min(f_left, f_right) * 2);
  }
  // The motors hold the tracks' speed relative to the chassis: while the chassis pitches about the
  // axle at rate w (> 0 nose down), a track on the ground moves it r w faster (a nose dropping into
  // a gap drives the robot on under it, as with a wheel drive; a tail dropping holds it back).
  if (driven_wheel_contacts_ > 0) v += tr.wheel_radius * (q.inverse() * vec(dBodyGetAngularVel(baseBody()))).y();
  dJointSetLMotorParam(drive_linear_, dParamVel, v);
  dJointSetLMotorParam(drive_linear_, dParamFMax, f_max);
  dJointSetLMotorParam(drive_linear_, dParamVel2, 0);  // no side slip below the traction limit
  dJointSetLMotorParam(drive_linear_, dParamFMax2, traction);
  dJointSetAMotorParam(drive_angular_, dParamVel, yaw_rate);
  dJointSetAMotorParam(drive_angular_, dParamFMax, t_max);
  applyDriveReaction(q);
}

void Robot::applyDriveReaction(const Quat& q) {
  // A wheel motor that pushes the robot forward with force F turns the chassis the other way with
  // F times the wheel radius: nose up when driving or pushing forward, nose down when braking. The
  // body drive's force acts at the chassis' centre, on the axle, so this torque is added here, from
  // the drive force of the last step. Only while a driven wheel touches something: a wheel in the
  // air spins free and loads its motor with nothing (so a hard start rears the robot onto its rear
  // caster, which lifts the wheels, and it drops back instead of flipping over). Without it the
  // Fast robot pitched nose-down into every halved gap from 4.5 cm (Table 4.5).
  if (driven_wheel_contacts_ == 0) return;
  const double push = (q.inverse() * vec(drive_linear_fb_.f1)).x();  // [N] along the heading
  const Vec3 axle = q * Vec3::UnitY();
  const double torque = -push * description_->treels.wheel_radius;  // [N m] about +y: > 0 nose down
  dBodyAddTorque(baseBody(), torque * axle.x(), torque * axle.y(), torque * axle.z());
}

void Robot::readFeedback(double dt) {
  for (auto& h : hinges_) {
    const double raw = dJointGetHingeAngle(h.id);
    h.angle += std::remainder(raw - h.raw_angle, 2 * M_PI);
    h.raw_angle = raw;
    // Torque the joint applied to the child body about the joint axis (motor + limit stops). The
    // child's centre of mass lies on or near the axis, so the constraint force adds ~nothing.
    dVector3 a;
    dJointGetHingeAxis(h.id, a);
    h.effort = vec(h.feedback.t1).dot(Vec3(a[0], a[1], a[2]));
  }
  if (drive_linear_) {
    // Motor forces back to per-track axle torques: forward force shared equally, yaw torque as a
    // force couple of the two tracks.
    const Quat q = bodyPose(baseBody()).orientation;
    const double forward = (q.inverse() * vec(drive_linear_fb_.f1)).x();
    const double yaw = (q.inverse() * vec(drive_angular_fb_.t1)).z();
    const double r = description_->treels.wheel_radius;
    drive_torque_[0] = (0.5 * forward - yaw / track_width_) * r;
    drive_torque_[1] = (0.5 * forward + yaw / track_width_) * r;
  }
  auto sum = [this](const std::vector<int>& side) {
    double t = 0;
    for (int i : side) t += hinges_[i].effort;
    return t;
  };
  const std::array<double, 2> now = drive_linear_ ? std::array<double, 2>{drive_torque_[0], drive_torque_[1]}
                                                  : std::array<double, 2>{sum(left_hinges_), sum(right_hinges_)};
  // The window's length in steps; rebuilt (and refilled from this step) if the step or the level changed.
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(description_->treels.torque_window / dt)));
  if (torque_history_.size() != n) {
    torque_history_.assign(n, now);
    torque_sum_ = {now[0] * n, now[1] * n};
    torque_next_ = 0;
    return;
  }
  for (int s = 0; s < 2; ++s) torque_sum_[s] += now[s] - torque_history_[torque_next_][s];
  torque_history_[torque_next_] = now;
  torque_next_ = (torque_next_ + 1) % n;
  if (torque_next_ == 0) {  // once per window: re-add, so rounding cannot accumulate over long runs
    torque_sum_ = {0, 0};
    for (const auto& h : torque_history_) torque_sum_[0] += h[0], torque_sum_[1] += h[1];
  }
}

}  // namespace sbot
