// The world: ODE's world and collision spaces, the robots in it, gravity and the fixed-step loop.
// Contacts (world_contacts.cpp), sleeping and waking (world_sleep.cpp), ray queries
// (world_rays.cpp), the terrain (world_terrain.cpp) and placing robots (world_placement.cpp) are
// World's other parts, each in its own file.
#include "sbot_sim/core/world.h"

#include <atomic>
#include <cstdarg>
#include <cstdio>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <string>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/random_streams.h"
#include "ode_errors.h"
#include "world_internal.h"

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

}  // namespace

World::World(const WorldConfig& config)
    : config_(config), wheel_contacts_(std::make_unique<std::deque<WheelContact>>()) {
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

void World::setGravity(const Vec3& g) { dWorldSetGravity(world_, g.x(), g.y(), g.z()); }

Vec3 World::gravity() const {
  dVector3 g;
  dWorldGetGravity(world_, g);
  return Vec3(g[0], g[1], g[2]);
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

}  // namespace sbot
