// Building a robot from its RobotDescription: its links grouped into ODE bodies with their masses,
// the collision geoms, the hinges, the track drive (wheels or body drive) and the side arm's loop
// joints; and taking them apart again (destroyModel), which a model switch and a turret weld use.
// The robot at run time (actuation, read-out, sleeping) is robot.cpp.
#include "sbot_sim/core/robot.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/world.h"
#include "robot_internal.h"

namespace sbot {

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


/// build()'s links grouped into rigid bodies: a fixed joint merges the child into its parent's body.
struct Robot::LinkGroups {
  struct Group {
    std::string first_link;
    std::vector<std::pair<std::string, Pose>> links;  ///< (link, group_T_link)
  };
  std::vector<Group> groups;
  std::map<std::string, std::pair<int, Pose>> link_group;  ///< link -> (group, group_T_link)
  std::map<std::string, Pose> world_T_link;
};

namespace {

/// The mass of a group's links about the group's centre of mass, which goes to `com` (in the
/// group's frame). Throws ConfigError when the group has no mass.
dMass centredGroupMass(const RobotDescription& d, const std::vector<std::pair<std::string, Pose>>& links,
                       const std::string& first_link, double inertia_floor, Vec3& com) {
  dMass total;
  dMassSetZero(&total);
  for (const auto& [link_name, group_T_link] : links) {
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
    throw ConfigError(d.urdf_path, "link " + first_link + "/inertial",
                      "a link moved by a joint needs mass (it and its fixed children have none)");
  }
  com = Vec3(total.c[0], total.c[1], total.c[2]);
  dMassTranslate(&total, -com.x(), -com.y(), -com.z());
  // Inertia floor (sidecar extra inertia_floor_kgm2): the side arm's gram-sized links have
  // moments near 1e-8 kg m^2, which ODE's iterative solver cannot hold together at a 10 ms step
  // (the arm flails and explodes). Raising tiny principal moments to the floor keeps masses,
  // centres of mass and statics exact and only slows such links' own rotational response.
  if (inertia_floor > 0) {
    for (int k = 0; k < 3; ++k) total.I[k * 4 + k] = std::max(total.I[k * 4 + k], inertia_floor);
  }
  return total;
}

}  // namespace

void Robot::build(const Pose& base_pose) {
  static std::atomic<std::uint64_t> last_build_id{0};
  build_id_ = ++last_build_id;
  const RobotDescription& d = *model_;
  // 1. Group links into rigid bodies: a fixed joint merges the child into its parent's body.
  const LinkGroups groups = groupLinks(d, base_pose);
  // 2. One ODE body per group, its frame at the group's centre of mass (ODE requires that).
  const double inertia_floor = std::atof(d.extraOr("inertia_floor_kgm2", "0").c_str());
  space_ = dSimpleSpaceCreate(world_.space());
  dGeomSetData(reinterpret_cast<dGeomID>(space_), this);  // World::handlePair reads it
  for (std::size_t gi = 0; gi < groups.groups.size(); ++gi) addGroupBody(groups, gi, inertia_floor);
  base_body_T_base_ = link_index_.at(d.root_link).body_T_link;
  // 3. Hinges for the moving joints, then what drives the tracks.
  addHinges(groups);
  markDriveWheels();
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
  addLoopJoints(groups.world_T_link, groups.link_group);
}

Robot::LinkGroups Robot::groupLinks(const RobotDescription& d, const Pose& base_pose) {
  // group_T_link is each link's frame in its group's frame (the group's first link).
  LinkGroups out;
  std::vector<LinkGroups::Group>& groups = out.groups;
  std::map<std::string, std::pair<int, Pose>>& link_group = out.link_group;
  std::map<std::string, Pose>& world_T_link = out.world_T_link;
  groups = {{d.root_link, {{d.root_link, Pose()}}}};
  link_group = {{d.root_link, {0, Pose()}}};
  world_T_link = {{d.root_link, base_pose}};
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
  return out;
}

void Robot::addGroupBody(const LinkGroups& groups, std::size_t gi, double inertia_floor) {
  const RobotDescription& d = *model_;
  Vec3 com;
  dMass total = centredGroupMass(d, groups.groups[gi].links, groups.groups[gi].first_link, inertia_floor, com);
  const Pose body_T_group(-com, Quat::Identity());

  dBodyID body = dBodyCreate(world_.odeWorld());
  dBodySetMass(body, &total);
  const Pose world_T_group = groups.world_T_link.at(groups.groups[gi].first_link);
  setBodyPose(body, world_T_group * body_T_group.inverse());
  dBodySetData(body, this);
  bodies_.push_back(body);

  for (const auto& [link_name, group_T_link] : groups.groups[gi].links) {
    const Pose body_T_link = body_T_group * group_T_link;
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

void Robot::addHinges(const LinkGroups& groups) {
  const RobotDescription& d = *model_;
  // Body 1 = child, body 2 = parent, so the hinge angle is the child's rotation about the axis
  // relative to its parent, as URDF defines it.
  for (const auto& j : d.joints) {
    if (j.type == JointDescription::Type::Fixed) continue;
    const int child = groups.link_group.at(j.child).first;
    const int parent = groups.link_group.at(j.parent).first;
    Hinge h;
    h.name = j.name;
    h.child_body = child;
    h.axis_in_child = j.axis;
    h.id = dJointCreateHinge(world_.odeWorld(), nullptr);
    dJointAttach(h.id, bodies_[child], bodies_[parent]);
    const Pose& w = groups.world_T_link.at(j.child);
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
    h.feedback = detail::newJointFeedback();
    hinge_index_[j.name] = static_cast<int>(hinges_.size());
    hinges_.push_back(std::move(h));
  }
  for (auto& h : hinges_) dJointSetFeedback(h.id, h.feedback.get());
}

void Robot::markDriveWheels() {
  const RobotDescription& d = *model_;
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
  if (!drive_linear_fb_) drive_linear_fb_ = detail::newJointFeedback();
  dJointSetFeedback(drive_linear_, drive_linear_fb_.get());
  drive_angular_ = dJointCreateAMotor(world_.odeWorld(), nullptr);
  dJointAttach(drive_angular_, chassis, nullptr);
  dJointSetAMotorMode(drive_angular_, dAMotorUser);
  dJointSetAMotorNumAxes(drive_angular_, 1);
  dJointSetAMotorAxis(drive_angular_, 0, 1, up.x(), up.y(), up.z());
  if (!drive_angular_fb_) drive_angular_fb_ = detail::newJointFeedback();
  dJointSetFeedback(drive_angular_, drive_angular_fb_.get());
  dJointSetLMotorParam(drive_linear_, dParamFMax, 0);  // until the first applyCommands
  dJointSetAMotorParam(drive_angular_, dParamFMax, 0);
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


}  // namespace sbot
