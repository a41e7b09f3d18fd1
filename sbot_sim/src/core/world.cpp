#include "sbot_sim/core/world.h"

#include <atomic>
#include <cstdarg>
#include <cstdio>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/geom_info.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/random_streams.h"
#include "sbot_sim/core/terrain.h"
#include "ode_errors.h"

namespace sbot {
namespace {

// ODE's informational messages (with the exact solver: "LCP internal error" whenever contacts are
// redundant, up to every step) would flood the logs: print the first ten, then every 1000th.
void initOdeOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    installOdeHandlers();  // ODE errors name the robot, body and step (ode_errors.h)
  });
  // Every thread that touches ODE needs its own collision scratch data (parallel simulations).
  dAllocateODEDataForThread(dAllocateMaskAll);
}

void nearCallback(void* data, dGeomID a, dGeomID b) { static_cast<World*>(data)->handlePair(a, b); }

const GeomInfo* infoOf(dGeomID g) { return static_cast<const GeomInfo*>(dGeomGetData(g)); }

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

const std::string kGround = "ground";

/// The first friction direction of a robot's contact with the terrain: the way its wheels roll in
/// the contact plane (axle x normal). On floors and ramps that is the heading; on a face the robot
/// is pressed against, it is up the face. The heading's projection there is only a sideways
/// remnant of the robot's yaw, and a pyramid turned by it let friction hold up to 1.4 mu N up the
/// face (the box's diagonal; measured 2026-11-27 at a step's face at mu 0.5: 0.69 N up per 1 N
/// pressed). Contacts on the robot's flanks (normal along the axle) keep the heading.
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

}  // namespace

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

World::World(const WorldConfig& config) : config_(config) {
  initOdeOnce();
  if (!(config_.step > 0)) throw ConfigError("<world>", "step", "must be > 0");

  if (config_.solver != "quickstep" && config_.solver != "exact")
    throw ConfigError("<world>", "solver", "expected 'quickstep' or 'exact', found '" + config_.solver + "'");
  exact_solver_ = config_.solver == "exact";
  world_ = dWorldCreate();
  dWorldSetGravity(world_, 0, 0, -config_.gravity);
  updateSolverIterations();
  dWorldSetQuickStepW(world_, config_.solver_sor);
  dWorldSetContactSurfaceLayer(world_, 0.0005);
  dWorldSetContactMaxCorrectingVel(world_, 0.5);
  space_ = dHashSpaceCreate(nullptr);
  static_space_ = dHashSpaceCreate(nullptr);
  // A sublevel above the robots' spaces: ODE's dSpaceCollide2 then walked the static geoms against
  // a robot space as one geom, the order collideWithTerrain keeps.
  dSpaceSetSublevel(static_space_, 1);
  contacts_ = dJointGroupCreate(0);
  buildTerrain();
  indexTerrain();
  connections_ = std::make_unique<ConnectionManager>(*this);
}

World::~World() {
  connections_.reset();  // joints between robot bodies first
  robots_.clear();
  for (dGeomID g : static_geoms_) {
    delete static_cast<GeomInfo*>(dGeomGetData(g));
    dGeomDestroy(g);
  }
  if (heightfield_data_) dGeomHeightfieldDataDestroy(heightfield_data_);
  dJointGroupDestroy(contacts_);
  if (query_ray_) dGeomDestroy(query_ray_);
  if (query_box_) dGeomDestroy(query_box_);
  dSpaceDestroy(static_space_);
  dSpaceDestroy(space_);
  dWorldDestroy(world_);
}

std::string positionProblem(const Vec3& p) {
  if (p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate) return "";
  std::ostringstream msg;
  msg << "position (" << p.x() << ", " << p.y() << ", " << p.z() << ") m is outside the simulated space (every "
      << "coordinate finite and within +-" << kMaxCoordinate << " m)";
  return msg.str();
}

void World::buildTerrain() {
  const TerrainConfig& t = config_.terrain;
  for (const auto& box : t.boxes) {
    std::string problem = positionProblem(box.center);
    if (problem.empty()) problem = positionProblem(box.size);
    // A box without volume is degenerate for ODE's collision tests (an assertion, not an error).
    if (problem.empty()) problem = boxSizeProblem(box.size);
    if (!problem.empty()) throw ConfigError("<world>", "terrain.boxes (" + box.name + ")", problem);
  }
  if (t.type == TerrainConfig::Type::Rough) {
    const std::string problem = positionProblem(Vec3(t.size_x, t.size_y, t.height_range));
    if (!problem.empty()) throw ConfigError("<world>", "terrain (size, height_range)", problem);
  }
  auto addStatic = [this](dGeomID g, const std::string& material, const std::string& name) {
    dGeomSetData(g, new GeomInfo{nullptr, material, name});
    static_geoms_.push_back(g);
  };
  if (t.type != TerrainConfig::Type::Rough && t.ground_plane) {
    addStatic(dCreatePlane(static_space_, 0, 0, 1, 0), kGround, "ground_plane");
  }
  for (const auto& box : t.boxes) {
    dGeomID g = dCreateBox(static_space_, box.size.x(), box.size.y(), box.size.z());
    dGeomSetPosition(g, box.center.x(), box.center.y(), box.center.z());
    const Quat q = quatFromRPY(0, box.pitch, box.yaw);
    dQuaternion oq{q.w(), q.x(), q.y(), q.z()};
    dGeomSetQuaternion(g, oq);
    addStatic(g, box.surface, box.name);
  }
  if (t.type == TerrainConfig::Type::Rough) {
    HeightMap map = makeHeightMap(t);
    heightfield_ = map.heights;
    heightfield_data_ = dGeomHeightfieldDataCreate();
    // ODE height fields are y-up; the geom is rotated so that its y axis is world z (see terrain.h).
    dGeomHeightfieldDataBuildDouble(heightfield_data_, heightfield_.data(), 0, t.size_x, t.size_y,
                                    map.cols, map.rows, 1.0, 0.0, 1.0, 0);
    const double lo = *std::min_element(heightfield_.begin(), heightfield_.end());
    const double hi = *std::max_element(heightfield_.begin(), heightfield_.end());
    dGeomHeightfieldDataSetBounds(heightfield_data_, lo - 0.01, hi + 0.01);
    dGeomID g = dCreateHeightfield(static_space_, heightfield_data_, 1);
    dMatrix3 R;
    dRFromAxisAndAngle(R, 1, 0, 0, M_PI / 2);
    dGeomSetRotation(g, R);
    addStatic(g, kGround, "rough_terrain");
  }
}

