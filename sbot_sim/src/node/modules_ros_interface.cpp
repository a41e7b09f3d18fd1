#include "modules_ros_interface.h"

#include <algorithm>
#include <cmath>

#include <sbot_msgs/SensorsAvailable.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/ros/typed_param.h"

namespace sbot_node {

namespace sn = sbot::sensors;

namespace {

/// The rate channels' names, in the publisher table's order (for messages and look-ups).
const std::vector<std::string>& channelNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const SensorPublisherType* p : sensorPublisherTable()) n.push_back(p->channel);
    return n;
  }();
  return names;
}

std::string clampNote(const char* what, long asked, long applied, long lo, long hi) {
  return std::string(what) + " " + std::to_string(asked) + " outside [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "]: clamped to " + std::to_string(applied);
}

}  // namespace

double samplingRateHz(unsigned code) {
  switch (code) {
    case 1: return 50;
    case 2: return 33;
    case 3: return 20;
    case 4: return 10;
    case 5: return 5;
    case 6: return 2;
    case 7: return 1;
    case 8: return 0.5;
    default: return 0;
  }
}

// ---- per robot ----------------------------------------------------------------------------------

RobotModulesRos::RobotModulesRos(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& name,
                                 bool per_sensor_topics)
    : name_(name), topics_(nh, pnh, name, per_sensor_topics) {
  for (const SensorPublisherType* p : sensorPublisherTable()) {
    const std::string ch = p->channel;
    double hz = p->default_hz;
    pnh.param("rates/" + ch, hz, p->default_hz);
    if (!std::isfinite(hz) || hz <= 0) {
      ROS_WARN("simulator: ~rates/%s must be > 0 Hz, got %g: using %g", ch.c_str(), hz, p->default_hz);
      hz = p->default_hz;
    }
    topics_.rates()[ch].hz = hz;
  }
  // ~per_sensor_topics: false leaves out the 23 per-sensor topics, half of a robot's publications.
  // roscpp looks a topic up linearly among all the node's publications at every publish, and a
  // recorder's subscription costs a connection each, so a large swarm runs faster without them.
  for (const SensorPublisherType* p : sensorPublisherTable()) {
    publishers_.push_back(p->make());
    publishers_.back()->advertise(topics_);
  }
  ros::NodeHandle& rnh = topics_.nh();
  available_pub_ = rnh.advertise<sbot_msgs::SensorsAvailable>("sensors_available", 1, /*latch=*/true);
  leds_sub_ = rnh.subscribe("leds", 10, &RobotModulesRos::onLeds, this, ros::TransportHints().tcpNoDelay());
  speaker_sub_ = rnh.subscribe("speaker", 10, &RobotModulesRos::onSpeaker, this, ros::TransportHints().tcpNoDelay());
  set_gripper_srv_ = rnh.advertiseService("set_gripper", &RobotModulesRos::onSetGripper, this);
  set_side_arm_srv_ = rnh.advertiseService("set_side_arm", &RobotModulesRos::onSetSideArm, this);
  set_leds_srv_ = rnh.advertiseService("set_leds", &RobotModulesRos::onSetLeds, this);
  set_rate_srv_ = rnh.advertiseService("set_sampling_rate", &RobotModulesRos::onSetSamplingRate, this);
  for (const SensorPublisherType* p : sensorPublisherTable()) {
    if (!p->noted_topic) continue;
    const std::string key = p->channel;
    publicationStamps().watchSubscribers(name_, p->noted_topic,
                                         [this, key](const std::string& node) { return topics_.roster(key).has(node); });
  }
}

RobotModulesRos::~RobotModulesRos() {
  for (const SensorPublisherType* p : sensorPublisherTable())
    if (p->noted_topic) publicationStamps().forgetSubscribers(name_, p->noted_topic);
  unbind();
}

void RobotModulesRos::bind(sbot::World& world, sn::Environment& env, sbot::Robot& robot) {
  unbind();
  suite_ = std::make_unique<sn::SensorSuite>(world, robot, env);
  gripper_ = std::make_unique<sbot::actuators::FrontGripper>(world, robot);
  side_arm_ = std::make_unique<sbot::actuators::SideArm>(world, robot);
  static_cast<RobotModules&>(topics_) = {&world, &env, &robot, suite_.get(), gripper_.get(), side_arm_.get()};
  for (auto& p : publishers_) p->bind(topics_);
  const double t = world.time();
  for (auto& [ch, r] : topics_.rates()) r.next = t;
  next_any_ = t;
  publishAvailable();
}

void RobotModulesRos::unbind() {
  for (auto it = publishers_.rbegin(); it != publishers_.rend(); ++it) (*it)->unbind();
  side_arm_.reset();
  gripper_.reset();
  suite_.reset();
  static_cast<RobotModules&>(topics_) = RobotModules{};
}

