#include "sim_ros_interface.h"

#include "publication_stamps.h"
#include "robot_lookup.h"
#include "sbot_sim/core/input_limits.h"

#include "sbot_sim/core/scenario_world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <ros/callback_queue.h>
#include <rosgraph_msgs/Clock.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sbot_sim/ros/typed_param.h"

namespace sbot_node {

namespace {

using SteadyClock = std::chrono::steady_clock;

double secondsSince(SteadyClock::time_point t) {
  return std::chrono::duration<double>(SteadyClock::now() - t).count();
}

/// If the loop falls this far behind the requested real-time factor (slow machine, debugger, a
/// blocking service), it re-anchors instead of racing to catch up. [s wall]
constexpr double kMaxPacingLag = 0.25;

}  // namespace

volatile std::sig_atomic_t SimRosInterface::stop_requested_ = 0;

void SimRosInterface::requestStop(int) { stop_requested_ = 1; }

SimRosInterface::SimRosInterface() : pnh_("~") {}

SimRosInterface::~SimRosInterface() {
  // Interfaces hold pointers into the world: drop them first.
  modules_.reset();  // modules hold references into the world
  robots_.clear();
  world_.reset();
}

bool SimRosInterface::readParams() {
  bool ok = true;
  if (!pnh_.getParam("scenario", params_.scenario) || params_.scenario.empty()) {
    ROS_FATAL("simulator: private parameter ~scenario (path of the scenario YAML) is required, e.g. "
              "_scenario:=$(rospack find swarmbot3d)/config/scenarios/flat_swarm.yaml");
    return false;
  }
  // Defaults: SimParams (sim_ros_interface.h).
  ok &= sbot_ros_params::readTypedParam(pnh_, "robots", params_.robots);
  ok &= sbot_ros_params::readTypedParam(pnh_, "level", params_.level);
  ok &= sbot_ros_params::readTypedParam(pnh_, "real_time_factor", params_.real_time_factor);
  ok &= sbot_ros_params::readTypedParam(pnh_, "duration", params_.duration);
  ok &= sbot_ros_params::readTypedParam(pnh_, "publish_rate", params_.publish_rate);
  ok &= sbot_ros_params::readTypedParam(pnh_, "paused", params_.paused);
  ok &= sbot_ros_params::readTypedParam(pnh_, "set_description_params", params_.set_description_params);
  ok &= sbot_ros_params::readTypedParam(pnh_, "effects", params_.effects);
  ok &= sbot_ros_params::readTypedParam(pnh_, "lockstep", params_.lockstep.enabled);
  ok &= sbot_ros_params::readTypedParam(pnh_, "lockstep_controllers", params_.lockstep.controllers);
  ok &= sbot_ros_params::readTypedParam(pnh_, "lockstep_timeout", params_.lockstep.timeout);
  {  // Read by the modules, markers and graph publishers (their ranges are checked there): types here.
    bool flag = false;
    int whole = 0;
    double number = 0;
    ok &= sbot_ros_params::readTypedParam(pnh_, "modules", flag);
    ok &= sbot_ros_params::readTypedParam(pnh_, "per_sensor_topics", flag);
    ok &= sbot_ros_params::readTypedParam(pnh_, "marker_rate", number);
    ok &= sbot_ros_params::readTypedParam(pnh_, "trail_length", whole);
    ok &= sbot_ros_params::readTypedParam(pnh_, "graph_rate", number);
    // The raw camera's buffers are width x height: 100000 x 100000 px ran out of memory mid-run.
    for (const char* side : {"camera/width", "camera/height"}) {
      whole = 0;
      ok &= sbot_ros_params::readTypedParam(pnh_, side, whole);
      if (whole > 4096) {
        ROS_FATAL("simulator: ~%s must be <= 4096 px, got %d", side, whole);
        ok = false;
      }
    }
    ok &= sbot_ros_params::readTypedParam(pnh_, "camera/internal_scale", whole);
    ok &= ModulesRosInterface::checkRateParams(pnh_);
  }
  ROS_INFO("simulator: ~scenario=%s ~robots=%d ~level=%s ~real_time_factor=%g ~duration=%g ~publish_rate=%g "
           "~paused=%s ~set_description_params=%s ~effects=%s", params_.scenario.c_str(), params_.robots,
           params_.level.empty() ? "(the scenario's)" : params_.level.c_str(),
           params_.real_time_factor, params_.duration, params_.publish_rate, params_.paused ? "true" : "false",
           params_.set_description_params ? "true" : "false",
           params_.effects.empty() ? "(the scenario's)" : params_.effects.c_str());
  ROS_INFO("simulator: ~lockstep=%s ~lockstep_controllers=%d ~lockstep_timeout=%g", params_.lockstep.enabled ? "true" : "false",
           params_.lockstep.controllers, params_.lockstep.timeout);
  const auto& levels = sbot::modelLevels();
  if (!params_.level.empty() && std::find(levels.begin(), levels.end(), params_.level) == levels.end()) {
    ROS_FATAL("simulator: ~level must be fast, simple, basic, medium or detailed (empty: the scenario's levels), "
              "got '%s'", params_.level.c_str());
    ok = false;
  }
  if (params_.robots < -1) {
    ROS_FATAL("simulator: ~robots must be -1 (the scenario's count) or >= 0, got %d", params_.robots);
    ok = false;
  }
  if (!std::isfinite(params_.real_time_factor) || params_.real_time_factor < 0) {
    ROS_FATAL("simulator: ~real_time_factor must be >= 0 (0 = as fast as possible), got %g",
              params_.real_time_factor);
    ok = false;
  }
  if (!std::isfinite(params_.duration) || params_.duration < 0) {
    ROS_FATAL("simulator: ~duration must be >= 0 s (0 = the scenario's), got %g", params_.duration);
    ok = false;
  }
  if (params_.lockstep.controllers < 0) {
    ROS_FATAL("simulator: ~lockstep_controllers must be >= 0 (controllers to await before the first step), got %d",
              params_.lockstep.controllers);
    ok = false;
  }
  if (!std::isfinite(params_.lockstep.timeout) || params_.lockstep.timeout <= 0) {
    ROS_FATAL("simulator: ~lockstep_timeout must be > 0 s wall, got %g", params_.lockstep.timeout);
    ok = false;
  }
  if (params_.lockstep.controllers > 0 && !params_.lockstep.enabled)
    ROS_WARN("simulator: ~lockstep_controllers=%d has no effect without ~lockstep true", params_.lockstep.controllers);
  if (!std::isfinite(params_.publish_rate) || params_.publish_rate <= 0) {
    ROS_FATAL("simulator: ~publish_rate must be > 0 Hz, got %g", params_.publish_rate);
    ok = false;
  }
  return ok;
}

bool SimRosInterface::init() {
  if (!readParams()) return false;
  try {
    scenario_ = sbot::loadScenario(params_.scenario, params_.robots);
    // ~level: every robot at one level (the world's step and gravity stay the scenario's).
    if (!params_.level.empty()) {
      for (sbot::RobotSpawn& r : scenario_.robots) r.level = params_.level;
      sbot::checkGravityOfLevels(scenario_, params_.scenario + " with ~level " + params_.level);
    }
    if (!params_.effects.empty()) scenario_.effects_file = params_.effects;
    world_ = buildWorld();
  } catch (const sbot::ConfigError& e) {
    ROS_FATAL("simulator: %s", e.what());
    return false;
  } catch (const std::exception& e) {
    ROS_FATAL("simulator: cannot load scenario %s: %s", params_.scenario.c_str(), e.what());
    return false;
  }
  end_time_ = params_.duration > 0 ? params_.duration : scenario_.duration;
  paused_ = params_.paused;

  // Every node started after this one follows /clock (the launch files set it too).
  ros::param::set("/use_sim_time", true);
  // Read by libsbot_ros's initSwarmBot, which waits for the robots' services advertised below.
  ros::param::set("/sim/lockstep", params_.lockstep.enabled);

  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 1000);
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  markers_ = std::make_unique<MarkerPublisher>(nh_, pnh_);
  swarm_ = std::make_unique<SwarmRosInterface>(nh_, pnh_, world_, robots_, params_.set_description_params);
  for (sbot::Robot* r : world_->robots())
    robots_.push_back(std::make_unique<RobotRosInterface>(nh_, *r, params_.set_description_params));
  if (params_.lockstep.enabled) {
    std::vector<std::string> names;
    for (const auto& r : robots_) names.push_back(r->name());
    publicationStamps().enable();
    lockstep_ = std::make_unique<LockstepGate>(nh_, params_.lockstep, names, [this](const std::string& name) {
      std::string why;
      return lookupRobot(world_.get(), name, why) ? std::string() : why;
    });
  }
  bool modules = true;  // ~modules: false = no sensor/actuator modules (benchmarking the bare node)
  pnh_.param("modules", modules, true);
  ROS_INFO("simulator: ~modules=%s", modules ? "true" : "false");
  if (modules) {
    modules_ = std::make_unique<ModulesRosInterface>(nh_, pnh_, world_, scenario_);
    modules_->attach();
  }
  if (swarm_ && modules_) {  // spawn / delete / model switch keep the modules bound
    swarm_->before_delete.push_back([this](sbot::Robot& r) { modules_->robotRemoving(r); });
    swarm_->after_spawn.push_back([this](sbot::Robot& r) { modules_->robotAdded(r); });
    swarm_->after_switch.push_back([this](sbot::Robot& r) { modules_->robotRebuilt(r); });
  }