namespace {

/// Points (x, y) under a collision geom's own outline: a box's eight corners, a sphere's or a
/// cylinder's rim (eight points a circle, at each end of a cylinder), and the centre. Its axis-aligned
/// box reached further: a robot 2 cm clear of a wall at 45 deg had a corner of it over the wall and
/// was spawned on the wall's height, 10 cm up. Other classes: the corners of that box.
std::vector<std::pair<double, double>> footprintOf(dGeomID g) {
  const dReal* c = dGeomGetPosition(g);
  const dReal* R = dGeomGetRotation(g);  // 3x4, row-major
  auto world = [&](double x, double y, double z) {
    return std::pair<double, double>(c[0] + R[0] * x + R[1] * y + R[2] * z, c[1] + R[4] * x + R[5] * y + R[6] * z);
  };
  std::vector<std::pair<double, double>> out{{c[0], c[1]}};
  // Eight points of a circle about the geom's z axis at height z in its frame.
  auto rim = [&](double radius, double z) {
    for (int k = 0; k < 8; ++k) out.push_back(world(radius * std::cos(k * M_PI / 4), radius * std::sin(k * M_PI / 4), z));
  };
  switch (dGeomGetClass(g)) {
    case dBoxClass: {
      dVector3 size;
      dGeomBoxGetLengths(g, size);
      for (int sx : {-1, 1})
        for (int sy : {-1, 1})
          for (int sz : {-1, 1}) out.push_back(world(sx * size[0] / 2, sy * size[1] / 2, sz * size[2] / 2));
      break;
    }
    case dSphereClass:
      rim(dGeomSphereGetRadius(g), 0);
      break;
    case dCylinderClass: {
      dReal radius, length;
      dGeomCylinderGetParams(g, &radius, &length);
      rim(radius, -length / 2);
      rim(radius, length / 2);
      break;
    }
    default: {
      dReal aabb[6];
      dGeomGetAABB(g, aabb);
      for (double x : {aabb[0], aabb[1]})
        for (double y : {aabb[2], aabb[3]}) out.push_back({x, y});
    }
  }
  return out;
}

}  // namespace

Robot& World::addRobot(const RobotDescription& description, const Pose2D& pose, const std::string& name) {
  Robot& r = addRobotAt(description, Pose(Vec3(pose.x, pose.y, 0), quatFromRPY(0, 0, pose.yaw)), name);
  // Drop it onto the terrain: lowest collision point 1 mm above the highest ground below the robot.
  double lowest = std::numeric_limits<double>::infinity();
  double ground = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < dSpaceGetNumGeoms(r.space()); ++i) {
    const dGeomID g = dSpaceGetGeom(r.space(), i);
    dReal aabb[6];
    dGeomGetAABB(g, aabb);
    lowest = std::min(lowest, static_cast<double>(aabb[4]));
    for (const auto& [x, y] : footprintOf(g)) ground = std::max(ground, terrainHeight(x, y));
  }
  ground = std::max(ground, terrainHeight(pose.x, pose.y));
  Pose p = r.basePose();
  p.position.z() += ground - lowest + 0.001;
  r.setBasePose(p);
  return r;
}

std::string robotNameProblem(const std::string& name) {
  const auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); };
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  bool ok = !name.empty() && name.size() <= kMaxRobotNameLength && letter(name[0]);
  for (char c : name) ok = ok && (letter(c) || digit(c) || c == '_');
  if (ok) return "";
  return "invalid robot name '" + name.substr(0, kMaxRobotNameLength) + (name.size() > kMaxRobotNameLength ? "...'" : "'") +
         " (a ROS name of at most " + std::to_string(kMaxRobotNameLength) + " characters: a letter, then letters, digits or '_')";
}

Robot& World::addRobotAt(const RobotDescription& description, const Pose& pose, const std::string& name) {
  if (findRobot(name)) throw ConfigError("<world>", "robots", "duplicate robot name '" + name + "'");
  const std::string problem = robotNameProblem(name);
  if (!problem.empty()) throw ConfigError("<world>", "robots", problem);
  const std::string where = positionProblem(pose.position);
  if (!where.empty()) throw ConfigError("<world>", "robots (" + name + ")", where);
  robots_.push_back(std::make_unique<Robot>(*this, description, name, next_index_++, pose));
  updateSolverIterations();
  return *robots_.back();
}

