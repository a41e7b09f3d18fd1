// The blocking read every sbot.h getter shares: Latest<Msg>, the latest message of one topic,
// subscribed on first use, waiting for a first message, for the next sample (sampled sensors) and, in
// lock-step, for the simulator's hold (api.cpp's header comment has the protocol).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sbot_msgs/SensorsAvailable.h>

namespace sbot_api {

using Clock = std::chrono::steady_clock;

/// Report through the controller's error (error = true) or warning handler, else on stderr.
void report(bool error, const char* fmt, ...);

extern std::atomic<bool> g_lockstep;  ///< the simulator runs in lock-step with the controllers

/// How long a getter waits for a message: `normal`, or 30 s in lock-step.
inline std::chrono::seconds waitLimit(int normal) { return std::chrono::seconds(g_lockstep ? 30 : normal); }

/// Lock-step: tell the simulator this controller now waits for a message on `channel` stamped later
/// than `after` (api.cpp). An empty channel: the controller leaves.
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
extern HoldState g_hold;

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
extern Availability g_available;

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

}  // namespace sbot_api