void RobotModulesRos::publishAvailable() {
  sbot_msgs::SensorsAvailable m;
  m.robot = name_;
  m.level = topics_.robot->level();
  for (sn::SensorChannel c : suite_->availableChannels()) {
    std::string n = sn::channelName(c);
    if (n == "fake_camera") n = "camera/blobs";
    m.channels.push_back(n);
  }
  m.channels.push_back("imu");
  m.channels.push_back("gripper/state");
  if (side_arm_->available()) m.channels.push_back("side_arm/state");
  m.channels.push_back("leds/state");
  m.ir_model = suite_->proximityModel();
  m.gripper = gripper_->typeName();
  m.side_arm = side_arm_->available();
  available_pub_.publish(m);
}

void RobotModulesRos::update(double dt, double sim_time) {
  if (!topics_.robot) return;
  suite_->update(dt);
  gripper_->update(dt);
  side_arm_->update(dt);
  if (sim_time + 1e-9 < next_any_) return;  // no topic due this step (the common case)
  struct NextAny {  // recompute the earliest due time on the way out
    RobotModulesRos* self;
    ~NextAny() {
      self->next_any_ = 1e300;
      for (const auto& [ch, r] : self->topics_.rates()) self->next_any_ = std::min(self->next_any_, r.next);
    }
  } next_any_guard{this};
  const ros::Time stamp(sim_time);
  for (auto& p : publishers_) p->publish(topics_, sim_time, stamp);
}

void RobotModulesRos::onLeds(const sbot_msgs::LedState::ConstPtr& msg) {
  if (!topics_.robot) return;
  std::array<unsigned, sn::kLedGroups> r{}, g{}, b{}, blink{};
  bool clamped = false;  // the light ring clamps colours to 0..15; the blink code is capped here
  for (int k = 0; k < sn::kLedGroups; ++k) {
    r[k] = msg->r[k];
    g[k] = msg->g[k];
    b[k] = msg->b[k];
    blink[k] = std::min<unsigned>(msg->blink[k], 10);
    clamped |= std::max({r[k], g[k], b[k]}) > sn::kLedMaxUnits || msg->blink[k] > 10;
  }
  if (clamped)  // as cmd_speed warns, and set_leds answers `clamped`
    ROS_WARN_THROTTLE(1.0, "%s/leds: colour above 15 or blink code above 10 clamped (sbot.h ranges: 0..15, 0..10)",
                      name_.c_str());
  suite_->setAllLightColor(r, g, b, blink);
}

void RobotModulesRos::onSpeaker(const std_msgs::Float64::ConstPtr& msg) {
  if (!topics_.robot) return;
  if (!std::isfinite(msg->data) || msg->data < 0) {
    ROS_WARN_THROTTLE(1.0, "%s/speaker rejected: %f is not a frequency (Hz >= 0; 0 turns it off; the speaker keeps its state)",
                      name_.c_str(), msg->data);
    return;
  }
  if (msg->data == 0) {
    suite_->stopSpeaker();
  } else {
    suite_->setSpeaker(msg->data, 1.0);
  }
}