Robot& World::switchLevel(const std::string& name, const RobotDescription& description) {
  Robot& r = robot(name);
  r.switchDescription(description);
  updateSolverIterations();
  wakeAll();  // robots that touched or held the old model
  return r;
}

void World::updateSolverIterations() {
  int n = config_.solver_iterations;
  if (config_.level_iterations)
    for (const auto& r : robots_) n = std::max(n, r->description().solver_iterations);
  if (n != solver_iterations_) dWorldSetQuickStepNumIterations(world_, n);
  solver_iterations_ = n;
}

void World::removeRobot(const std::string& name) {
  auto it = std::find_if(robots_.begin(), robots_.end(), [&](const auto& r) { return r->name() == name; });
  if (it == robots_.end()) throw UnknownName("unknown robot '" + name + "'");
  connections_->removeRobot(name);
  robots_.erase(it);
  updateSolverIterations();
  wakeAll();  // robots that rested on it or against it
}

Robot* World::findRobot(const std::string& name) {
  for (auto& r : robots_)
    if (r->name() == name) return r.get();
  return nullptr;
}

Robot& World::robot(const std::string& name) {
  Robot* r = findRobot(name);
  if (!r) throw UnknownName("unknown robot '" + name + "'");
  return *r;
}

std::vector<Robot*> World::robots() {
  std::vector<Robot*> out;
  for (auto& r : robots_) out.push_back(r.get());
  return out;
}

// ODE itself enables, during the step, every disabled body that a joint (a robot-robot contact just
// made, a gripper or side-arm connection, a static link) ties to an enabled one. A robot woken that
// way would be solved without the terrain contacts its sleep skipped, and drop for a step; so wake
// those robots here, before the terrain is collided, until no sleeper is jointed to an awake body
// (a chain of held robots wakes link by link). The robot-robot pass skipped pairs of sleepers
// (handlePair): a robot woken here is collided with the robots that slept then, and a sleeper it
// touches wakes in turn, as the skipped contact would have woken it.
void World::wakeSleepersJointedToAwakeBodies() {
  const std::size_t n = robots_.size();
  std::vector<char> slept_in_pass(n), collided_again(n, 0);
  bool any_asleep = false;
  for (std::size_t i = 0; i < n; ++i) {
    slept_in_pass[i] = robots_[i]->asleep();
    any_asleep = any_asleep || slept_in_pass[i];
  }
  if (!any_asleep) return;  // a swarm that drives
  bool woke = true;
  while (woke) {
    woke = false;
    for (std::size_t i = 0; i < n; ++i) {
      Robot& r = *robots_[i];
      if (!r.asleep() || !jointedToAnEnabledBody(r)) continue;
      r.wakeByTouch();
      joinHeldBackContactsOf(r);
      for (std::size_t k = 0; k < n; ++k)  // a pair is collided once: skip robots already done
        if (k != i && slept_in_pass[k] && !collided_again[k]) collideRobots(r, *robots_[k]);
      collided_again[i] = 1;
      woke = true;
    }
  }
}

namespace {

/// The body that `joint` ties `body` to (null for the static world).
dBodyID otherBody(dJointID joint, dBodyID body) {
  return dJointGetBody(joint, 0) == body ? dJointGetBody(joint, 1) : dJointGetBody(joint, 0);
}

}  // namespace

bool World::jointedToAnEnabledBody(const Robot& robot) const {
  for (dBodyID b : robot.bodies()) {
    for (int i = 0, n = dBodyGetNumJoints(b); i < n; ++i) {
      const dJointID j = dBodyGetJoint(b, i);
      if (!dJointIsEnabled(j)) continue;  // ODE walks enabled joints only
      const dBodyID other = otherBody(j, b);
      if (other && dBodyIsEnabled(other)) return true;  // a sleeper's own bodies are all disabled
    }
  }
  return false;
}

void World::releaseHeldBackContacts() {
  if (held_back_.empty()) return;
  // Pushed: robots that are not standing, and every awake robot in contact with a pushed one.
  std::unordered_set<const Robot*> pushed;
  for (const auto& r : robots_)
    if (!r->asleep() && !r->standing()) pushed.insert(r.get());
  for (bool grew = !pushed.empty(); grew;) {
    grew = false;
    for (const auto& [a, b] : awake_touches_)
      if (pushed.count(a) != pushed.count(b)) grew = pushed.insert(pushed.count(a) ? b : a).second || grew;
  }
  for (const HeldBackContact& h : held_back_)
    if (pushed.count(h.standing)) dJointAttach(h.joint, h.body_a, h.body_b);  // wakes its sleeper below
}

void World::joinHeldBackContactsOf(const Robot& sleeper) {
  for (const HeldBackContact& h : held_back_)
    if (h.sleeper == &sleeper) dJointAttach(h.joint, h.body_a, h.body_b);
}

