// libsbot_ros: the standard s-bot API (include/sbot.h, seed Appendix A) over the swarmbot3d
// simulator's ROS interface, for one robot chosen by namespace. See ../README.md for the mapping.
//
// * initSwarmBot starts a roscpp node "sbot_api" (anonymous) in the namespace $SBOT_NAMESPACE, else
//   the one ROS gives the process (__ns:= on the command line, which we read from /proc/self/cmdline
//   because sbot.h does not pass argc/argv, or $ROS_NAMESPACE as roslaunch sets it), with a private
//   spinner thread. It waits (up to 30 s wall) for the robot's services.
// * Getters return the latest received value. Topics are subscribed on first use (a sensor nobody
//   reads costs the simulator nothing); the first call waits up to 2 s wall for a first message.
//   A getter of a module the robot's level lacks (<robot>/sensors_available) returns at once as a
//   failed read and reports it once.
// * Sampled sensors (proximity, ground, light, slope) behave like the hardware's sampling: a reading
//   of one sensor is refreshed once per sampling period. A getter asked again for a sensor whose
//   current sample it already returned waits (up to 1 s wall) for the next sample. A controller's
//   read-act loop therefore runs once per sample in SIMULATED time, whatever the simulator's
//   real-time factor. Set SBOT_NO_SAMPLE_WAIT=1 to always return the latest value at once.
// * Lock-step (the simulator's ~lockstep true, read from /sim/lockstep at initSwarmBot): each time a
//   getter blocks for a message it tells the simulator so on /sim/controller_sync (the topic, the
//   stamp it has, the cmd_speed / speaker messages sent so far), and the simulator holds its clock
//   until that message is read and those commands have arrived (sbot_sim/src/node/lockstep_gate.h).
//   Every getter also waits for the simulator's <robot>/lockstep_hold of the instant it holds at and
//   for the messages published up to then (ROS orders messages per topic only). The waits then last
//   up to 30 s wall instead of 2 s / 1 s (the simulator may be holding for another, slower
//   controller) and end early when the simulator disconnects.
// * Setters publish (setSpeed -> cmd_speed, LEDs -> leds via set_leds) or call services (turret,
//   gripper, side arm, sampling rates). Clamped values are reported through the warning handler,
//   failures through the error handler (if given; else stderr).
// * playMusic(filename): plays one tone on the simulated speaker (seed 2.2.10: one frequency at a
//   time), at 200 + (FNV-1a hash of the filename mod 1800) Hz, so different files are
//   distinguishable by the sound sensors; stopMusic() silences it.
#include "sbot.h"
#include "sbot_controllers/lockstep_client.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sbot_msgs/Battery.h>
#include <sbot_msgs/Climate.h>
#include <sbot_msgs/GripperState.h>
#include <sbot_msgs/GroundArray.h>
#include <sbot_msgs/LedState.h>
#include <sbot_msgs/LightArray.h>
#include <sbot_msgs/LockstepHold.h>
#include <sbot_msgs/ProximityArray.h>
#include <sbot_msgs/SetGripper.h>
#include <sbot_msgs/SetLeds.h>
#include <sbot_msgs/SetSamplingRate.h>
#include <sbot_msgs/SensorsAvailable.h>
#include <sbot_msgs/SetSideArm.h>
#include <sbot_msgs/SetTurret.h>
#include <sbot_msgs/SideArmState.h>
#include <sbot_msgs/Slope.h>
#include <sbot_msgs/TrackSpeed.h>
#include <sbot_msgs/TrackState.h>
#include <sbot_msgs/TurretState.h>
#include <std_msgs/Float64.h>

namespace {

/// An API argument into a service's int16 field, clamped (a bare cast wraps 40000 to -25536).
int16_t toInt16(int v) { return static_cast<int16_t>(v < -32768 ? -32768 : v > 32767 ? 32767 : v); }

using Clock = std::chrono::steady_clock;

void (*g_error)(const char*) = nullptr;
void (*g_warning)(const char*) = nullptr;

void report(bool error, const char* fmt, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof(buf), fmt, ap);
  va_end(ap);
  auto handler = error ? g_error : g_warning;
  if (handler) {
    handler(buf);
  } else {
    std::fprintf(stderr, "sbot %s: %s\n", error ? "error" : "warning", buf);
  }
}

