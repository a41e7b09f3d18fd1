// libsbot_ros: the standard s-bot API (include/sbot.h, seed Appendix A) over the swarmbot3d
// simulator's ROS interface, for one robot chosen by namespace. See ../../README.md for the mapping.
// This file: the shared state and initSwarmBot / shutdownSwarmBot; the getters and setters are in
// one file per device group (locomotion, gripper, side_arm, sensors, leds_sound), all reading
// through latest.h's Latest<Msg> (api.h: read, readField, readFields, readSensor, readAll).
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
#include "api.h"

#include <unistd.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <fstream>

#include <sbot_msgs/LockstepHold.h>
#include <sbot_msgs/SetSamplingRate.h>
#include <sbot_msgs/TrackSpeed.h>
#include <std_msgs/Float64.h>

namespace sbot_api {

namespace {
void (*g_error)(const char*) = nullptr;
void (*g_warning)(const char*) = nullptr;
}  // namespace

std::atomic<bool> g_lockstep{false};
HoldState g_hold;
Availability g_available;
std::unique_ptr<Api> g;

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

namespace {

std::vector<std::string> processArgs() {
  std::vector<std::string> args;
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string a;
  while (std::getline(f, a, '\0')) args.push_back(a);
  if (args.empty()) args.push_back("sbot_controller");
  return args;
}

}  // namespace

}  // namespace sbot_api

using namespace sbot_api;

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

}  // extern "C"