// Robots joined by a connection or a static link fall asleep together: a sleeper jointed to an
// awake robot is woken (above), so joined robots that became ready at different steps woke each
// other for ever (20 standing chains of 5: 95 of 100 asleep at the end, RTM 60 against 158).
void World::sleepRestingGroups() {
  const int n = static_cast<int>(robots_.size());
  std::vector<int> group(n);
  bool any_ready = false;
  for (int i = 0; i < n; ++i) {
    group[i] = i;
    any_ready = any_ready || robots_[i]->restReady();
  }
  if (!any_ready) return;
  auto find = [&](int i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  std::unordered_map<const Robot*, int> index;
  for (int i = 0; i < n; ++i) index[robots_[i].get()] = i;
  // The step's contacts are gone by now: the joints left between robots are connections and links.
  for (int i = 0; i < n; ++i) {
    for (dBodyID body : robots_[i]->bodies()) {
      for (int j = 0, nj = dBodyGetNumJoints(body); j < nj; ++j) {
        const dBodyID other = otherBody(dBodyGetJoint(body, j), body);
        const Robot* joined = other ? static_cast<const Robot*>(dBodyGetData(other)) : nullptr;
        if (joined && joined != robots_[i].get()) group[find(i)] = find(index.at(joined));
      }
    }
  }
  std::vector<char> moving(n, 0);  // a group with an awake robot that is not ready stays awake
  for (int i = 0; i < n; ++i)
    if (!robots_[i]->asleep() && !robots_[i]->restReady()) moving[find(i)] = 1;
  for (int i = 0; i < n; ++i)
    if (robots_[i]->restReady() && !moving[find(i)]) robots_[i]->sleepAtRest();
}

void World::wakeAll() {
  for (auto& r : robots_)
    if (r->asleep()) r->wake();
}

void World::enableProfile(bool on) {
  profiling_ = on;
  profile_ = StepProfile{};
}

void World::step() {
  using Clock = std::chrono::steady_clock;
  // Phase boundaries; each lap adds the time since the previous one to its phase (profiling only).
  Clock::time_point mark;
  if (profiling_) mark = Clock::now();
  auto lap = [&](double& phase) {
    if (!profiling_) return;
    const Clock::time_point now = Clock::now();
    phase += std::chrono::duration<double>(now - mark).count();
    mark = now;
  };
  const double dt = config_.step;
  const OdeStepScope ode_scope(*this);
  // A new gravity (a slope experiment tilts it) disturbs every robot.
  dVector3 ode_g;
  dWorldGetGravity(world_, ode_g);
  const Vec3 g(ode_g[0], ode_g[1], ode_g[2]);
  if (g != stepped_gravity_) wakeAll();
  stepped_gravity_ = g;
  for (auto& r : robots_) r->wakeIfDisturbed();
  for (auto& r : robots_) r->applyCommands(dt, effects_);
  lap(profile_.commands_s);
  for (auto& r : robots_) r->updateStanding();
  held_back_.clear();
  awake_touches_.clear();
  dSpaceCollide(space_, this, &nearCallback);  // robot against robot
  releaseHeldBackContacts();
  wakeSleepersJointedToAwakeBodies();
  // A sleeping robot's contacts with the terrain join no island (ODE solves only what an enabled
  // body reaches), so they are not made: in an idle swarm they were most of the step.
  for (auto& r : robots_)
    if (!r->asleep()) collideWithTerrain(*r);
  lap(profile_.collision_s);
  // QuickStep shuffles constraints with ODE's one global generator; reseeding it from the step
  // count makes every run of a scenario bit-identical whatever other worlds did in this process.
  // (Worlds in parallel threads would share that generator: run parallel simulations as processes.)
  dRandSetSeed(static_cast<unsigned long>(stableHash(config_.seed, std::to_string(steps_))));
  noteOdePhase("the solver");
  if (exact_solver_)
    dWorldStep(world_, dt);
  else
    dWorldQuickStep(world_, dt);
  lap(profile_.solver_s);
  updateDriveWheelLoads();
  dJointGroupEmpty(contacts_);
  for (auto& r : robots_) r->readFeedback(dt);
  time_ += dt;
  ++steps_;
  for (auto& r : robots_) r->updateRest(config_.rest);
  sleepRestingGroups();
  lap(profile_.feedback_s);
  ++profile_.steps;
}

namespace {

/// ODE's bounding-box overlap test (collideAABBs): boxes that touch meet.
bool boxesMeet(const dReal* a, const dReal* b) {
  return !(a[0] > b[1] || a[1] < b[0] || a[2] > b[3] || a[3] < b[2] || a[4] > b[5] || a[5] < b[4]);
}

/// The geoms of `space` with their boxes, in the space's own list order (ODE's, newest first; the
/// order its collide2 visits them).
void readBoxedGeoms(dSpaceID space, std::vector<World::BoxedGeom>& out) {
  const int n = dSpaceGetNumGeoms(space);
  out.resize(n);
  for (int i = 0; i < n; ++i) {
    out[i].geom = dSpaceGetGeom(space, i);
    dGeomGetAABB(out[i].geom, out[i].aabb);
  }
}

}  // namespace

void World::indexTerrain() { readBoxedGeoms(static_space_, terrain_index_); }

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

namespace {

/// The robot whose geoms `g` holds if `g` is a robot's space (Robot sets itself as its data).
const Robot* robotOfSpace(dGeomID g) { return dGeomIsSpace(g) ? static_cast<const Robot*>(dGeomGetData(g)) : nullptr; }

}  // namespace

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
  // Robot against robot: a sleeper that a standing (settling) robot touches stays asleep; two
  // settling neighbours used to wake each other for ever (README, "Sleeping at rest").
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
      wheel_contacts_.push_back({{}, ctx.normal, wheel_a ? ia->robot : nullptr, wheel_b ? ib->robot : nullptr, ba == nullptr,
                                 wheel_a && ia->track >= 0, wheel_b && ib->track >= 0});
      dJointSetFeedback(c, &wheel_contacts_.back().feedback);
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
  for (const WheelContact& w : wheel_contacts_) {
    // The contact normal points from geom 2 into geom 1: body 1 is pushed along it, body 2
    // against it. A contact whose body 1 is static is stored reversed by ODE: its body 2's force
    // is reported in f1.
    add(w.wheel_of_body1, w.feedback.f1, 1.0, w.normal, w.on_wheel1);
    add(w.wheel_of_body2, w.body1_static ? w.feedback.f1 : w.feedback.f2, -1.0, w.normal, w.on_wheel2);
  }
  wheel_contacts_.clear();
}