std::atomic<bool> g_lockstep{false};  ///< the simulator runs in lock-step with the controllers

/// How long a getter waits for a message: `normal`, or 30 s in lock-step.
std::chrono::seconds waitLimit(int normal) { return std::chrono::seconds(g_lockstep ? 30 : normal); }

/// Lock-step: tell the simulator this controller now waits for a message on `channel` stamped later
/// than `after` (defined below, after Api).
/// `first`: the controller has just subscribed; the connection is awaited first (up to 5 s).
void announceWait(const std::string& channel, const ros::Time& after, const ros::Subscriber& sub, bool first);

/// Wait on `cv` (its `lock` held) in 100 ms slices until `ready`, `deadline`, ROS shuts down, or, if
/// `sim` is given, that subscription has lost its publisher: the simulator is gone, and a controller
/// stopped with it must not stay blocked.
template <class Ready>
void waitSliced(std::unique_lock<std::mutex>& lock, std::condition_variable& cv, Clock::time_point deadline,
                const ros::Subscriber* sim, Ready ready) {
  while (!ready() && ros::ok() && Clock::now() < deadline) {
    cv.wait_for(lock, std::chrono::milliseconds(100), ready);
    if (sim && *sim && sim->getNumPublishers() == 0) break;
  }
}

/// Lock-step: where the simulator holds for this controller. A controller runs only while the
/// simulator holds its clock at `now` for it (it woke on a message stamped `now`); the simulator
/// then sends a LockstepHold listing what it has published on each topic up to `now`, and every
/// getter first waits for that, so it returns what was published up to `now` whatever the order in
/// which the topics' messages arrived.
struct HoldState {
  std::mutex m;
  std::condition_variable cv;
  ros::Time now;                                   ///< the sim time the controller acts at
  ros::Time held;                                  ///< stamp of the latest LockstepHold received
  std::map<std::string, ros::Time> latest;         ///< its topic -> latest stamp published
  ros::Subscriber sub;                             ///< <robot>/lockstep_hold

  void woke(const ros::Time& t) {
    std::lock_guard<std::mutex> l(m);
    if (t > now) now = t;
  }
  ros::Time current() {
    std::lock_guard<std::mutex> l(m);
    return now;
  }
  /// The latest stamp published on `topic` up to `now` (waits for the hold of `now`; 0 = unknown).
  ros::Time latestOf(const std::string& topic) {
    std::unique_lock<std::mutex> l(m);
    waitSliced(l, cv, Clock::now() + std::chrono::seconds(30), &sub, [this] { return held >= now; });
    if (held < now) return ros::Time(0);
    const auto it = latest.find(topic);
    return it == latest.end() ? ros::Time(0) : it->second;
  }
};
HoldState g_hold;

/// What the robot's model level offers (<robot>/sensors_available, latched; republished when the
/// level changes). A getter of a topic the level does not publish returns at once, reporting it
/// once, instead of waiting for a message that never comes.
struct Availability {
  std::mutex m;
  std::atomic<bool> known{false};
  std::string robot, level;
  std::set<std::string> channels;
  std::set<std::string> reported;  ///< "level/topic" already reported
  ros::Subscriber sub;

  void update(const sbot_msgs::SensorsAvailable& msg) {
    std::lock_guard<std::mutex> l(m);
    known = true;
    robot = msg.robot;
    level = msg.level;
    channels = std::set<std::string>(msg.channels.begin(), msg.channels.end());
  }
  /// False (after reporting once through the error handler) if `topic` is one the level may lack
  /// and does not publish.
  bool offers(const std::string& topic) {
    static const std::set<std::string> optional = {"proximity", "ground", "light", "slope", "battery",
                                                   "climate", "gripper/state", "side_arm/state"};
    std::string message;
    {
      std::lock_guard<std::mutex> l(m);
      if (!known || !optional.count(topic) || channels.count(topic)) return true;
      if (!reported.insert(level + "/" + topic).second) return false;
      std::string list;
      for (const auto& c : channels) list += (list.empty() ? "" : " ") + c;
      message = robot + " is a " + level + " s-bot, which has no " + topic + " (it offers: " + list +
                "); the getter returns without a value";
    }
    report(true, "%s", message.c_str());
    return false;
  }
};
Availability g_available;