  ros::NodeHandle sim(nh_, "sim");
  pause_srv_ = sim.advertiseService("pause", &SimRosInterface::onPause, this);
  unpause_srv_ = sim.advertiseService("unpause", &SimRosInterface::onUnpause, this);
  reset_srv_ = sim.advertiseService("reset", &SimRosInterface::onReset, this);
  step_srv_ = sim.advertiseService("step", &SimRosInterface::onStep, this);
  set_pose_srv_ = sim.advertiseService("set_pose", &SimRosInterface::onSetPose, this);

  const double dt = world_->config().step;
  char duration[64] = "unlimited";
  if (end_time_ > 0) std::snprintf(duration, sizeof(duration), "%g s", end_time_);
  ROS_INFO("simulator: scenario %s: %zu robots (%s), step %g s, %d solver iterations, seed %llu, duration %s%s",
           scenario_.source.c_str(), world_->robotCount(), robotSummary(world_.get()).c_str(), dt,
           world_->solverIterations(), static_cast<unsigned long long>(world_->config().seed), duration,
           paused_ ? "; starting paused (call /sim/unpause or /sim/step)" : "");
  if (params_.publish_rate * dt > 1.0 + 1e-9)
    ROS_WARN("simulator: ~publish_rate %g Hz exceeds the step rate %g Hz: publishing every step",
             params_.publish_rate, 1.0 / dt);
  return true;
}