namespace {

struct RayQuery {
  const Robot* ignore;
  RayHit* best;
};

// Test the ray against one geom and keep the nearest hit.
void rayAgainstGeom(RayQuery& q, dGeomID ray, dGeomID other) {
  const GeomInfo* gi = infoOf(other);
  if (gi && q.ignore && gi->robot == q.ignore) return;  // a sensor does not see its own robot
  dContactGeom c;
  if (dCollide(ray, other, 1, &c, sizeof(c)) != 1 || c.depth >= q.best->distance) return;
  RayHit& b = *q.best;
  b.hit = true;
  b.distance = c.depth;
  b.point = Vec3(c.pos[0], c.pos[1], c.pos[2]);
  b.normal = Vec3(c.normal[0], c.normal[1], c.normal[2]);
  b.surface = gi ? gi->material : kGround;
  b.robot = gi ? gi->robot : nullptr;
}

// The query walks of castRay and castRays: when (o1, o2) involves a robot's space, descend into it
// with `callback` unless it is the ignored robot's (skips its ~20 geoms at once) and return true.
bool descendIntoSpace(void* data, dGeomID o1, dGeomID o2, const Robot* ignore, dNearCallback* callback) {
  if (!dGeomIsSpace(o1) && !dGeomIsSpace(o2)) return false;
  const dGeomID sub = dGeomIsSpace(o1) ? o1 : o2;
  if (!ignore || sub != reinterpret_cast<dGeomID>(ignore->space())) dSpaceCollide2(o1, o2, data, callback);
  return true;
}

void rayCallback(void* data, dGeomID o1, dGeomID o2) {
  auto& q = *static_cast<RayQuery*>(data);
  if (descendIntoSpace(data, o1, o2, q.ignore, &rayCallback)) return;
  const bool first_is_ray = dGeomGetClass(o1) == dRayClass;
  rayAgainstGeom(q, first_is_ray ? o1 : o2, first_is_ray ? o2 : o1);
}

}  // namespace

namespace {

struct OverlapQuery {
  const Robot* robot;
  World::Overlap* deepest;
};

void overlapCallback(void* data, dGeomID o1, dGeomID o2) {
  auto& q = *static_cast<OverlapQuery*>(data);
  if (o1 == o2) return;  // the robot's own space, met inside the world's
  if (dGeomIsSpace(o1) || dGeomIsSpace(o2)) {
    dSpaceCollide2(o1, o2, data, &overlapCallback);
    return;
  }
  const GeomInfo *a = infoOf(o1), *b = infoOf(o2);
  const bool a_own = a && a->robot == q.robot, b_own = b && b->robot == q.robot;
  if (a_own == b_own) return;  // two of its own geoms (its joints decide), or neither
  dContactGeom c[4];
  const int n = dCollide(o1, o2, 4, c, sizeof(dContactGeom));
  const GeomInfo* other = a_own ? b : a;
  for (int i = 0; i < n; ++i) {
    if (c[i].depth <= q.deepest->depth) continue;
    q.deepest->depth = c[i].depth;
    if (other && other->robot) q.deepest->with = "robot '" + other->robot->name() + "'";
    else if (other && other->material != kGround) q.deepest->with = "box '" + other->link + "'";
    else q.deepest->with = "the ground";
  }
}

}  // namespace

World::Overlap World::deepestOverlap(const Robot& robot, bool robots_only) const {
  Overlap deepest;
  OverlapQuery q{&robot, &deepest};
  const dGeomID own = reinterpret_cast<dGeomID>(robot.space());
  if (!robots_only) dSpaceCollide2(own, reinterpret_cast<dGeomID>(static_space_), &q, &overlapCallback);
  dSpaceCollide2(own, reinterpret_cast<dGeomID>(space_), &q, &overlapCallback);
  return deepest;
}

std::string World::robotsOverlapProblem() const {
  for (const auto& r : robots_) {
    const Overlap o = deepestOverlap(*r, true);
    if (o.depth <= kPlacementTolerance) continue;
    std::ostringstream why;
    why << "robot '" << r->name() << "' and " << o.with << " overlap by " << std::fixed << std::setprecision(3)
        << o.depth << " m at their start poses (at most " << kPlacementTolerance << " m)";
    return why.str();
  }
  return "";
}

std::string World::placeRobot(Robot& robot, const Pose& pose) {
  const std::vector<Robot::BodyState> before = robot.bodyStates();
  robot.setBasePose(pose);
  const Overlap o = deepestOverlap(robot);
  if (o.depth <= kPlacementTolerance) return "";
  robot.setBodyStates(before);
  std::ostringstream why;
  why << "robot '" << robot.name() << "' there would sit " << std::fixed << std::setprecision(3) << o.depth
      << " m deep inside " << o.with << " (at most " << kPlacementTolerance << " m): not moved";
  return why.str();
}

