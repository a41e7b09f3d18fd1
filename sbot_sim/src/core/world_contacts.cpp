// World's contacts: the pairs the broad phase finds (robot against robot, robot against the
// terrain), the contact joints built for them with their materials' friction and the robots' own
// friction directions, and the drive wheels' loads read back after the step.
#include "sbot_sim/core/world.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "ode_errors.h"
#include "world_internal.h"

namespace sbot {
namespace {

/// Track creep (Robot::trackCreepSlip) as ODE's force-dependent slip along fdir1 (the direction
/// the wheel rolls in, axle x normal), on a terrain contact of a driven wheel where that is the
/// heading in the contact plane: floors, ramps, slopes. Not robot-robot contacts (no fdir1), nor a
/// face the wheel is pressed against, where the heading's projection is a sideways remnant.
/// `axle`: the wheel's robot's lateral axis (its wheels' axles) in world coordinates.
void applyTrackCreep(const GeomInfo& wheel, const Vec3& axle, const ContactContext& ctx, dSurfaceParameters& surface) {
  if (ctx.fdir1.squaredNorm() == 0) return;
  const Vec3 roll = axle.cross(ctx.normal);
  if (roll.norm() < 0.5 || std::abs(roll.normalized().dot(ctx.heading)) < 0.95) return;
  const double slip = wheel.robot->trackCreepSlip(wheel.track);
  if (slip <= 0) return;
  surface.mode |= dContactSlip1;
  surface.slip1 = slip;
}

/// The first friction direction of a robot's contact with the terrain: the way its wheels roll in
/// the contact plane (axle x normal). On floors and ramps that is the heading; on a face the robot
/// is pressed against, it is up the face. The heading's projection there is only a sideways
/// remnant of the robot's yaw, and a pyramid turned by it let friction hold up to 1.4 mu N up the
/// face (the box's diagonal; at a step's face at mu 0.5: 0.69 N up per 1 N pressed, gtest
/// TreelsFriction.APyramidOnAFaceAheadRunsUpTheFace). Contacts on the robot's flanks (normal along the axle) keep the heading.
Vec3 rollingDirection(const Vec3& axle, const Vec3& normal, const Vec3& heading_in_plane) {
  const Vec3 roll = axle.cross(normal);
  if (roll.norm() < 0.5) return heading_in_plane;
  return roll.dot(heading_in_plane) < 0 ? Vec3(-roll.normalized()) : Vec3(roll.normalized());
}

/// The level's treels friction (TreelsSemantics::friction_scale) for a contact of a driven wheel;
/// two driven wheels in contact (robots driving over each other) take the smaller; 1 otherwise.
double treelsFrictionScale(const GeomInfo* a, const GeomInfo* b) {
  const auto scale = [](const GeomInfo* g) {
    return g && g->track >= 0 && g->robot ? g->robot->description().treels.friction_scale : -1.0;
  };
  const double sa = scale(a), sb = scale(b);
  if (sa < 0 && sb < 0) return 1.0;
  if (sa < 0 || sb < 0) return std::max(sa, sb);
  return std::min(sa, sb);
}

/// The robot whose geoms `g` holds if `g` is a robot's space (Robot sets itself as its data).
const Robot* robotOfSpace(dGeomID g) { return dGeomIsSpace(g) ? static_cast<const Robot*>(dGeomGetData(g)) : nullptr; }

}  // namespace

void nearCallback(void* data, dGeomID a, dGeomID b) { static_cast<World*>(data)->handlePair(a, b); }

const std::set<std::string>& knownSurfaces() {
  static const std::set<std::string> s{"ground",      "wall",       "white_paper", "grey_paper", "black_card",
                                       "wood",        "polystyrene", "aluminium",  "cardboard",  "plastic",
                                       "sbot",        "chassis",     "track",      "stickable",  "mirror"};
  return s;
}

std::set<std::string> surfaceLabels(const TerrainConfig& terrain) {
  std::set<std::string> labels;
  if (terrain.ground_plane) labels.insert("ground");
  for (const BoxObstacle& b : terrain.boxes) labels.insert(b.surface);
  return labels;
}

double ContactConfig::muFor(const std::string& a, const std::string& b) const {
  // A material with its own coefficient overrides the default surface; two such materials in
  // contact use the lower of the two.
  auto ia = material_mu.find(a), ib = material_mu.find(b);
  if (ia == material_mu.end() && ib == material_mu.end()) return mu;
  if (ia == material_mu.end()) return ib->second;
  if (ib == material_mu.end()) return ia->second;
  return std::min(ia->second, ib->second);
}

// What dSpaceCollide2(static_space_, robot space) did, pair for pair and in the same order, so runs
// are unchanged: ODE (the static space a sublevel above the robots') tested every static geom's box
// against the robot space's, then each static geom that met it against the robot's geoms. Here the
// first pass runs over a flat array of boxes computed once (the terrain never moves) instead of
// ODE's list of geoms with their per-geom checks: it was ~4 % of a model-switching run on a course
// of ~250 boxes.
void World::collideWithTerrain(Robot& r) {
  dReal robot_box[6];
  dGeomGetAABB(reinterpret_cast<dGeomID>(r.space()), robot_box);
  bool robot_geoms_read = false;
  for (const BoxedGeom& t : terrain_index_) {
    if (!boxesMeet(t.aabb, robot_box)) continue;
    if (!robot_geoms_read) {
      // As ODE's collide2 does: clears the robot geoms' dirty flags, which decide the order of its
      // list (dGeomMoved puts a moved geom first unless it is still flagged) and so of the contacts.
      dSpaceClean(r.space());
      readBoxedGeoms(r.space(), robot_geoms_);
      robot_geoms_read = true;
    }
    for (const BoxedGeom& g : robot_geoms_)
      if (boxesMeet(g.aabb, t.aabb)) handlePair(t.geom, g.geom);
  }
}

// What the robot-robot pass (dSpaceCollide of the robots' spaces) does for one pair.
void World::collideRobots(const Robot& a, const Robot& b) {
  dReal box_a[6], box_b[6];
  dGeomGetAABB(reinterpret_cast<dGeomID>(a.space()), box_a);
  dGeomGetAABB(reinterpret_cast<dGeomID>(b.space()), box_b);
  if (boxesMeet(box_a, box_b)) dSpaceCollide2(reinterpret_cast<dGeomID>(a.space()), reinterpret_cast<dGeomID>(b.space()), this, &nearCallback);
}

void World::handlePair(dGeomID a, dGeomID b) {
  noteOdePair(a, b);
  if (dGeomIsSpace(a) || dGeomIsSpace(b)) {
    // Two sleeping robots' contacts would join no island (ODE solves only what an enabled body
    // reaches): not made; in a resting cluster they were half the step. If one of them wakes,
    // wakeSleepersJointedToAwakeBodies makes them.
    const Robot *robot_a = robotOfSpace(a), *robot_b = robotOfSpace(b);
    if (robot_a && robot_b && robot_a->asleep() && robot_b->asleep()) return;
    // A robot's own space is never collided with itself: self-collision is off, like the seed.
    dSpaceCollide2(a, b, this, &nearCallback);
    return;
  }
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  if (!ba && !bb) return;  // static vs static
  if (ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
  const GeomInfo* ia = infoOf(a);
  const GeomInfo* ib = infoOf(b);

  const int max_contacts = std::max(1, std::min(config_.contact.max_contacts, 16));
  dContact contacts[16];
  const int n = dCollide(a, b, max_contacts, &contacts[0].geom, sizeof(dContact));
  if (n == 0) return;

  ContactContext ctx;
  ctx.robot_a = ia ? ia->robot : nullptr;
  ctx.robot_b = ib ? ib->robot : nullptr;
  // Robot against robot: a sleeper that a standing (settling) robot touches stays asleep, or two
  // settling neighbours would wake each other for ever (docs/model.md, "Sleeping at rest").
  const Robot* held_back_sleeper = nullptr;
  if (ba && bb && ctx.robot_a && ctx.robot_b && ctx.robot_a != ctx.robot_b) {
    const bool awake_a = dBodyIsEnabled(ba), awake_b = dBodyIsEnabled(bb);
    if (awake_a && awake_b) awake_touches_.emplace_back(ctx.robot_a, ctx.robot_b);
    else if (awake_a && ctx.robot_a->standing()) held_back_sleeper = ctx.robot_b;
    else if (awake_b && ctx.robot_b->standing()) held_back_sleeper = ctx.robot_a;
  }
  ctx.material_a = ia ? ia->material : kGround;
  ctx.material_b = ib ? ib->material : kGround;
  const ContactConfig& cc = config_.contact;
  dSurfaceParameters surface{};
  surface.mode = dContactSoftERP | dContactSoftCFM | (cc.coulomb ? dContactApprox1 : 0) |
                 (cc.bounce > 0 ? dContactBounce : 0);
  surface.mu = cc.muFor(ctx.material_a, ctx.material_b) * treelsFrictionScale(ia, ib);
  surface.soft_erp = cc.erp;
  surface.soft_cfm = cc.cfm;
  surface.bounce = cc.bounce;
  surface.bounce_vel = 0.05;
  const Robot* mover = ctx.robot_a ? ctx.robot_a : ctx.robot_b;
  if (mover && (!ba || !bb) && mover->description().treels.friction_law == TreelsSemantics::FrictionLaw::ForceLimit) {
    // The seed's friction law for this level: each terrain contact holds up to a fixed force.
    surface.mode &= ~dContactApprox1;
    surface.mu = mover->description().treels.friction_force_limit;
  }
  // With fdir1 set (a robot against static geometry) the mover is also the wheels' robot.
  const Quat orientation = mover ? mover->basePose().orientation : Quat::Identity();
  const Vec3 heading = mover ? Vec3(orientation * Vec3::UnitX()) : Vec3::Zero();
  const Vec3 axle = orientation * Vec3::UnitY();
  for (int i = 0; i < n; ++i) {
    ctx.normal = Vec3(contacts[i].geom.normal[0], contacts[i].geom.normal[1], contacts[i].geom.normal[2]);
    const Vec3 along = heading - heading.dot(ctx.normal) * ctx.normal;
    ctx.heading = along.norm() > 1e-9 ? Vec3(along.normalized()) : Vec3::Zero();
    // ODE's friction pyramid (dContactApprox1) is a box in two friction directions. ODE's default
    // directions are fixed in the world, so the same robot spun ~3 % faster heading 45 deg than
    // heading 0; a robot's contacts with the terrain take its own directions instead (body-fixed,
    // as Gazebo's fdir1). (Slip-aligned directions would act as a Coulomb cone, but quickstep
    // leaves ~1 cm/s of slip jitter at resting contacts.) Robot-robot contacts keep ODE's.
    ctx.fdir1 = (!ba || !bb) ? rollingDirection(axle, ctx.normal, ctx.heading) : Vec3::Zero();
    contacts[i].surface = surface;
    for (const auto& e : effects_) e->onContact(ctx, contacts[i].surface);
    if (ia && ia->track >= 0) applyTrackCreep(*ia, axle, ctx, contacts[i].surface);
    else if (ib && ib->track >= 0) applyTrackCreep(*ib, axle, ctx, contacts[i].surface);
    if (ctx.fdir1.squaredNorm() > 0) {
      contacts[i].surface.mode |= dContactFDir1;
      for (int k = 0; k < 3; ++k) contacts[i].fdir1[k] = ctx.fdir1[k];
    }
    dJointID c = dJointCreateContact(world_, contacts_, &contacts[i]);
    ++profile_.contacts;
    if (held_back_sleeper) {
      // The sleeper stands as a static body for its standing neighbour (releaseHeldBackContacts).
      const bool a_sleeps = held_back_sleeper == ctx.robot_a;
      dJointAttach(c, a_sleeps ? nullptr : ba, a_sleeps ? bb : nullptr);
      held_back_.push_back({c, ba, bb, held_back_sleeper, a_sleeps ? ctx.robot_b : ctx.robot_a});
    } else {
      dJointAttach(c, ba, bb);
    }
    const bool wheel_a = ia && ia->drive_wheel, wheel_b = ib && ib->drive_wheel;
    if (wheel_a || wheel_b) {
      wheel_contacts_->push_back({{}, ctx.normal, wheel_a ? ia->robot : nullptr, wheel_b ? ib->robot : nullptr, ba == nullptr,
                                 wheel_a && ia->track >= 0, wheel_b && ib->track >= 0});
      dJointSetFeedback(c, &wheel_contacts_->back().feedback);
    }
  }
}

void World::updateDriveWheelLoads() {
  // A robot out of the solve keeps the loads it stood on (its contacts' feedback is not written).
  for (auto& r : robots_)
    if (dBodyIsEnabled(r->baseBody())) r->clearDriveContacts();
  auto add = [](Robot* r, const dVector3 force, double sign, const Vec3& normal, bool wheel) {
    const Vec3 f(force[0], force[1], force[2]);
    const double push = sign * f.dot(normal);
    if (r && push > 0 && dBodyIsEnabled(r->baseBody())) r->addDriveContact(push, f, wheel);
  };
  for (const WheelContact& w : *wheel_contacts_) {
    // The contact normal points from geom 2 into geom 1: body 1 is pushed along it, body 2
    // against it. A contact whose body 1 is static is stored reversed by ODE: its body 2's force
    // is reported in f1.
    add(w.wheel_of_body1, w.feedback.f1, 1.0, w.normal, w.on_wheel1);
    add(w.wheel_of_body2, w.body1_static ? w.feedback.f1 : w.feedback.f2, -1.0, w.normal, w.on_wheel2);
  }
  wheel_contacts_->clear();
}

}  // namespace sbot