std::unique_ptr<sbot::World> SimRosInterface::buildWorld() const {
  std::unique_ptr<sbot::World> world = sbot::buildScenarioWorld(scenario_);
  if (!scenario_.effects_file.empty()) {
    std::vector<std::string> names;
    for (const sbot::EffectPtr& e : world->effects()) names.push_back(e->name());
    ROS_INFO("simulator: effects from %s: %s", scenario_.effects_file.c_str(),
             names.empty() ? "none" : sbot::nameList(names).c_str());
  }
  return world;
}

void SimRosInterface::publishClock() {
  rosgraph_msgs::Clock c;
  c.clock = stamp();
  clock_pub_.publish(c);
}

void SimRosInterface::publishStates() {
  // Publish on every step that crosses a multiple of 1/publish_rate: the average rate is exact even
  // when the step rate is not a multiple of it.
  const double dt = world_->config().step;
  const auto tick = static_cast<std::int64_t>(std::floor(static_cast<double>(total_steps_) * dt *
                                                         params_.publish_rate + 1e-6));
  if (tick == last_publish_tick_) return;
  last_publish_tick_ = tick;
  const ros::Time t = stamp();
  std::vector<geometry_msgs::TransformStamped> transforms;
  transforms.reserve(robots_.size());
  for (auto& r : robots_) r->publishState(t, transforms);
  if (!transforms.empty()) tf_broadcaster_->sendTransform(transforms);
}

void SimRosInterface::stepOnce() {
  world_->step();
  if (modules_) modules_->afterStep(simTime());  // battery, gripper, side arm; sensor topics
  ++total_steps_;
  publishClock();
  publishStates();
  if (markers_) markers_->update(*world_, simTime());
  if (swarm_) swarm_->update(simTime());
}

bool SimRosInterface::durationReached() const {
  return end_time_ > 0 && simTime() >= end_time_ - 1e-9;
}

void SimRosInterface::resetPacing() {
  pace_wall_ = SteadyClock::now();
  pace_sim_ = simTime();
}