dGeomID World::queryRay(double length) const {
  if (!query_ray_) {
    query_ray_ = dCreateRay(nullptr, length);
    dGeomRaySetClosestHit(query_ray_, 1);
  }
  dGeomRaySetLength(query_ray_, length);
  return query_ray_;
}

RayHit World::castRay(const Vec3& origin, const Vec3& direction, double length, const Robot* ignore) const {
  RayHit best;
  best.distance = length;
  dGeomID ray = queryRay(length);
  const Vec3 d = direction.normalized();
  dGeomRaySet(ray, origin.x(), origin.y(), origin.z(), d.x(), d.y(), d.z());
  RayQuery query{ignore, &best};
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(space_), &query, &rayCallback);
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(static_space_), &query, &rayCallback);
  return best;
}

namespace {

struct BoxQuery {
  dGeomID box;
  const Robot* ignore;
  std::vector<World::BoxedGeom>* found;
};

/// Whether the segment from `origin` to `end` has a bounding box that meets `aabb` (ODE's layout).
/// An axis-aligned ground plane's box is the half space below it, so the proximity ring's level
/// rays skip it (most of a flat-ground ring's ray tests, each a dGeomRaySet and a dCollide).
bool segmentMayMeet(const Vec3& origin, const Vec3& end, const dReal* aabb) {
  dReal segment[6];
  for (int k = 0; k < 3; ++k) {
    segment[2 * k] = std::min(origin[k], end[k]);
    segment[2 * k + 1] = std::max(origin[k], end[k]);
  }
  return boxesMeet(segment, aabb);
}

// Collect the geoms whose bounding boxes meet the query box.
void boxCallback(void* data, dGeomID o1, dGeomID o2) {
  auto& q = *static_cast<BoxQuery*>(data);
  if (descendIntoSpace(data, o1, o2, q.ignore, &boxCallback)) return;
  const dGeomID other = o1 == q.box ? o2 : o1;
  const GeomInfo* gi = infoOf(other);
  if (gi && q.ignore && gi->robot == q.ignore) return;
  World::BoxedGeom c;
  c.geom = other;
  dGeomGetAABB(other, c.aabb);
  q.found->push_back(c);
}

/// Grows [lo, hi] to hold the segments of the n unit `directions` from `origin`, `length` long.
void growRayBounds(const Vec3& origin, const Vec3* directions, std::size_t n, double length, Vec3& lo, Vec3& hi) {
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 end = origin + directions[i] * length;
    lo = lo.cwiseMin(origin).cwiseMin(end);
    hi = hi.cwiseMax(origin).cwiseMax(end);
  }
}

}  // namespace

const Vec3* World::unitDirections(const std::vector<Vec3>& directions) const {
  ray_units_.resize(directions.size());
  for (std::size_t i = 0; i < directions.size(); ++i) ray_units_[i] = directions[i].normalized();
  return ray_units_.data();
}

void World::findRayCandidates(const Vec3& lo, const Vec3& hi, const Robot* ignore) const {
  constexpr double kMargin = 1e-6;  // [m] keeps the box's sides from vanishing (axis-aligned rays)
  if (!query_box_) query_box_ = dCreateBox(nullptr, 1, 1, 1);
  const Vec3 centre = 0.5 * (lo + hi), size = (hi - lo).array() + 2 * kMargin;
  dGeomBoxSetLengths(query_box_, size.x(), size.y(), size.z());
  dGeomSetPosition(query_box_, centre.x(), centre.y(), centre.z());
  ray_candidates_.clear();
  BoxQuery box{query_box_, ignore, &ray_candidates_};
  dSpaceCollide2(query_box_, reinterpret_cast<dGeomID>(space_), &box, &boxCallback);
  dSpaceCollide2(query_box_, reinterpret_cast<dGeomID>(static_space_), &box, &boxCallback);
}

void World::castAgainstCandidates(const Vec3& origin, const Vec3* directions, std::size_t n, double length,
                                  const Robot* ignore, RayHit* hits) const {
  RayHit miss;
  miss.distance = length;
  std::fill(hits, hits + n, miss);
  if (ray_candidates_.empty()) return;
  dGeomID ray = queryRay(length);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& d = directions[i];
    const Vec3 end = origin + d * length;
    bool ray_set = false;
    RayQuery query{ignore, &hits[i]};
    for (const BoxedGeom& c : ray_candidates_) {
      if (!segmentMayMeet(origin, end, c.aabb)) continue;
      if (!ray_set) dGeomRaySet(ray, origin.x(), origin.y(), origin.z(), d.x(), d.y(), d.z());
      ray_set = true;
      rayAgainstGeom(query, ray, c.geom);
    }
  }
}

// One broad-phase search for the box around every ray's segment instead of one per ray (for a
// sensor's 5-ray cone that was most of the cost of a ray: ODE's space traversal) or per bundle (a
// 15-sensor ring); a ray can only hit a geom whose bounding box meets its segment's, so the hits
// are castRay's.
std::vector<RayHit> World::castRays(const Vec3& origin, const std::vector<Vec3>& directions, double length,
                                    const Robot* ignore) const {
  const Vec3* units = unitDirections(directions);
  Vec3 lo = origin, hi = origin;
  growRayBounds(origin, units, directions.size(), length, lo, hi);
  if (directions.empty()) ray_candidates_.clear();
  else findRayCandidates(lo, hi, ignore);
  std::vector<RayHit> hits(directions.size());
  castAgainstCandidates(origin, units, directions.size(), length, ignore, hits.data());
  return hits;
}