/// Latest message of one topic, subscribed on first use, with per-index "already returned" stamps.
template <class Msg>
class Latest {
 public:
  Latest(const char* topic, std::size_t indices) : topic_(topic), returned_(indices, ros::Time(0)) {}

  /// Copy of the latest message; waits for a first one, and (with `fresh`) for one newer than the
  /// sample index `index` last returned (index = npos: all indices).
  bool get(ros::NodeHandle& nh, Msg* out, bool fresh = false, std::size_t index = npos) {
    if (!g_available.offers(topic_)) return false;
    std::unique_lock<std::mutex> lock(m_);
    if (!sub_) {
      sub_ = nh.subscribe<Msg>(topic_, 5, [this](const typename Msg::ConstPtr& msg) {
        std::lock_guard<std::mutex> l(m_);
        msg_ = *msg;
        has_ = true;
        ++seq_;
        cv_.notify_all();
      }, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    }
    auto stale = [&] {
      const ros::Time s = stamp(msg_);
      if (index == npos) {
        for (const auto& r : returned_)
          if (r >= s) return true;
        return false;
      }
      return returned_[index] >= s;
    };
    if (g_lockstep) {
      if (!getInLockstep(lock, fresh && sampleWait(), stale)) return false;
    } else {
      if (!has_) waitUntil(lock, 2, [this] { return has_; });
      if (!has_) return false;
      if (fresh && sampleWait() && stale()) waitUntil(lock, 1, [&] { return !stale(); });
    }
    const ros::Time s = stamp(msg_);
    if (index == npos) {
      for (auto& r : returned_) r = s;
    } else if (index < returned_.size()) {
      returned_[index] = s;
    }
    *out = msg_;
    return true;
  }
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

 private:
  /// The lock-step path of get(): a first message published after the controller's present, the
  /// topic caught up with the simulator's hold, and (fresh) a message newer than the one returned.
  /// Each wait for a new message is announced, so the simulator steps until it publishes one and
  /// then holds again.
  template <class Stale>
  bool getInLockstep(std::unique_lock<std::mutex>& lock, bool fresh, Stale stale) {
    if (!has_) {
      const ros::Time now = g_hold.current();
      lock.unlock();
      announceWait(topic_, now, sub_, true);
      lock.lock();
      waitUntil(lock, 2, [&] { return has_ && stamp(msg_) > now; });
      if (!has_) return false;
      g_hold.woke(stamp(msg_));
    }
    catchUp(lock);
    if (fresh && stale()) {
      const ros::Time have = stamp(msg_);
      lock.unlock();
      announceWait(topic_, have, sub_, false);
      lock.lock();
      waitUntil(lock, 1, [&] { return stamp(msg_) > have; });
      if (stamp(msg_) > have) {
        g_hold.woke(stamp(msg_));
        catchUp(lock);
      }
    }
    return true;
  }
  /// Wait until this topic's message is the latest the simulator published up to the present.
  void catchUp(std::unique_lock<std::mutex>& lock) {
    lock.unlock();
    const ros::Time need = g_hold.latestOf(topic_);
    lock.lock();
    waitUntil(lock, 1, [&] { return stamp(msg_) >= need; });
  }
  /// Wait (lock held on entry and exit) until `ready`, ROS shuts down, `normal` seconds pass (30 in
  /// lock-step), or, in lock-step, the simulator disconnects (so a controller stopped with its
  /// simulator is not left blocked for the full 30 s).
  template <class Pred>
  void waitUntil(std::unique_lock<std::mutex>& lock, int normal, Pred ready) {
    waitSliced(lock, cv_, Clock::now() + waitLimit(normal), g_lockstep ? &sub_ : nullptr, ready);
  }
  static bool sampleWait() {
    static const bool wait = !(std::getenv("SBOT_NO_SAMPLE_WAIT") && std::string(std::getenv("SBOT_NO_SAMPLE_WAIT")) == "1");
    return wait;
  }
  template <class M>
  static auto stamp(const M& m) -> decltype(m.header.stamp) { return m.header.stamp; }
  std::string topic_;
  std::mutex m_;
  std::condition_variable cv_;
  ros::Subscriber sub_;
  Msg msg_;
  bool has_ = false;
  std::uint64_t seq_ = 0;
  std::vector<ros::Time> returned_;
};

struct Api {
  std::unique_ptr<ros::NodeHandle> nh;
  std::unique_ptr<ros::AsyncSpinner> spinner;
  ros::Publisher speed_pub, speaker_pub;
  std::unique_ptr<sbot_controllers::LockstepClient> lockstep;  ///< /sim/controller_sync
  std::atomic<std::uint64_t> speed_sent{0}, speaker_sent{0};
  Latest<sbot_msgs::ProximityArray> proximity{"proximity", 15};
  Latest<sbot_msgs::GroundArray> ground{"ground", 4};
  Latest<sbot_msgs::LightArray> light{"light", 8};
  Latest<sbot_msgs::Slope> slope{"slope", 1};
  Latest<sbot_msgs::Battery> battery{"battery", 1};
  Latest<sbot_msgs::Climate> climate{"climate", 1};
  Latest<sbot_msgs::TrackState> tracks{"track_state", 1};
  Latest<sbot_msgs::TurretState> turret{"turret/state", 1};
  Latest<sbot_msgs::GripperState> gripper{"gripper/state", 1};
  Latest<sbot_msgs::SideArmState> side_arm{"side_arm/state", 1};
  std::mutex cmd_m;
  bool gripper_known = false;
  int gripper_elevation = 0, gripper_aperture = 0;  ///< last commanded
  bool arm_known = false;
  int arm_e = 0, arm_r = 0, arm_d = 60;
};

std::unique_ptr<Api> g;

void announceWait(const std::string& channel, const ros::Time& after, const ros::Subscriber& sub, bool first) {
  if (!g_lockstep || !g) return;
  // The simulator can only hold for a message it can deliver: wait for the connection first.
  if (first) sbot_controllers::pollUntil([&sub] { return sub.getNumPublishers() > 0; }, Clock::now() + std::chrono::seconds(5));
  if (channel.empty())
    g->lockstep->leaving();
  else
    g->lockstep->waitingFor(channel, after, g->speed_sent, g->speaker_sent, first);
}

bool ready(const char* fn) {
  if (g && g->nh && ros::ok()) return true;
  report(true, "%s: initSwarmBot() has not been called (or ROS shut down)", fn);
  return false;
}

std::vector<std::string> processArgs() {
  std::vector<std::string> args;
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string a;
  while (std::getline(f, a, '\0')) args.push_back(a);
  if (args.empty()) args.push_back("sbot_controller");
  return args;
}

template <class Srv>
bool call(const char* service, Srv& srv, const char* fn) {
  if (!ready(fn)) return false;
  ros::ServiceClient c = g->nh->serviceClient<Srv>(service);
  if (!c.call(srv)) {
    report(true, "%s: service %s/%s failed (is the simulator running?)", fn, g->nh->getNamespace().c_str(), service);
    return false;
  }
  if (!srv.response.success) {
    report(true, "%s: %s", fn, srv.response.message.c_str());
    return false;
  }
  if (!srv.response.message.empty()) report(false, "%s: %s", fn, srv.response.message.c_str());
  return true;
}

void setRate(const char* channel, SamplingRate rate, const char* fn) {
  // Named with the caller's value: the uint8 field made 999 read "code 255" in the reply, and 0
  // (the service's "use hz") read "hz must be > 0".
  if (static_cast<unsigned>(rate) < SAMPLING_RATE_50 || static_cast<unsigned>(rate) > SAMPLING_RATE_0_5) {
    report(false, "%s(%u): not a SAMPLING_RATE code (SAMPLING_RATE_50 = 1 .. SAMPLING_RATE_0_5 = 8)", fn,
           static_cast<unsigned>(rate));
    return;
  }
  sbot_msgs::SetSamplingRate srv;
  srv.request.channel = channel;
  srv.request.rate = static_cast<uint8_t>(rate);
  call("set_sampling_rate", srv, fn);
}

void gripperCommand(const char* fn) {
  sbot_msgs::SetGripper srv;
  srv.request.elevation = static_cast<int16_t>(g->gripper_elevation);
  srv.request.aperture = static_cast<int16_t>(g->gripper_aperture);
  if (call("set_gripper", srv, fn) && srv.response.clamped) {
    g->gripper_elevation = srv.response.applied_elevation;
    g->gripper_aperture = srv.response.applied_aperture;
  }
}

void knowGripper() {
  if (g->gripper_known) return;
  sbot_msgs::GripperState s;
  if (g->gripper.get(*g->nh, &s)) {
    g->gripper_elevation = s.elevation;
    g->gripper_aperture = s.aperture;
  }
  g->gripper_known = true;
}

void knowArm() {
  if (g->arm_known) return;
  sbot_msgs::SideArmState s;
  if (g->side_arm.get(*g->nh, &s)) {
    g->arm_e = s.elevation;
    g->arm_r = s.rotation;
    g->arm_d = s.depth;
  }
  g->arm_known = true;
}

void armCommand(uint8_t jaws, const char* fn) {
  sbot_msgs::SetSideArm srv;
  srv.request.elevation = static_cast<int16_t>(g->arm_e);
  srv.request.rotation = static_cast<int16_t>(g->arm_r);
  srv.request.depth = static_cast<int16_t>(g->arm_d);
  srv.request.jaws = jaws;
  call("set_side_arm", srv, fn);
}

void leds(const std::vector<unsigned>& groups, const unsigned* r, const unsigned* gr, const unsigned* b,
          const BlinkingRate* blink, bool same, const char* fn) {
  sbot_msgs::SetLeds srv;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const std::size_t k = same ? 0 : i;
    if (groups[i] > 7) {  // named with the caller's value (the uint8 field made 300 read "group 255")
      report(false, "%s: light group %u outside [0, 7]", fn, groups[i]);
      return;
    }
    srv.request.group.push_back(static_cast<uint8_t>(groups[i]));
    srv.request.r.push_back(static_cast<uint8_t>(r[k] > 255 ? 255 : r[k]));
    srv.request.g.push_back(static_cast<uint8_t>(gr[k] > 255 ? 255 : gr[k]));
    srv.request.b.push_back(static_cast<uint8_t>(b[k] > 255 ? 255 : b[k]));
    srv.request.blink.push_back(static_cast<uint8_t>(blink[k] > 255 ? 255 : blink[k]));
  }
  call("set_leds", srv, fn);
}

}  // namespace