bool RobotModulesRos::onSetGripper(sbot_msgs::SetGripper::Request& req, sbot_msgs::SetGripper::Response& res) {
  if (!topics_.robot) {
    res.success = false;
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  using G = sbot::actuators::FrontGripper;
  const bool ce = gripper_->setElevation(req.elevation);
  const bool ca = gripper_->setAperture(req.aperture);
  res.applied_elevation = static_cast<int16_t>(gripper_->commandedElevation());
  res.applied_aperture = static_cast<int16_t>(gripper_->commandedAperture());
  res.clamped = ce || ca;
  res.success = true;
  std::string msg;
  if (ce) msg = clampNote("elevation", req.elevation, res.applied_elevation, G::kElevationMin, G::kElevationMax);
  if (ca) msg += (msg.empty() ? "" : "; ") + clampNote("aperture", req.aperture, res.applied_aperture, G::kApertureMin, G::kApertureMax);
  if (!gripper_->physical())
    msg += std::string(msg.empty() ? "" : "; ") + "level '" + topics_.robot->level() +
           "' has no gripper model: command accepted, nothing moves (seed 2.2.3)";
  res.message = msg;
  return true;
}

bool RobotModulesRos::onSetSideArm(sbot_msgs::SetSideArm::Request& req, sbot_msgs::SetSideArm::Response& res) {
  res.success = false;
  res.clamped = false;
  if (!topics_.robot) {
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  if (!side_arm_->available()) {
    res.message = name_ + " (level '" + topics_.robot->level() + "') has no side arm (Detailed only)";
    return true;
  }
  if (req.jaws > sbot_msgs::SetSideArm::Request::JAWS_CLOSE) {
    res.message = "jaws must be 0 (keep), 1 (open) or 2 (close), got " + std::to_string(req.jaws);
    return true;
  }
  res.clamped = side_arm_->setPos(req.elevation, req.rotation, req.depth);
  if (req.jaws == sbot_msgs::SetSideArm::Request::JAWS_OPEN) side_arm_->setOpened();
  if (req.jaws == sbot_msgs::SetSideArm::Request::JAWS_CLOSE) side_arm_->setClosed();
  res.success = true;
  if (res.clamped)
    res.message = "clamped to elevation [-" + std::to_string(side_arm_->elevationLimit()) + ", " +
                  std::to_string(side_arm_->elevationLimit()) + "], rotation [-" +
                  std::to_string(side_arm_->rotationLimit()) + ", " + std::to_string(side_arm_->rotationLimit()) +
                  "] (units of 0.458 deg), depth [" + std::to_string(side_arm_->depthMin()) + ", " +
                  std::to_string(side_arm_->depthMax()) + "] mm";
  return true;
}

bool RobotModulesRos::onSetLeds(sbot_msgs::SetLeds::Request& req, sbot_msgs::SetLeds::Response& res) {
  res.success = false;
  res.clamped = false;
  if (!topics_.robot) {
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  const std::size_t n = req.group.size();
  if (req.r.size() != n || req.g.size() != n || req.b.size() != n || req.blink.size() != n) {
    res.message = "group, r, g, b and blink must have the same length";
    return true;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (req.group[i] >= sn::kLedGroups) {
      res.message = "group " + std::to_string(req.group[i]) + " outside [0, 7]";
      return true;
    }
  }
  std::string notes;
  for (std::size_t i = 0; i < n; ++i) {
    unsigned r = req.r[i], g = req.g[i], b = req.b[i], blink = req.blink[i];
    if (r > 15 || g > 15 || b > 15) {
      res.clamped = true;
      notes = "colours clamped to [0, 15]";
    }
    if (blink > 10) {
      res.clamped = true;
      blink = 10;
      notes += std::string(notes.empty() ? "" : "; ") + "blink code clamped to [0, 10]";
    }
    suite_->setLightColor(req.group[i], std::min(r, 15u), std::min(g, 15u), std::min(b, 15u), blink);
  }
  res.success = true;
  res.message = notes;
  return true;
}

bool RobotModulesRos::onSetSamplingRate(sbot_msgs::SetSamplingRate::Request& req,
                                        sbot_msgs::SetSamplingRate::Response& res) {
  res.success = false;
  if (!topics_.robot) {  // deleted: answered as the other per-robot services are (it said success)
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  auto it = topics_.rates().find(req.channel);
  if (it == topics_.rates().end()) {
    res.message = "unknown channel '" + req.channel + "' (channels: " + sbot::nameList(channelNames()) + ")";
    return true;
  }
  double hz = 0;
  if (req.rate != 0) {
    hz = samplingRateHz(req.rate);
    if (hz <= 0) {
      res.message = "unknown SAMPLING_RATE code " + std::to_string(req.rate) + " (1..8)";
      res.applied_hz = it->second.hz;
      return true;
    }
  } else {
    if (const std::string problem = sbot::samplingRateProblem(req.hz); !problem.empty()) {
      res.message = "hz " + problem;
      res.applied_hz = it->second.hz;
      return true;
    }
    hz = req.hz;
  }
  // A channel is published at most once a step: the reply says the rate it gets (it said 1e300).
  const double step_hz = 1.0 / topics_.world->config().step;
  if (hz > step_hz) {
    res.message = "capped at the step rate " + std::to_string(step_hz) + " Hz (asked " + std::to_string(hz) + ")";
    hz = step_hz;
  }
  it->second.hz = hz;
  it->second.next = 0;  // publish at the next step, then every 1/hz
  next_any_ = 0;
  res.applied_hz = hz;
  res.success = true;
  return true;
}

// ---- world ----------------------------------------------------------------------------------------

ModulesRosInterface::ModulesRosInterface(ros::NodeHandle nh, ros::NodeHandle pnh,
                                         std::unique_ptr<sbot::World>& world, const sbot::Scenario& scenario)
    : nh_(nh), pnh_(pnh), world_(world), lamps_(scenario.lamps), ambient_(scenario.ambient_light) {
  pnh_.param("per_sensor_topics", per_sensor_topics_, true);  // its type is checked by SimRosInterface
  ROS_INFO("simulator: ~per_sensor_topics=%s", per_sensor_topics_ ? "true" : "false");
  ros::NodeHandle sim(nh_, "sim");
  set_lamp_srv_ = sim.advertiseService("set_lamp", &ModulesRosInterface::onSetLamp, this);
  set_ambient_srv_ = sim.advertiseService("set_ambient_light", &ModulesRosInterface::onSetAmbient, this);
}

ModulesRosInterface::~ModulesRosInterface() { detach(); }

bool ModulesRosInterface::checkRateParams(const ros::NodeHandle& pnh) {
  if (!pnh.hasParam("rates")) return true;
  XmlRpc::XmlRpcValue rates;
  pnh.getParam("rates", rates);
  const std::vector<std::string>& channels = channelNames();
  const std::string known = sbot::nameList(channels);
  if (rates.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    ROS_FATAL("simulator: ~rates must be a map of channel: Hz (channels: %s)", known.c_str());
    return false;
  }
  bool ok = true;
  for (auto it = rates.begin(); it != rates.end(); ++it) {
    if (std::find(channels.begin(), channels.end(), it->first) == channels.end()) {
      ROS_FATAL("simulator: ~rates/%s: unknown channel (channels: %s)", it->first.c_str(), known.c_str());
      ok = false;
      continue;
    }
    double hz = 0;
    ok &= sbot_ros_params::readTypedParam(pnh, "rates/" + it->first, hz);
  }
  return ok;
}

RobotModulesRos& ModulesRosInterface::modulesFor(const std::string& name) {
  auto& m = robots_[name];
  if (!m) m = std::make_unique<RobotModulesRos>(nh_, pnh_, name, per_sensor_topics_);
  return *m;
}

void ModulesRosInterface::attach() {
  detach();
  if (!world_) return;
  env_ = std::make_unique<sn::Environment>(*world_);
  for (const sbot::LampSpawn& l : lamps_) env_->addLamp(l.position, l.intensity, l.colour);
  env_->setAmbientLight(ambient_);
  bound_world_ = world_.get();
  for (auto it = robots_.begin(); it != robots_.end();)  // robots spawned since the world was built
    it = world_->findRobot(it->first) ? std::next(it) : robots_.erase(it);
  for (sbot::Robot* r : world_->robots()) modulesFor(r->name()).bind(*world_, *env_, *r);
}

void ModulesRosInterface::detach() {
  for (auto& [n, m] : robots_) m->unbind();
  env_.reset();
  bound_world_ = nullptr;
}

void ModulesRosInterface::afterStep(double sim_time) {
  if (!world_) return;
  if (world_.get() != bound_world_) attach();
  const double dt = world_->config().step;
  for (auto& [n, m] : robots_) m->update(dt, sim_time);
}

void ModulesRosInterface::robotAdded(sbot::Robot& robot) {
  if (env_ && world_) modulesFor(robot.name()).bind(*world_, *env_, robot);
}

void ModulesRosInterface::robotRemoving(sbot::Robot& robot) {
  auto it = robots_.find(robot.name());
  if (it != robots_.end()) {  // its topics and services go with it (SwarmRosInterface::onDelete)
    it->second->unbind();
    robots_.erase(it);
  }
  if (env_) env_->forgetRobot(robot.name());
}

void ModulesRosInterface::robotRebuilt(sbot::Robot& robot) {
  if (env_ && world_) modulesFor(robot.name()).bind(*world_, *env_, robot);
}

bool ModulesRosInterface::onSetLamp(sbot_msgs::SetLamp::Request& req, sbot_msgs::SetLamp::Response& res) {
  res.success = false;
  if (!env_) {
    res.message = "no world";
    return true;
  }
  if (const std::string problem = sbot::lightIntensityProblem(req.intensity, "mcd"); !problem.empty()) {
    res.message = "intensity " + problem;
    return true;
  }
  if (req.lamp >= env_->lamps().size()) {
    res.message = "unknown lamp " + std::to_string(req.lamp) + " (the scenario has " +
                  std::to_string(env_->lamps().size()) + " lamps in world.lamps)";
    return true;
  }
  env_->setLampIntensity(static_cast<int>(req.lamp), req.intensity);
  lamps_[req.lamp].intensity = req.intensity;  // kept over /sim/reset
  res.success = true;
  return true;
}

bool ModulesRosInterface::onSetAmbient(sbot_msgs::SetAmbientLight::Request& req,
                                       sbot_msgs::SetAmbientLight::Response& res) {
  res.success = false;
  if (const std::string problem = sbot::lightIntensityProblem(req.intensity, "mcd/cm^2"); !problem.empty()) {
    res.message = "intensity " + problem;
    return true;
  }
  ambient_ = req.intensity;
  if (env_) env_->setAmbientLight(req.intensity);
  res.success = true;
  return true;
}

}  // namespace sbot_node