double SimRosInterface::wallUntilNextStep() {
  if (params_.real_time_factor <= 0) return 0;
  // The step that brings the clock to simTime() + dt is due when the wall clock, scaled by the
  // real-time factor, gets there: /clock never runs ahead of rtf x wall time.
  const double next = simTime() + world_->config().step - pace_sim_;
  const double wait = next / params_.real_time_factor - secondsSince(pace_wall_);
  if (wait < -kMaxPacingLag) {
    resetPacing();
    return 0;
  }
  return wait;
}

int SimRosInterface::run() {
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  run_start_ = SteadyClock::now();
  run_start_sim_ = simTime();
  resetPacing();
  std::string reason = "shutdown requested";
  while (ros::ok()) {
    if (stop_requested_) {
      reason = "interrupted";
      break;
    }
    if (!world_) {
      logSummary("no world after a failed reset");
      return 1;
    }
    if (durationReached()) {
      reason = "duration reached";
      break;
    }
    if (paused_) {
      // Services (unpause, step, reset, set_pose) and commands are served while paused.
      const auto t = SteadyClock::now();
      queue->callAvailable(ros::WallDuration(0.05));
      paused_wall_ += secondsSince(t);
      resetPacing();
      continue;
    }
    const double wait = wallUntilNextStep();
    if (wait > 1e-6) {
      // Serve callbacks while waiting; loop again to re-check the pause flag and the deadline.
      queue->callAvailable(ros::WallDuration(std::min(wait, 0.05)));
      continue;
    }
    queue->callAvailable();  // commands received so far apply at this step
    if (paused_ || !ros::ok()) continue;
    if (lockstep_ && !lockstep_->mayStep()) {
      queue->callAvailable(ros::WallDuration(0.002));  // a controller is reading or sending
      continue;
    }
    try {
      stepOnce();
    } catch (const std::exception& e) {
      ROS_FATAL("simulator: step %llu at t=%.3f s failed: %s",
                static_cast<unsigned long long>(world_->stepCount()), simTime(), e.what());
      logSummary("error");
      return 1;
    }
  }
  logSummary(reason);
  return 0;
}

void SimRosInterface::logSummary(const std::string& reason) const {
  const double wall = secondsSince(run_start_);
  const double running = wall - paused_wall_;  // RTM over the time the simulation was running
  const double sim = (world_ ? simTime() : time_offset_) - run_start_sim_;
  char line[320];
  std::snprintf(line, sizeof(line),
                "simulator: %s: sim time %.3f s, wall time %.3f s (%.3f s paused), RTM %.3f, robots %zu, "
                "steps %llu, resets %llu", reason.c_str(), sim, wall, paused_wall_,
                running > 1e-9 ? sim / running : 0.0, robots_.size(),
                static_cast<unsigned long long>(total_steps_ - reset_count_),  // a reset counts one step
                static_cast<unsigned long long>(reset_count_));
  std::string text = line;
  if (lockstep_) text += "; " + lockstep_->summary();
  if (ros::ok()) {
    ROS_INFO("%s", text.c_str());
  } else {
    // Shut down from outside (rosnode kill, master gone): rosconsole no longer prints.
    std::printf("[ INFO] %s\n", text.c_str());
    std::fflush(stdout);
  }
}

// ---- services ---------------------------------------------------------------------------------

bool SimRosInterface::onPause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = true;
  res.message = std::string(paused_ ? "already paused" : "paused") + " at t=" + std::to_string(simTime()) +
                " s";
  if (!paused_) ROS_INFO("simulator: paused at t=%.3f s", simTime());
  paused_ = true;
  return true;
}

bool SimRosInterface::onUnpause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = true;
  res.message = std::string(paused_ ? "running" : "already running") + " from t=" +
                std::to_string(simTime()) + " s";
  if (paused_) ROS_INFO("simulator: running from t=%.3f s", simTime());
  paused_ = false;
  resetPacing();
  return true;
}

