// random_walk: a Braitenberg-style random walk with wall avoidance for one s-bot.
//
// The robot drives straight, and every few seconds picks a new random curvature; when its ground
// truth says it is close to the arena wall and heading outward, it turns towards the arena centre
// until it points inward again. (It uses ground truth until the IR sensors arrive.)
//
// Subscribes: ground_truth (nav_msgs/Odometry).  Publishes: cmd_speed (sbot_msgs/TrackSpeed).
// In the simulator's lock-step (~lockstep true, docs/ros_api.md "Lock-step") it acts on the first ground truth
// at or after each control tick (k / rate, k = 1, 2, ...) and then tells the simulator it waits for
// the next tick, so the simulator holds until its command has arrived; otherwise a sim-time timer.
// Private parameters (echoed at start):
//   ~arena_size  [m]     side of the square arena centred on the origin (default 4.0)
//   ~margin      [m]     distance from a wall at which avoidance starts (default 0.35)
//   ~speed       [units] cruise speed, 1 unit = 2.8 mm/s (default 50)
//   ~seed        int     seed of this controller's random stream (default: hash of the namespace)
//   ~rate        [Hz]    control rate in sim time (default 10)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <functional>
#include <memory>
#include <random>

#include <nav_msgs/Odometry.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sbot_msgs/TrackSpeed.h>

#include "sbot_controllers/lockstep_client.h"

namespace {

class RandomWalk {
 public:
  RandomWalk(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
    pnh.param("arena_size", arena_size_, 4.0);
    pnh.param("margin", margin_, 0.35);
    pnh.param("speed", speed_, 50);
    int seed = static_cast<int>(std::hash<std::string>()(nh.getNamespace()) & 0x7fffffff);
    pnh.param("seed", seed, seed);
    double rate = 10.0;
    pnh.param("rate", rate, rate);
    if (!(arena_size_ > 0) || !(margin_ >= 0) || !(rate > 0)) {
      ROS_FATAL("random_walk: need arena_size > 0, margin >= 0, rate > 0 (got %g, %g, %g)", arena_size_, margin_, rate);
      ros::shutdown();
      return;
    }
    rng_.seed(seed);
    ROS_INFO("random_walk %s: arena_size=%.2f m margin=%.2f m speed=%d units seed=%d rate=%.1f Hz",
             nh.getNamespace().c_str(), arena_size_, margin_, speed_, seed, rate);
    pub_ = nh.advertise<sbot_msgs::TrackSpeed>("cmd_speed", 1);
    period_ = ros::Duration(1.0 / rate);
    // Lock-step is the simulator's setting: wait for it to be up before reading it.
    if (!ros::service::waitForService("/sim/pause", ros::Duration(30.0)))
      ROS_WARN("random_walk %s: no simulator after 30 s; running free", nh.getNamespace().c_str());
    lockstep_ = std::make_unique<sbot_controllers::LockstepClient>(nh);
    if (lockstep_->enabled()) {
      // Every message in order (ground truth is published at ~publish_rate, faster than the ticks).
      sub_ = nh.subscribe("ground_truth", 100, &RandomWalk::onPose, this, ros::TransportHints().tcpNoDelay());
      sbot_controllers::pollUntil([this] { return sub_.getNumPublishers() > 0 && pub_.getNumSubscribers() > 0; },
                                  std::chrono::steady_clock::now() + std::chrono::seconds(10));
      next_tick_ = ros::Time(0) + period_;
      announceNextTick(/*new_subscription=*/true);
      ROS_INFO("random_walk %s: in lock-step with the simulator", nh.getNamespace().c_str());
    } else {
      sub_ = nh.subscribe("ground_truth", 1, &RandomWalk::onPose, this);
      timer_ = nh.createTimer(period_, &RandomWalk::onTimer, this);
    }
  }

 /// Lock-step: tell the simulator not to hold for this controller any more.
  void stop() {
    if (lockstep_) lockstep_->leaving();
  }

 private:
  void onPose(const nav_msgs::Odometry& odom) {
    x_ = odom.pose.pose.position.x;
    y_ = odom.pose.pose.position.y;
    const auto& q = odom.pose.pose.orientation;
    yaw_ = std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
    have_pose_ = true;
    if (!lockstep_ || !lockstep_->enabled() || odom.header.stamp < next_tick_) return;
    act(odom.header.stamp);
    while (next_tick_ <= odom.header.stamp) next_tick_ += period_;
    announceNextTick();
  }

  /// Lock-step: the simulator may run until it publishes the ground truth of the next tick.
  void announceNextTick(bool new_subscription = false) {
    lockstep_->waitingFor("ground_truth", next_tick_ - ros::Duration(0, 1), sent_, 0, new_subscription);
  }

  void onTimer(const ros::TimerEvent&) {
    if (have_pose_) act(ros::Time::now());  // sim time under /use_sim_time
  }

  /// One control decision at sim time `now`.
  void act(const ros::Time& now) {
    auto publish = [this](const sbot_msgs::TrackSpeed& cmd) {
      pub_.publish(cmd);
      ++sent_;
    };
    const double half = arena_size_ / 2 - margin_;
    sbot_msgs::TrackSpeed cmd;
    if (std::abs(x_) > half || std::abs(y_) > half) {
      // Near a wall: turn on the spot towards the centre while heading outward.
      const double to_centre = std::atan2(-y_, -x_);
      const double err = std::atan2(std::sin(to_centre - yaw_), std::cos(to_centre - yaw_));
      if (std::abs(err) > M_PI / 3) {
        const int turn = err > 0 ? speed_ : -speed_;
        cmd.left = -turn;
        cmd.right = turn;
        publish(cmd);
        return;
      }
    }
    if (now >= next_change_) {
      std::uniform_real_distribution<double> curvature(-0.6, 0.6), hold(1.0, 4.0);
      bias_ = curvature(rng_);
      next_change_ = now + ros::Duration(hold(rng_));
    }
    // Stay within the simulator's +-70 unit limit instead of relying on its clamping.
    auto limited = [](double v) { return static_cast<int16_t>(std::lround(std::max(-70.0, std::min(70.0, v)))); };
    cmd.left = limited(speed_ * (1 - bias_));
    cmd.right = limited(speed_ * (1 + bias_));
    publish(cmd);
  }

  double arena_size_ = 4.0, margin_ = 0.35;
  int speed_ = 50;
  std::mt19937 rng_;
  double x_ = 0, y_ = 0, yaw_ = 0, bias_ = 0;
  bool have_pose_ = false;
  ros::Time next_change_;
  ros::Duration period_;
  ros::Time next_tick_;        ///< lock-step: the next control instant
  std::uint64_t sent_ = 0;     ///< cmd_speed messages published
  std::unique_ptr<sbot_controllers::LockstepClient> lockstep_;
  ros::Publisher pub_;
  ros::Subscriber sub_;
  ros::Timer timer_;
};

volatile std::sig_atomic_t g_stop = 0;

}  // namespace

int main(int argc, char** argv) {
  // Our own SIGINT/SIGTERM handling, so that a lock-step controller can say it leaves before ROS
  // shuts down (otherwise the simulator holds for it until ~lockstep_timeout).
  ros::init(argc, argv, "random_walk", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, [](int) { g_stop = 1; });
  std::signal(SIGTERM, [](int) { g_stop = 1; });
  ros::NodeHandle nh, pnh("~");
  RandomWalk walk(nh, pnh);
  while (ros::ok() && !g_stop) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  walk.stop();
  ros::WallDuration(0.05).sleep();
  ros::shutdown();
  return 0;
}
