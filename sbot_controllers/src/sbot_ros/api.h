// libsbot_ros's shared state (Api: the node handle, the command publishers, one Latest<Msg> per
// topic the getters read) and the helpers every device file uses: ready(), call() for a service,
// setRate() for a sampling rate, and read() / readSensor() / readAll(), the getters' one way to the
// blocking read (latest.h).
#pragma once

#include <memory>

#include <sbot_msgs/Battery.h>
#include <sbot_msgs/Climate.h>
#include <sbot_msgs/GripperState.h>
#include <sbot_msgs/GroundArray.h>
#include <sbot_msgs/LightArray.h>
#include <sbot_msgs/ProximityArray.h>
#include <sbot_msgs/SideArmState.h>
#include <sbot_msgs/Slope.h>
#include <sbot_msgs/TrackState.h>
#include <sbot_msgs/TurretState.h>

#include "latest.h"
#include "sbot.h"
#include "sbot_controllers/lockstep_client.h"

namespace sbot_api {

/// An API argument into a service's int16 field, clamped (a bare cast wraps 40000 to -25536).
inline int16_t toInt16(int v) { return static_cast<int16_t>(v < -32768 ? -32768 : v > 32767 ? 32767 : v); }

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

extern std::unique_ptr<Api> g;

/// initSwarmBot has run and ROS is up; else reports `fn` as an error.
bool ready(const char* fn);

/// Call the robot's `service`; false (reported as an error) when it fails or answers !success; a
/// message with success is reported as a warning.
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

/// set_sampling_rate of `channel` to an sbot.h code, checked first.
void setRate(const char* channel, SamplingRate rate, const char* fn);

/// A getter's read of `topic` (a Latest<Msg> member of Api) into `out`; false when not initialised
/// or no message came. `fresh` / `index`: Latest::get.
template <class Msg>
bool read(const char* fn, Latest<Msg> Api::*topic, Msg* out, bool fresh = false,
          std::size_t index = Latest<Msg>::npos) {
  return ready(fn) && ((*g).*topic).get(*g->nh, out, fresh, index);
}

/// One sensor of a sampled array topic (readings[0..count)): 0 when `sensor` is out of range
/// (reported as a warning) or nothing was read.
template <class Msg>
unsigned readSensor(const char* fn, Latest<Msg> Api::*topic, unsigned sensor, unsigned count) {
  if (sensor >= count) {
    report(false, "%s(%u): sensor outside [0, %u]", fn, sensor, count - 1);
    return 0;
  }
  Msg s;
  if (!read(fn, topic, &s, true, sensor)) return 0;
  return s.readings[sensor];
}

/// Every sensor of a sampled array topic into sensors[0..count); zeros when nothing was read.
template <class Msg>
void readAll(const char* fn, Latest<Msg> Api::*topic, unsigned* sensors, int count) {
  Msg s;
  if (!read(fn, topic, &s, true)) {
    for (int k = 0; k < count; ++k) sensors[k] = 0;
    return;
  }
  for (int k = 0; k < count; ++k) sensors[k] = s.readings[k];
}

/// A getter of one field of `topic`'s latest message; 0 when nothing was read.
template <class Msg, class F>
F readField(const char* fn, Latest<Msg> Api::*topic, F Msg::*field) {
  Msg s;
  return read(fn, topic, &s) ? s.*field : F(0);
}

/// Where readFields puts one field: *out = msg.*field (nothing when out is null).
template <class Out, class Msg, class F>
struct Into {
  Out* out;
  F Msg::*field;
};
template <class Out, class Msg, class F>
Into<Out, Msg, F> into(Out* out, F Msg::*field) {
  return {out, field};
}

/// A getter of several fields of `topic`'s latest message (fresh: Latest::get); nothing written
/// when nothing was read.
template <class Msg, class... Outs>
void readFields(const char* fn, Latest<Msg> Api::*topic, bool fresh, Outs... outs) {
  Msg s;
  if (!read(fn, topic, &s, fresh)) return;
  ((outs.out ? void(*outs.out = s.*(outs.field)) : void()), ...);
}

}  // namespace sbot_api