bool SimRosInterface::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  if (!world_) {
    res.success = false;
    res.message = "no world (a previous reset failed)";
    return true;
  }
  const double before = simTime();
  try {
    // Resolve every level first (cached), so a failure leaves the running world untouched.
    for (const sbot::RobotSpawn& s : scenario_.robots) sbot::loadLevel(s.level);
    // Tear the old world down before building the new one (one ODE world at a time).
    for (auto& iface : robots_) iface->unbind();
    if (modules_) modules_->detach();
    world_.reset();
    // The rebuilt world starts at 0; ROS time continues one step later so stamps stay increasing.
    time_offset_ = before + scenario_.world.step;
    ++total_steps_;
    world_ = buildWorld();
  } catch (const std::exception& e) {
    ROS_FATAL("simulator: /sim/reset failed to rebuild the world: %s", e.what());
    res.success = false;
    res.message = std::string("reset failed: ") + e.what();
    world_.reset();  // the old world is gone: run() exits with an error
    return true;
  }
  // The interfaces follow the rebuilt world: robots spawned since have none now, deleted ones of the
  // scenario are back (a new interface on the same names).
  std::vector<std::unique_ptr<RobotRosInterface>> interfaces;
  for (sbot::Robot* r : world_->robots()) {
    auto it = std::find_if(robots_.begin(), robots_.end(), [&](const auto& iface) { return iface && iface->name() == r->name(); });
    if (it != robots_.end()) {
      (*it)->bind(*r);
      interfaces.push_back(std::move(*it));
    } else {
      interfaces.push_back(std::make_unique<RobotRosInterface>(nh_, *r, params_.set_description_params));
    }
  }
  robots_ = std::move(interfaces);  // (SwarmRosInterface holds a reference to this vector)
  if (modules_) modules_->attach();
  ++reset_count_;
  if (markers_) markers_->clearTrails();
  if (swarm_) swarm_->republish();
  last_publish_tick_ = -1;  // publish the initial state now
  publishClock();
  publishStates();
  resetPacing();
  res.success = true;
  res.message = "world rebuilt from " + scenario_.source + " (seed " +
                std::to_string(scenario_.world.seed) + "); ROS time continues at " +
                std::to_string(simTime()) + " s";
  ROS_INFO("simulator: reset at t=%.3f s: %s", before, res.message.c_str());
  return true;
}

bool SimRosInterface::onStep(sbot_msgs::Step::Request& req, sbot_msgs::Step::Response& res) {
  if (!world_) {
    res.success = false;
    res.message = "no world (a reset failed)";
    return true;
  }
  res.time = simTime();
  if (!paused_) {
    res.success = false;
    res.message = "the simulation is running: call /sim/pause before /sim/step";
    return true;
  }
  // The node serves nothing else while it steps: 2^32 steps held it (and /sim/pause) for days.
  constexpr std::uint32_t kMaxStepsPerCall = 100000;
  if (req.steps > kMaxStepsPerCall) {
    res.success = false;
    res.message = "steps " + std::to_string(req.steps) + " exceeds " + std::to_string(kMaxStepsPerCall) +
                  " per call (nothing else is served while it steps): call /sim/step again, or /sim/unpause";
    return true;
  }
  try {
    std::uint32_t done = 0;
    for (; done < req.steps && !durationReached() && ros::ok() && !stop_requested_; ++done) stepOnce();
    res.success = true;
    if (done < req.steps)
      res.message = "stopped after " + std::to_string(done) + " of " + std::to_string(req.steps) +
                    " steps: " + (durationReached() ? "duration reached" : "shutting down");
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("step failed: ") + e.what();
  }
  res.time = simTime();
  return true;
}

bool SimRosInterface::onSetPose(sbot_msgs::SetPose::Request& req, sbot_msgs::SetPose::Response& res) {
  res.success = false;
  sbot::Robot* robot = lookupRobot(world_.get(), req.robot, res.message);
  if (!robot) return true;
  const std::pair<const char*, double> fields[] = {
      {"x", req.x}, {"y", req.y}, {"z", req.z}, {"yaw", req.yaw}};
  for (const auto& f : fields) {
    if (!std::isfinite(f.second)) {
      res.message = std::string("field ") + f.first + " is not finite (" + std::to_string(f.second) + ")";
      return true;
    }
  }
  if (const std::string problem = sbot::angleProblem(req.yaw); !problem.empty()) {
    res.message = "field yaw " + problem;
    return true;
  }
  try {
    res.message = world_->placeRobot(*robot, sbot::Pose(sbot::Vec3(req.x, req.y, req.z), sbot::quatFromRPY(0, 0, req.yaw)));
    res.success = res.message.empty();
  } catch (const std::exception& e) {
    res.message = e.what();
  }
  return true;
}

}  // namespace sbot_node