extern "C" {

void initSwarmBot(void (*errorHandler)(const char*), void (*warningHandler)(const char*)) {
  g_error = errorHandler;
  g_warning = warningHandler;
  if (g) return;
  std::vector<std::string> args = processArgs();
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(&a[0]);
  int argc = static_cast<int>(argv.size());
  if (!ros::isInitialized())
    ros::init(argc, argv.data(), "sbot_api", ros::init_options::AnonymousName | ros::init_options::NoSigintHandler);
  g = std::make_unique<Api>();
  const char* ns = std::getenv("SBOT_NAMESPACE");
  g->nh = std::make_unique<ros::NodeHandle>(ns && *ns ? std::string(ns) : std::string());
  g->spinner = std::make_unique<ros::AsyncSpinner>(1);
  g->spinner->start();
  g->speed_pub = g->nh->advertise<sbot_msgs::TrackSpeed>("cmd_speed", 10);
  g->speaker_pub = g->nh->advertise<std_msgs::Float64>("speaker", 10, true);
  // Every service the API calls: the simulator advertises them one after another, so one being up
  // does not mean the others are (a first setTurretRotation right after set_gripper appeared can
  // fail; rostest sbot_api_avoidance). 30 s for them all.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  for (const char* service : {"set_gripper", "set_side_arm", "set_leds", "set_sampling_rate", "set_turret"}) {
    const std::string probe = g->nh->resolveName(service);
    const double left = std::max(0.1, (deadline - ros::WallTime::now()).toSec());
    if (!ros::service::waitForService(probe, ros::Duration(left))) {
      report(true, "initSwarmBot: %s not available after 30 s: is the simulator running and the namespace "
                   "right (SBOT_NAMESPACE, __ns:=, ROS_NAMESPACE)?", probe.c_str());
      return;
    }
  }
  const auto until = Clock::now() + std::chrono::seconds(5);
  sbot_controllers::pollUntil([] { return g->speed_pub.getNumSubscribers() > 0; }, until);
  g_available.sub = g->nh->subscribe<sbot_msgs::SensorsAvailable>(
      "sensors_available", 1, [](const sbot_msgs::SensorsAvailable::ConstPtr& m) { g_available.update(*m); },
      ros::VoidConstPtr(), ros::TransportHints());
  sbot_controllers::pollUntil([] { return g_available.known.load(); }, until + std::chrono::seconds(2));
  g->lockstep = std::make_unique<sbot_controllers::LockstepClient>(*g->nh);
  if (g->lockstep->enabled()) {
    g_hold.sub = g->nh->subscribe<sbot_msgs::LockstepHold>("lockstep_hold", 10, [](const sbot_msgs::LockstepHold::ConstPtr& h) {
      std::lock_guard<std::mutex> l(g_hold.m);
      g_hold.held = h->stamp;
      g_hold.latest.clear();
      for (std::size_t k = 0; k < h->topics.size() && k < h->latest.size(); ++k) g_hold.latest[h->topics[k]] = h->latest[k];
      g_hold.cv.notify_all();
    }, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    sbot_controllers::pollUntil([] { return g_hold.sub.getNumPublishers() > 0; }, until + std::chrono::seconds(5));
    if (!g->lockstep->connected() || g_hold.sub.getNumPublishers() == 0)
      report(false, "initSwarmBot: the simulator runs in lock-step but is not connected on /sim/controller_sync "
                    "and %s", g_hold.sub.getTopic().c_str());
    g_lockstep = true;
  }
}

void shutdownSwarmBot(void) {
  if (!g) return;
  if (ros::ok()) {
    setSpeed(0, 0);
    if (g_lockstep) announceWait("", ros::Time(0), ros::Subscriber(), false);  // leaving: stop holding for us
    usleep(100000);
  }
  g_lockstep = false;
  g_hold.sub.shutdown();
  g_available.sub.shutdown();
  g->spinner->stop();
  g.reset();
  ros::shutdown();
}

void setSpeed(int left, int right) {
  if (!ready("setSpeed")) return;
  if (left < -127 || left > 127 || right < -127 || right > 127)
    report(false, "setSpeed(%d, %d): outside [-127, 127], clamped", left, right);
  sbot_msgs::TrackSpeed m;
  m.left = static_cast<int16_t>(left < -127 ? -127 : left > 127 ? 127 : left);
  m.right = static_cast<int16_t>(right < -127 ? -127 : right > 127 ? 127 : right);
  g->speed_pub.publish(m);
  ++g->speed_sent;
}

void getSpeed(int* left, int* right) {
  sbot_msgs::TrackState s;
  if (!ready("getSpeed") || !g->tracks.get(*g->nh, &s)) return;
  if (left) *left = s.measured_left;
  if (right) *right = s.measured_right;
}

void getTrackTorque(int* left, int* right) {
  sbot_msgs::TrackState s;
  if (!ready("getTrackTorque") || !g->tracks.get(*g->nh, &s)) return;
  if (left) *left = s.torque_left;
  if (right) *right = s.torque_right;
}

void setTurretRotation(int pos) {
  sbot_msgs::SetTurret srv;
  srv.request.position = toInt16(pos);
  call("set_turret", srv, "setTurretRotation");
}

int getTurretRotation(void) {
  sbot_msgs::TurretState s;
  if (!ready("getTurretRotation") || !g->turret.get(*g->nh, &s)) return 0;
  return s.rotation;
}

int getTurretRotationTorque(void) {
  sbot_msgs::TurretState s;
  if (!ready("getTurretRotationTorque") || !g->turret.get(*g->nh, &s)) return 0;
  return s.torque;
}

void setGripperElevation(int elevation) {
  if (!ready("setGripperElevation")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowGripper();
  g->gripper_elevation = toInt16(elevation);
  gripperCommand("setGripperElevation");
}

int getGripperElevation(void) {
  sbot_msgs::GripperState s;
  if (!ready("getGripperElevation") || !g->gripper.get(*g->nh, &s)) return 0;
  return s.elevation;
}

void setGripperAperture(int aperture) {
  if (!ready("setGripperAperture")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowGripper();
  g->gripper_aperture = toInt16(aperture);
  gripperCommand("setGripperAperture");
}

int getGripperAperture(void) {
  sbot_msgs::GripperState s;
  if (!ready("getGripperAperture") || !g->gripper.get(*g->nh, &s)) return 0;
  return s.aperture;
}

int getGripperElevationTorque(void) {
  sbot_msgs::GripperState s;
  if (!ready("getGripperElevationTorque") || !g->gripper.get(*g->nh, &s)) return 0;
  return s.elevation_torque;
}

void getGripperOpticalBarrier(unsigned* internal, unsigned* external, unsigned* combined) {
  sbot_msgs::GripperState s;
  if (!ready("getGripperOpticalBarrier") || !g->gripper.get(*g->nh, &s)) return;
  if (internal) *internal = s.barrier_internal;
  if (external) *external = s.barrier_external;
  if (combined) *combined = s.barrier_combined;
}

void setSideArmPos(int elevation, int rotation, int depth) {
  if (!ready("setSideArmPos")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  g->arm_known = true;
  g->arm_e = toInt16(elevation);  // the service's int16 (40000 became -25536: the opposite limit)
  g->arm_r = toInt16(rotation);
  g->arm_d = toInt16(depth);
  armCommand(sbot_msgs::SetSideArm::Request::JAWS_KEEP, "setSideArmPos");
}

void getSideArmPos(int* elevation, int* rotation, int* depth) {
  sbot_msgs::SideArmState s;
  if (!ready("getSideArmPos") || !g->side_arm.get(*g->nh, &s)) return;
  if (elevation) *elevation = s.elevation;
  if (rotation) *rotation = s.rotation;
  if (depth) *depth = s.depth;
}

void getSideArmTorque(int* elevation, int* rotation, int* depth) {
  sbot_msgs::SideArmState s;
  if (!ready("getSideArmTorque") || !g->side_arm.get(*g->nh, &s)) return;
  if (elevation) *elevation = s.torque_elevation;
  if (rotation) *rotation = s.torque_rotation;
  if (depth) *depth = s.torque_depth;
}

void setSideArmOpened(void) {
  if (!ready("setSideArmOpened")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowArm();
  armCommand(sbot_msgs::SetSideArm::Request::JAWS_OPEN, "setSideArmOpened");
}

void setSideArmClosed(void) {
  if (!ready("setSideArmClosed")) return;
  std::lock_guard<std::mutex> l(g->cmd_m);
  knowArm();
  armCommand(sbot_msgs::SetSideArm::Request::JAWS_CLOSE, "setSideArmClosed");
}

void getSideArmOpticalBarrier(unsigned* internal, unsigned* external, unsigned* combined) {
  sbot_msgs::SideArmState s;
  if (!ready("getSideArmOpticalBarrier") || !g->side_arm.get(*g->nh, &s)) return;
  if (internal) *internal = s.barrier_internal;
  if (external) *external = s.barrier_external;
  if (combined) *combined = s.barrier_combined;
}

unsigned getProximitySensor(unsigned sensor) {
  if (sensor > 14) {
    report(false, "getProximitySensor(%u): sensor outside [0, 14]", sensor);
    return 0;
  }
  sbot_msgs::ProximityArray s;
  if (!ready("getProximitySensor") || !g->proximity.get(*g->nh, &s, true, sensor)) return 0;
  return s.readings[sensor];
}

void getAllProximitySensors(unsigned sensors[15]) {
  sbot_msgs::ProximityArray s;
  if (!ready("getAllProximitySensors") || !g->proximity.get(*g->nh, &s, true)) {
    for (int k = 0; k < 15; ++k) sensors[k] = 0;
    return;
  }
  for (int k = 0; k < 15; ++k) sensors[k] = s.readings[k];
}

void setProximitySamplingRate(SamplingRate rate) { setRate("proximity", rate, "setProximitySamplingRate"); }

unsigned getGroundSensor(unsigned sensor) {
  if (sensor > 3) {
    report(false, "getGroundSensor(%u): sensor outside [0, 3]", sensor);
    return 0;
  }
  sbot_msgs::GroundArray s;
  if (!ready("getGroundSensor") || !g->ground.get(*g->nh, &s, true, sensor)) return 0;
  return s.readings[sensor];
}

void getAllGroundSensors(unsigned sensors[4]) {
  sbot_msgs::GroundArray s;
  if (!ready("getAllGroundSensors") || !g->ground.get(*g->nh, &s, true)) {
    for (int k = 0; k < 4; ++k) sensors[k] = 0;
    return;
  }
  for (int k = 0; k < 4; ++k) sensors[k] = s.readings[k];
}

void setGroundSamplingRate(SamplingRate rate) { setRate("ground", rate, "setGroundSamplingRate"); }

unsigned getLightSensor(unsigned sensor) {
  if (sensor > 7) {
    report(false, "getLightSensor(%u): sensor outside [0, 7]", sensor);
    return 0;
  }
  sbot_msgs::LightArray s;
  if (!ready("getLightSensor") || !g->light.get(*g->nh, &s, true, sensor)) return 0;
  return s.readings[sensor];
}

void getAllLightSensors(unsigned sensors[8]) {
  sbot_msgs::LightArray s;
  if (!ready("getAllLightSensors") || !g->light.get(*g->nh, &s, true)) {
    for (int k = 0; k < 8; ++k) sensors[k] = 0;
    return;
  }
  for (int k = 0; k < 8; ++k) sensors[k] = s.readings[k];
}

void setLightColor(unsigned light, unsigned r, unsigned gr, unsigned b, BlinkingRate blink) {
  leds({light}, &r, &gr, &b, &blink, true, "setLightColor");
}

void setAllLightColor(unsigned r[8], unsigned gr[8], unsigned b[8], BlinkingRate blink[8]) {
  leds({0, 1, 2, 3, 4, 5, 6, 7}, r, gr, b, blink, false, "setAllLightColor");
}

void setSameLightColor(unsigned r, unsigned gr, unsigned b, BlinkingRate blink) {
  leds({0, 1, 2, 3, 4, 5, 6, 7}, &r, &gr, &b, &blink, true, "setSameLightColor");
}

void setLightSamplingRate(SamplingRate rate) { setRate("light", rate, "setLightSamplingRate"); }

void getTemperatureAndHumidityLeft(float* temperature, float* humidity) {
  sbot_msgs::Climate s;
  if (!ready("getTemperatureAndHumidityLeft") || !g->climate.get(*g->nh, &s)) return;
  if (temperature) *temperature = s.temperature_left;
  if (humidity) *humidity = s.humidity_left;
}

void getTemperatureAndHumidityRight(float* temperature, float* humidity) {
  sbot_msgs::Climate s;
  if (!ready("getTemperatureAndHumidityRight") || !g->climate.get(*g->nh, &s)) return;
  if (temperature) *temperature = s.temperature_right;
  if (humidity) *humidity = s.humidity_right;
}

void getSlope(int* pitch, int* roll) {
  sbot_msgs::Slope s;
  if (!ready("getSlope") || !g->slope.get(*g->nh, &s, true)) return;
  if (pitch) *pitch = s.pitch;
  if (roll) *roll = s.roll;
}

void setSlopeSamplingRate(SamplingRate rate) { setRate("slope", rate, "setSlopeSamplingRate"); }

unsigned getBatteryVoltage(void) {
  sbot_msgs::Battery s;
  if (!ready("getBatteryVoltage") || !g->battery.get(*g->nh, &s)) return 0;
  return s.voltage_units;
}

void playMusic(const char* filename) {
  if (!ready("playMusic")) return;
  std::uint32_t h = 2166136261u;  // FNV-1a
  for (const char* p = filename ? filename : ""; *p; ++p) h = (h ^ static_cast<unsigned char>(*p)) * 16777619u;
  std_msgs::Float64 m;
  m.data = 200.0 + static_cast<double>(h % 1800u);
  g->speaker_pub.publish(m);
  ++g->speaker_sent;
}

void stopMusic(void) {
  if (!ready("stopMusic")) return;
  std_msgs::Float64 m;
  m.data = 0;
  g->speaker_pub.publish(m);
  ++g->speaker_sent;
}

}  // extern "C"
