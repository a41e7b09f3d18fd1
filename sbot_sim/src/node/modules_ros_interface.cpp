#include "modules_ros_interface.h"

#include <algorithm>
#include <cmath>

#include <sbot_msgs/Battery.h>
#include <sbot_msgs/BlobArray.h>
#include <sbot_msgs/Climate.h>
#include <sbot_msgs/GripperState.h>
#include <sbot_msgs/GroundArray.h>
#include <sbot_msgs/LightArray.h>
#include <sbot_msgs/ProximityArray.h>
#include <sbot_msgs/SensorsAvailable.h>
#include <sbot_msgs/SideArmState.h>
#include <sbot_msgs/Slope.h>
#include <sbot_msgs/SoundState.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/Illuminance.h>
#include <sensor_msgs/Range.h>
#include <visualization_msgs/MarkerArray.h>

#include "ros_conversions.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/ros/typed_param.h"

namespace sbot_node {

namespace sn = sbot::sensors;

namespace {

template <class T>
struct Tag {
  using type = T;
};

/// The rate channels whose publications are noted for the lock-step gate (publishNoted), as
/// {subscriber-roster key, topic}: the topics sbot.h getters read.
const std::vector<std::pair<std::string, std::string>>& notedTopics() {
  static const std::vector<std::pair<std::string, std::string>> t = {
      {"proximity", "proximity"}, {"ground", "ground"},           {"light", "light"},        {"slope", "slope"},
      {"gripper", "gripper/state"}, {"side_arm", "side_arm/state"}, {"battery", "battery"}, {"climate", "climate"}};
  return t;
}

/// Every rate channel with its default [Hz] (sbot.h has no documented default; 10 Hz = SAMPLING_RATE_10).
const std::vector<std::pair<std::string, double>>& channelDefaults() {
  static const std::vector<std::pair<std::string, double>> d = {
      {"proximity", 10}, {"ground", 10}, {"light", 10}, {"slope", 10}, {"imu", 10},    {"sound", 10},
      {"camera", 10},    {"gripper", 10}, {"side_arm", 10}, {"battery", 1}, {"climate", 1}, {"leds", 10},
      {"markers", 10}, {"raw_camera", 5}};
  return d;
}

/// The rate channels' names, in channelDefaults' order (for messages and look-ups).
const std::vector<std::string>& channelNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [ch, def] : channelDefaults()) n.push_back(ch);
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
    : nh_(nh, name), pnh_(pnh), name_(name) {
  for (const auto& [ch, def] : channelDefaults()) {
    double hz = def;
    pnh_.param("rates/" + ch, hz, def);
    if (!std::isfinite(hz) || hz <= 0) {
      ROS_WARN("simulator: ~rates/%s must be > 0 Hz, got %g: using %g", ch.c_str(), hz, def);
      hz = def;
    }
    rates_[ch].hz = hz;
  }
  constexpr uint32_t q = 10;
  // Subscribers are kept by connect/disconnect callbacks (SubscriberRoster): Publisher::getNumSubscribers()
  // looks the topic up among all the node's publications (linear in their number: ~20 per robot),
  // far too slow to ask every step for 100 robots.
  auto adv = [&](auto type_tag, const std::string& topic, const std::string& key, uint32_t queue, bool latch) {
    using M = typename decltype(type_tag)::type;
    SubscriberRoster& roster = subs_[key];
    return nh_.advertise<M>(topic, queue, roster.connected(), roster.disconnected(), ros::VoidConstPtr(), latch);
  };
  // ~per_sensor_topics: false leaves out the 23 per-sensor topics, half of a robot's publications.
  // roscpp looks a topic up linearly among all the node's publications at every publish, and a
  // recorder's subscription costs a connection each, so a large swarm runs faster without them.
  // Their rosters then never fill, so the per-sensor messages below are never built.
  pubs_["proximity"] = adv(Tag<sbot_msgs::ProximityArray>(), "proximity", "proximity", q, false);
  for (int k = 0; per_sensor_topics && k < sn::kProximitySensors; ++k)
    ir_pubs_.push_back(adv(Tag<sensor_msgs::Range>(), "proximity/ir_" + std::to_string(k), "ir_" + std::to_string(k), q, false));
  pubs_["ground"] = adv(Tag<sbot_msgs::GroundArray>(), "ground", "ground", q, false);
  pubs_["light"] = adv(Tag<sbot_msgs::LightArray>(), "light", "light", q, false);
  for (int k = 0; per_sensor_topics && k < sn::kLightSensors; ++k)
    light_pubs_.push_back(adv(Tag<sensor_msgs::Illuminance>(), "light/sensor_" + std::to_string(k),
                              "light_" + std::to_string(k), q, false));
  pubs_["slope"] = adv(Tag<sbot_msgs::Slope>(), "slope", "slope", q, false);
  pubs_["imu"] = adv(Tag<sensor_msgs::Imu>(), "imu", "imu", q, false);
  pubs_["sound"] = adv(Tag<sbot_msgs::SoundState>(), "sound", "sound", q, false);
  pubs_["camera"] = adv(Tag<sbot_msgs::BlobArray>(), "camera/blobs", "camera", q, false);
  pubs_["gripper"] = adv(Tag<sbot_msgs::GripperState>(), "gripper/state", "gripper", q, false);
  pubs_["side_arm"] = adv(Tag<sbot_msgs::SideArmState>(), "side_arm/state", "side_arm", q, false);
  pubs_["battery"] = adv(Tag<sbot_msgs::Battery>(), "battery", "battery", q, false);
  pubs_["climate"] = adv(Tag<sbot_msgs::Climate>(), "climate", "climate", q, false);
  pubs_["leds"] = adv(Tag<sbot_msgs::LedState>(), "leds/state", "leds", q, false);
  int width = 640, height = 448, scale = 4;
  pnh_.param("camera/width", width, 640);
  pnh_.param("camera/height", height, 448);
  pnh_.param("camera/internal_scale", scale, 4);
  if (width < 16 || height < 16 || scale < 1)
    ROS_WARN_ONCE("simulator: ~camera/width and ~camera/height must be >= 16 px and ~camera/internal_scale >= 1, got "
                  "%d, %d, %d: using %d, %d, %d", width, height, scale, std::max(16, width), std::max(16, height),
                  std::max(1, scale));
  camera_params_.width = std::max(16, width);
  camera_params_.height = std::max(16, height);
  camera_params_.internal_width = std::max(8, camera_params_.width / std::max(1, scale));
  camera_params_.internal_height = std::max(8, camera_params_.height / std::max(1, scale));
  image_transport::ImageTransport it(nh_);
  camera_pub_ = it.advertise("camera/image_raw", 1);
  camera_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("camera/camera_info", 1);
  pubs_["markers"] = adv(Tag<visualization_msgs::MarkerArray>(), "sensor_markers", "markers", 2, false);
  pubs_["available"] = nh_.advertise<sbot_msgs::SensorsAvailable>("sensors_available", 1, /*latch=*/true);
  leds_sub_ = nh_.subscribe("leds", 10, &RobotModulesRos::onLeds, this, ros::TransportHints().tcpNoDelay());
  speaker_sub_ = nh_.subscribe("speaker", 10, &RobotModulesRos::onSpeaker, this, ros::TransportHints().tcpNoDelay());
  set_gripper_srv_ = nh_.advertiseService("set_gripper", &RobotModulesRos::onSetGripper, this);
  set_side_arm_srv_ = nh_.advertiseService("set_side_arm", &RobotModulesRos::onSetSideArm, this);
  set_leds_srv_ = nh_.advertiseService("set_leds", &RobotModulesRos::onSetLeds, this);
  set_rate_srv_ = nh_.advertiseService("set_sampling_rate", &RobotModulesRos::onSetSamplingRate, this);
  for (const auto& [key, topic] : notedTopics())
    publicationStamps().watchSubscribers(name_, topic, [this, key = key](const std::string& node) { return subs_[key].has(node); });
}

RobotModulesRos::~RobotModulesRos() {
  for (const auto& [key, topic] : notedTopics()) publicationStamps().forgetSubscribers(name_, topic);
  unbind();
}

void RobotModulesRos::bind(sbot::World& world, sn::Environment& env, sbot::Robot& robot) {
  unbind();
  world_ = &world;
  env_ = &env;
  robot_ = &robot;
  suite_ = std::make_unique<sn::SensorSuite>(world, robot, env);
  gripper_ = std::make_unique<sbot::actuators::FrontGripper>(world, robot);
  side_arm_ = std::make_unique<sbot::actuators::SideArm>(world, robot);
  raw_camera_ = std::make_unique<sn::RawCamera>(world, robot, env, camera_params_);
  const double t = world.time();
  for (auto& [ch, r] : rates_) r.next = t;
  next_any_ = t;
  publishAvailable();
}

void RobotModulesRos::unbind() {
  raw_camera_.reset();
  side_arm_.reset();
  gripper_.reset();
  suite_.reset();
  robot_ = nullptr;
  world_ = nullptr;
  env_ = nullptr;
}

void RobotModulesRos::publishAvailable() {
  sbot_msgs::SensorsAvailable m;
  m.robot = name_;
  m.level = robot_->level();
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
  pubs_["available"].publish(m);
}

bool RobotModulesRos::due(const std::string& channel, double t) {
  Rate& r = rates_[channel];
  if (t + 1e-9 < r.next) return false;
  const double period = 1.0 / r.hz;
  r.next += period;
  if (r.next <= t) r.next = t + period;  // fell behind (rate raised, reset): restart the phase
  return subs_[channel].any();
}

bool RobotModulesRos::dueWithSingles(const std::string& channel, const std::string& single_prefix, int count,
                                     double t, bool& any_single) {
  const bool was_due = t + 1e-9 >= rates_[channel].next;
  any_single = false;
  if (was_due)
    for (int k = 0; k < count; ++k) any_single = any_single || subs_[single_prefix + std::to_string(k)].any();
  return due(channel, t) || (was_due && any_single);
}

void RobotModulesRos::update(double dt, double sim_time) {
  if (!robot_) return;
  suite_->update(dt);
  gripper_->update(dt);
  side_arm_->update(dt);
  if (sim_time + 1e-9 < next_any_) return;  // no topic due this step (the common case)
  struct NextAny {  // recompute the earliest due time on the way out
    RobotModulesRos* self;
    ~NextAny() {
      self->next_any_ = 1e300;
      for (const auto& [ch, r] : self->rates_) self->next_any_ = std::min(self->next_any_, r.next);
    }
  } next_any_guard{this};

  const ros::Time stamp(sim_time);
  const std::string turret = name_ + "/turret", base = name_ + "/base_link";
  auto header = [&](const std::string& frame) {
    std_msgs::Header h;
    h.stamp = stamp;
    h.frame_id = frame;
    return h;
  };

  {
    bool any_ir = false;
    const bool want = dueWithSingles("proximity", "ir_", sn::kProximitySensors, sim_time, any_ir);
    if (want && suite_->available(sn::SensorChannel::Proximity)) {
      const auto all = suite_->getAllProximitySensors();
      sbot_msgs::ProximityArray m;
      m.header = header(turret);
      for (int k = 0; k < sn::kProximitySensors; ++k) m.readings[k] = static_cast<uint16_t>(all[k]);
      publishNoted(pubs_["proximity"], name_, "proximity", m);
      if (any_ir && suite_->proximity()) {
        const auto& resp = suite_->proximity()->response();
        for (int k = 0; k < sn::kProximitySensors; ++k) {
          if (!subs_["ir_" + std::to_string(k)].any()) continue;
          sensor_msgs::Range rg;
          rg.header = header(name_ + "/ir_" + std::to_string(k));
          rg.radiation_type = sensor_msgs::Range::INFRARED;
          rg.field_of_view = 0.5;
          rg.min_range = static_cast<float>(suite_->proximity()->rayModel().range_min);
          rg.max_range = static_cast<float>(suite_->proximity()->rayModel().range_max);
          // Distance equivalent of the (noisy) reading; +inf when nothing is detected (REP 117).
          rg.range = all[k] == 0 ? INFINITY : static_cast<float>(std::min(resp.distance(all[k]), 1e3));
          ir_pubs_[k].publish(rg);
        }
      }
    }
  }
  if (due("ground", sim_time) && suite_->available(sn::SensorChannel::Ground)) {
    sbot_msgs::GroundArray m;
    m.header = header(base);
    const auto all = suite_->getAllGroundSensors();
    for (int k = 0; k < sn::kGroundSensors; ++k) m.readings[k] = static_cast<uint16_t>(all[k]);
    publishNoted(pubs_["ground"], name_, "ground", m);
  }
  {
    // The compact array and, for whoever subscribes, one sensor_msgs/Illuminance per sensor (the
    // same noisy, saturating reading converted to lux: 1 mcd/cm^2 = 10 lx).
    bool any_single = false;
    const bool want = dueWithSingles("light", "light_", sn::kLightSensors, sim_time, any_single);
    if (want && suite_->available(sn::SensorChannel::Light)) {
      sbot_msgs::LightArray m;
      m.header = header(turret);
      const auto all = suite_->getAllLightSensors();
      for (int k = 0; k < sn::kLightSensors; ++k) m.readings[k] = static_cast<uint16_t>(all[k]);
      publishNoted(pubs_["light"], name_, "light", m);
      if (any_single && suite_->light()) {
        const sn::LightSensorParams& lp = suite_->light()->params();
        constexpr double kLuxPerMcdPerCm2 = 10.0;  // 1e-3 cd / 1e-4 m^2
        for (int k = 0; k < sn::kLightSensors; ++k) {
          if (!subs_["light_" + std::to_string(k)].any()) continue;
          sensor_msgs::Illuminance il;
          il.header = header(name_ + "/light_" + std::to_string(k));
          il.illuminance = all[k] * lp.unit * kLuxPerMcdPerCm2;
          // Uniform relative noise +-noise has variance (noise * value)^2 / 3; 0 = unknown (REP).
          const double sd = lp.noise * il.illuminance;
          il.variance = sd * sd / 3.0;
          light_pubs_[k].publish(il);
        }
      }
    }
  }
  if (due("slope", sim_time)) {
    sbot_msgs::Slope m;
    m.header = header(base);
    int pitch = 0, roll = 0;
    suite_->getSlope(&pitch, &roll);
    m.pitch = static_cast<int16_t>(pitch);
    m.roll = static_cast<int16_t>(roll);
    publishNoted(pubs_["slope"], name_, "slope", m);
  }
  if (due("imu", sim_time)) {
    sensor_msgs::Imu m;
    m.header = header(base);
    const sbot::Quat q = suite_->imuOrientation();
    m.orientation.x = q.x();
    m.orientation.y = q.y();
    m.orientation.z = q.z();
    m.orientation.w = q.w();
    const sbot::Vec3 w = suite_->imuAngularVelocity();
    m.angular_velocity.x = w.x();
    m.angular_velocity.y = w.y();
    m.angular_velocity.z = w.z();
    m.linear_acceleration_covariance[0] = -1;  // not provided
    pubs_["imu"].publish(m);
  }
  if (due("sound", sim_time) && suite_->available(sn::SensorChannel::Sound)) {
    sbot_msgs::SoundState m;
    m.header = header(turret);
    const auto all = suite_->getAllSoundIntensities();
    m.total = 0;
    for (int k = 0; k < sn::kMicrophones && k < 3; ++k) {
      m.amplitude[k] = all[k];
      m.total += all[k];
    }
    pubs_["sound"].publish(m);
  }
  if (due("camera", sim_time) && suite_->available(sn::SensorChannel::FakeCamera)) {
    sbot_msgs::BlobArray m;
    m.header = header(name_ + "/fake_camera");
    for (const sn::Blob& b : suite_->getFakeCameraBlobs()) {
      sbot_msgs::Blob o;
      o.bearing = b.bearing_camera;
      o.distance = b.distance;
      o.elevation = b.elevation;
      o.r = static_cast<uint8_t>(std::lround(std::clamp(b.colour.x(), 0.0, 1.0) * 15));
      o.g = static_cast<uint8_t>(std::lround(std::clamp(b.colour.y(), 0.0, 1.0) * 15));
      o.b = static_cast<uint8_t>(std::lround(std::clamp(b.colour.z(), 0.0, 1.0) * 15));
      m.blobs.push_back(o);
    }
    pubs_["camera"].publish(m);
  }
  if (due("gripper", sim_time)) {
    sbot_msgs::GripperState m;
    m.header = header(name_ + "/gripper");
    m.elevation = static_cast<int16_t>(gripper_->getElevation());
    m.aperture = static_cast<int16_t>(gripper_->getAperture());
    m.elevation_torque = static_cast<int16_t>(gripper_->getElevationTorque());
    const auto b = gripper_->getOpticalBarrier();
    m.barrier_internal = static_cast<uint16_t>(b.internal);
    m.barrier_external = static_cast<uint16_t>(b.external);
    m.barrier_combined = static_cast<uint16_t>(b.combined);
    m.gripping = gripper_->gripping();
    m.gripped = gripper_->gripped();
    publishNoted(pubs_["gripper"], name_, "gripper/state", m);
  }
  if (due("side_arm", sim_time) && side_arm_->available()) {
    sbot_msgs::SideArmState m;
    m.header = header(turret);
    int e = 0, r = 0, d = 0;
    side_arm_->getPos(&e, &r, &d);
    m.elevation = static_cast<int16_t>(e);
    m.rotation = static_cast<int16_t>(r);
    m.depth = static_cast<int16_t>(d);
    side_arm_->getTorque(&e, &r, &d);
    m.torque_elevation = static_cast<int16_t>(e);
    m.torque_rotation = static_cast<int16_t>(r);
    m.torque_depth = static_cast<int16_t>(d);
    m.jaws = side_arm_->jawsClosedCommanded() ? sbot_msgs::SideArmState::JAWS_CLOSED : sbot_msgs::SideArmState::JAWS_OPEN;
    const auto b = side_arm_->getOpticalBarrier();
    m.barrier_internal = static_cast<uint16_t>(b.internal);
    m.barrier_external = static_cast<uint16_t>(b.external);
    m.barrier_combined = static_cast<uint16_t>(b.combined);
    m.gripping = side_arm_->gripping();
    m.gripped = side_arm_->gripped();
    publishNoted(pubs_["side_arm"], name_, "side_arm/state", m);
  }
  if (due("battery", sim_time)) {
    sbot_msgs::Battery m;
    m.header = header(base);
    m.voltage_units = static_cast<uint8_t>(suite_->getBatteryVoltage());
    m.voltage = suite_->battery().voltage();
    m.charge_mAh = suite_->battery().stateOfCharge() * 1400.0;
    publishNoted(pubs_["battery"], name_, "battery", m);
  }
  if (due("climate", sim_time)) {
    sbot_msgs::Climate m;
    m.header = header(turret);
    suite_->getTemperatureAndHumidityLeft(&m.temperature_left, &m.humidity_left);
    suite_->getTemperatureAndHumidityRight(&m.temperature_right, &m.humidity_right);
    publishNoted(pubs_["climate"], name_, "climate", m);
  }
  if (due("leds", sim_time)) {
    sbot_msgs::LedState m;
    m.header = header(turret);
    const sn::LedRing& ring = env_->ledRing(name_);
    for (int k = 0; k < sn::kLedGroups; ++k) {
      m.r[k] = static_cast<uint8_t>(ring.groups[k].r);
      m.g[k] = static_cast<uint8_t>(ring.groups[k].g);
      m.b[k] = static_cast<uint8_t>(ring.groups[k].b);
      m.blink[k] = static_cast<uint8_t>(ring.groups[k].blink);
      m.lit[k] = ring.isLit(k, env_->time());
    }
    pubs_["leds"].publish(m);
  }
  if (due("markers", sim_time)) publishMarkers(stamp);
  {
    Rate& r = rates_["raw_camera"];
    if (sim_time + 1e-9 >= r.next) {
      r.next += 1.0 / r.hz;
      if (r.next <= sim_time) r.next = sim_time + 1.0 / r.hz;
      const bool image = camera_pub_.getNumSubscribers() > 0;
      if (image || camera_info_pub_.getNumSubscribers() > 0) publishRawCamera(stamp, image);
    }
  }
}

void RobotModulesRos::publishRawCamera(const ros::Time& stamp, bool with_image) {
  sensor_msgs::ImagePtr img = boost::make_shared<sensor_msgs::Image>();
  img->header.stamp = stamp;
  img->header.frame_id = name_ + "/camera";
  img->width = static_cast<uint32_t>(camera_params_.width);
  img->height = static_cast<uint32_t>(camera_params_.height);
  img->encoding = "rgb8";
  img->step = img->width * 3;
  // Rendered only for an image subscriber; camera_info alone is cheap.
  if (with_image) raw_camera_->render(img->data);
  sensor_msgs::CameraInfoPtr info = boost::make_shared<sensor_msgs::CameraInfo>();
  info->header = img->header;
  info->width = img->width;
  info->height = img->height;
  // Not a pinhole camera: the polar mapping is documented in sensors/raw_camera.h; K holds the
  // image circle (centre cx, cy and radius as fx = fy) for consumers that want it.
  info->distortion_model = "plumb_bob";
  info->D.assign(5, 0.0);
  const double radius = 0.5 * std::min(camera_params_.width, camera_params_.height);
  info->K = {radius, 0, 0.5 * camera_params_.width, 0, radius, 0.5 * camera_params_.height, 0, 0, 1};
  info->R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info->P = {radius, 0, 0.5 * camera_params_.width, 0, 0, radius, 0.5 * camera_params_.height, 0, 0, 0, 1, 0};
  if (with_image) camera_pub_.publish(img);
  camera_info_pub_.publish(info);
}

void RobotModulesRos::publishMarkers(const ros::Time& stamp) {
  // rviz: IR rays coloured by reading (green = nothing, red = 8191), LED groups in their colours
  // (dim when off / in the dark half of a blink), the world's lamps. Frame `world`.
  visualization_msgs::MarkerArray arr;
  auto base = [&](const char* ns, int id, int type) {
    visualization_msgs::Marker m;
    m.header.stamp = stamp;
    m.header.frame_id = "world";
    m.ns = name_ + "/" + ns;
    m.id = id;
    m.type = type;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1;
    m.lifetime = ros::Duration(1.0);
    return m;
  };
  if (suite_->available(sn::SensorChannel::Proximity) && suite_->proximity()) {
    const auto all = suite_->getAllProximitySensors();
    const auto& resp = suite_->proximity()->response();
    const double range_max = suite_->proximity()->rayModel().range_max;
    visualization_msgs::Marker rays = base("ir", 0, visualization_msgs::Marker::LINE_LIST);
    rays.scale.x = 0.002;
    for (int k = 0; k < sn::kProximitySensors; ++k) {
      const std::string link = "ir_" + std::to_string(k);
      if (!robot_->hasLink(link)) continue;
      const sbot::Pose p = robot_->linkPose(link);
      const double d = all[k] == 0 ? range_max : std::min(range_max, resp.distance(all[k]));
      rays.points.push_back(toPoint(p.position));
      rays.points.push_back(toPoint(p.position + p.orientation * sbot::Vec3(d, 0, 0)));
      std_msgs::ColorRGBA c;
      const double level = std::min(1.0, std::log1p(static_cast<double>(all[k])) / std::log1p(8191.0));
      c.r = static_cast<float>(level);
      c.g = static_cast<float>(1.0 - level);
      c.b = 0;
      c.a = 0.9f;
      rays.colors.push_back(c);
      rays.colors.push_back(c);
    }
    arr.markers.push_back(rays);
  }
  const sn::LedRing& ring = env_->ledRing(name_);
  for (int k = 0; k < sn::kLedGroups; ++k) {
    const std::string link = "light_" + std::to_string(k);
    if (!robot_->hasLink(link)) continue;
    visualization_msgs::Marker led = base("leds", k, visualization_msgs::Marker::SPHERE);
    led.pose.position = toPoint(robot_->linkPose(link).position);
    led.scale.x = led.scale.y = led.scale.z = 0.012;
    const auto& gp = ring.groups[k];
    const bool lit = ring.isLit(k, env_->time());
    led.color.r = gp.r / 15.0f;
    led.color.g = gp.g / 15.0f;
    led.color.b = gp.b / 15.0f;
    led.color.a = lit ? 1.0f : 0.25f;
    arr.markers.push_back(led);
  }
  int id = 0;
  for (const sn::Lamp& l : env_->lamps()) {
    visualization_msgs::Marker lamp = base("lamps", id++, visualization_msgs::Marker::SPHERE);
    lamp.pose.position = toPoint(l.position);
    lamp.scale.x = lamp.scale.y = lamp.scale.z = 0.05;
    lamp.color.r = static_cast<float>(l.colour.x());
    lamp.color.g = static_cast<float>(l.colour.y());
    lamp.color.b = static_cast<float>(l.colour.z());
    lamp.color.a = l.intensity > 0 ? 1.0f : 0.3f;
    arr.markers.push_back(lamp);
  }
  pubs_["markers"].publish(arr);
}

void RobotModulesRos::onLeds(const sbot_msgs::LedState::ConstPtr& msg) {
  if (!robot_) return;
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
  if (!robot_) return;
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
  if (!robot_) {
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
    msg += std::string(msg.empty() ? "" : "; ") + "level '" + robot_->level() +
           "' has no gripper model: command accepted, nothing moves (seed 2.2.3)";
  res.message = msg;
  return true;
}

bool RobotModulesRos::onSetSideArm(sbot_msgs::SetSideArm::Request& req, sbot_msgs::SetSideArm::Response& res) {
  res.success = false;
  res.clamped = false;
  if (!robot_) {
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  if (!side_arm_->available()) {
    res.message = name_ + " (level '" + robot_->level() + "') has no side arm (Detailed only)";
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
  if (!robot_) {
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
  if (!robot_) {  // deleted: answered as the other per-robot services are (it said success)
    res.message = "robot '" + name_ + "' is not in the simulation";
    return true;
  }
  auto it = rates_.find(req.channel);
  if (it == rates_.end()) {
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
  const double step_hz = 1.0 / world_->config().step;
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