std::vector<RayHit> World::castRayBundles(const std::vector<Vec3>& origins, const std::vector<Vec3>& directions,
                                          double length, const Robot* ignore) const {
  if (origins.empty() ? !directions.empty() : directions.size() % origins.size() != 0)
    throw std::invalid_argument("castRayBundles: " + std::to_string(directions.size()) +
                                " directions do not make equal bundles for " + std::to_string(origins.size()) +
                                " origins");
  std::vector<RayHit> hits(directions.size());
  if (origins.empty()) return hits;
  const std::size_t n = directions.size() / origins.size();
  const Vec3* units = unitDirections(directions);
  Vec3 lo = origins.front(), hi = origins.front();
  for (std::size_t k = 0; k < origins.size(); ++k) growRayBounds(origins[k], units + k * n, n, length, lo, hi);
  findRayCandidates(lo, hi, ignore);
  for (std::size_t k = 0; k < origins.size(); ++k)
    castAgainstCandidates(origins[k], units + k * n, n, length, ignore, &hits[k * n]);
  return hits;
}

namespace {

/// Whether the segment from `origin` along unit `d`, `length` long, crosses `aabb` (ODE's layout;
/// the slab test). Unlike segmentMayMeet's box against box, a long diagonal segment misses most of
/// the boxes its own box covers.
bool segmentCrosses(const Vec3& origin, const Vec3& d, double length, const dReal* aabb) {
  constexpr double kSlack = 1e-9;  // [m] a ray grazing a box's face is tested, as ODE would
  double t0 = 0, t1 = length;
  for (int k = 0; k < 3; ++k) {
    const double lo = aabb[2 * k] - kSlack, hi = aabb[2 * k + 1] + kSlack;
    if (std::abs(d[k]) < 1e-12) {
      if (origin[k] < lo || origin[k] > hi) return false;
      continue;
    }
    double ta = (lo - origin[k]) / d[k], tb = (hi - origin[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

/// A stand-in for atan2(dy, dx) that needs no trigonometry (the "diamond angle"), in (-2, 2]: 0
/// along +x, +-1 along +-y, 2 along -x. It grows with the bearing, and turning half a turn adds 2,
/// which is all the sectors below need (they are then up to 2x wider in angle at the diagonals).
double diamondBearing(double dx, double dy) {
  const double sum = std::abs(dx) + std::abs(dy);
  if (sum == 0) return 0;
  const double t = dy / sum;  // [-1, 1]
  return dx >= 0 ? t : (dy >= 0 ? 2 - t : -2 - t);
}

/// castRaysOfLengths' groups filed by the bearing sectors (of kSectors about the origin, equal in
/// diamondBearing) their boxes cover; `of[k]` lists the groups a ray of sector k may cross, nearest
/// box first.
struct SectorIndex {
  static constexpr int kSectors = 64;
  static constexpr double kTurn = 4;  ///< a full turn in diamondBearing
  std::vector<std::vector<std::size_t>> of;
  std::vector<std::size_t> all;  ///< every group (for rays with no bearing), nearest box first
  std::vector<double> near;      ///< [m] each group's box's distance from the origin (0: around it)
  int sectorOf(const Vec3& d) const { return sectorOfBearing(diamondBearing(d.x(), d.y())); }
  static int sectorOfBearing(double bearing) {
    const int k = static_cast<int>(std::floor((bearing + kTurn / 2) / kTurn * kSectors));
    return ((k % kSectors) + kSectors) % kSectors;
  }
};

template <class Group>
SectorIndex fileBySector(const Vec3& origin, const std::vector<Group>& groups) {
  constexpr double kMargin = 1e-6;  // bearings at a sector's edge are filed on both sides
  SectorIndex index;
  index.of.resize(SectorIndex::kSectors);
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    index.all.push_back(gi);
    const dReal* b = groups[gi].aabb;
    double near2 = 0;  // (an unbounded side adds nothing: max(-inf, 0) = 0)
    for (int k = 0; k < 3; ++k) {
      const double outside = std::max({b[2 * k] - origin[k], 0.0, origin[k] - b[2 * k + 1]});
      near2 += outside * outside;
    }
    // A box with NaN bounds (none is known) would break the sort below: it goes first instead.
    index.near.push_back(std::isfinite(near2) ? std::sqrt(near2) : 0.0);
    const bool around = origin.x() >= b[0] && origin.x() <= b[1] && origin.y() >= b[2] && origin.y() <= b[3];
    if (around || !std::isfinite(b[0] + b[1] + b[2] + b[3])) {  // seen from inside, or unbounded (a plane)
      for (auto& sector : index.of) sector.push_back(gi);
      continue;
    }
    // A box that does not hold the origin spans less than half a turn: its corners' bearings about
    // the bearing of its centre give the interval.
    const double centre = diamondBearing(0.5 * (b[0] + b[1]) - origin.x(), 0.5 * (b[2] + b[3]) - origin.y());
    double lo = 0, hi = 0;
    for (int cx = 0; cx < 2; ++cx)
      for (int cy = 2; cy < 4; ++cy) {
        const double rel =
            std::remainder(diamondBearing(b[cx] - origin.x(), b[cy] - origin.y()) - centre, SectorIndex::kTurn);
        lo = std::min(lo, rel);
        hi = std::max(hi, rel);
      }
    const int first = SectorIndex::sectorOfBearing(centre + lo - kMargin);
    const int span = SectorIndex::sectorOfBearing(centre + hi + kMargin) - first;
    const int count = (span + SectorIndex::kSectors) % SectorIndex::kSectors + 1;
    for (int k = 0; k < count; ++k) index.of[(first + k) % SectorIndex::kSectors].push_back(gi);
  }
  auto nearestFirst = [&](std::size_t a, std::size_t b) { return index.near[a] < index.near[b]; };
  for (auto& sector : index.of) std::stable_sort(sector.begin(), sector.end(), nearestFirst);
  std::stable_sort(index.all.begin(), index.all.end(), nearestFirst);
  return index;
}

}  // namespace

std::vector<RayHit> World::castRaysOfLengths(const Vec3& origin, const std::vector<Vec3>& directions,
                                             const std::vector<double>& lengths, const Robot* ignore) const {
  if (directions.size() != lengths.size())
    throw std::invalid_argument("castRaysOfLengths: " + std::to_string(directions.size()) + " directions but " +
                                std::to_string(lengths.size()) + " lengths");
  std::vector<RayHit> hits(directions.size());
  for (std::size_t i = 0; i < hits.size(); ++i) hits[i].distance = lengths[i];
  if (directions.empty()) return hits;
  const Vec3* units = unitDirections(directions);
  Vec3 lo = origin, hi = origin;
  for (std::size_t i = 0; i < directions.size(); ++i) growRayBounds(origin, units + i, 1, lengths[i], lo, hi);
  findRayCandidates(lo, hi, ignore);
  // Runs of one robot's geoms (the search descends into a robot's space and lists its geoms
  // together), each with the box around them.
  candidate_groups_.clear();
  for (std::size_t i = 0; i < ray_candidates_.size(); ++i) {
    const GeomInfo* gi = infoOf(ray_candidates_[i].geom);
    const Robot* robot = gi ? gi->robot : nullptr;
    const GeomInfo* prev = i > 0 ? infoOf(ray_candidates_[i - 1].geom) : nullptr;
    const bool extends = i > 0 && robot && prev && prev->robot == robot;
    if (!extends) {
      CandidateGroup g{i, i, {}};
      std::copy(ray_candidates_[i].aabb, ray_candidates_[i].aabb + 6, g.aabb);
      candidate_groups_.push_back(g);
    }
    CandidateGroup& g = candidate_groups_.back();
    g.end = i + 1;
    for (int k = 0; k < 3; ++k) {
      g.aabb[2 * k] = std::min(g.aabb[2 * k], ray_candidates_[i].aabb[2 * k]);
      g.aabb[2 * k + 1] = std::max(g.aabb[2 * k + 1], ray_candidates_[i].aabb[2 * k + 1]);
    }
  }
  // Every ray leaves the same origin, so a group's box can only be crossed by the rays whose
  // bearing (azimuth about the origin) lies within the bearings of its corners: the groups are
  // filed by bearing sector, and a ray tests its own sector's (a group whose box holds the origin
  // in plan, or has no bounds, such as a ground plane, is filed in every sector).
  const SectorIndex sectors = fileBySector(origin, candidate_groups_);
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const Vec3& d = units[i];
    if (!(lengths[i] > 0)) continue;
    dGeomID ray = nullptr;
    RayQuery query{ignore, &hits[i]};
    const bool steep = d.x() * d.x() + d.y() * d.y() < 1e-18;  // no bearing: test every group
    const std::vector<std::size_t>& filed = steep ? sectors.all : sectors.of[sectors.sectorOf(d)];
    for (std::size_t gi : filed) {
      // Nearest box first: once a box lies beyond the nearest hit so far (at first, the line's
      // end), so do all the others, and nothing in them can be nearer.
      const double reach = hits[i].distance;
      if (sectors.near[gi] >= reach) break;
      const CandidateGroup& g = candidate_groups_[gi];
      if (!segmentCrosses(origin, d, reach, g.aabb)) continue;
      for (std::size_t c = g.begin; c < g.end; ++c) {
        if (g.end - g.begin > 1 && !segmentCrosses(origin, d, hits[i].distance, ray_candidates_[c].aabb)) continue;
        if (!ray) {
          ray = queryRay(lengths[i]);
          dGeomRaySet(ray, origin.x(), origin.y(), origin.z(), d.x(), d.y(), d.z());
        }
        rayAgainstGeom(query, ray, ray_candidates_[c].geom);
      }
    }
  }
  return hits;
}

double World::terrainHeight(double x, double y) const {
  // Cast down against static geometry only: handles planes, tilted boxes and height fields alike.
  double best = config_.terrain.type == TerrainConfig::Type::Rough || !config_.terrain.ground_plane
                    ? -std::numeric_limits<double>::infinity()
                    : 0.0;
  constexpr double kTop = 100.0;
  dGeomID ray = queryRay(2 * kTop);
  dGeomRaySet(ray, x, y, kTop, 0, 0, -1);
  // Through the static space: its bounding-box test skips the geoms not under (x, y) (a composite
  // course has hundreds of boxes; testing each was 10 % of a model-switching run).
  struct Highest {
    double top, best;
  } q{kTop, best};
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(static_space_), &q, [](void* data, dGeomID a, dGeomID b) {
    auto& h = *static_cast<Highest*>(data);
    dContactGeom c;
    if (dCollide(a, b, 1, &c, sizeof(c)) == 1) h.best = std::max(h.best, h.top - c.depth);
  });
  best = q.best;
  return std::isfinite(best) ? best : 0.0;
}

}  // namespace sbot
