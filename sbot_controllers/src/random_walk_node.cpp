// random_walk: a Braitenberg-style random walk with wall avoidance for one s-bot.
//
// The robot drives straight, and every few seconds picks a new random curvature; when its ground
// truth says it is close to the arena wall and heading outward, it turns towards the arena centre
// until it points inward again. (It uses ground truth until the IR sensors arrive.)
//
// Subscribes: ground_truth (nav_msgs/Odometry).  Publishes: cmd_speed (sbot_msgs/TrackSpeed).
// Private parameters (echoed at start):
//   ~arena_size  [m]     side of the square arena centred on the origin (default 4.0)
//   ~margin      [m]     distance from a wall at which avoidance starts (default 0.35)
//   ~speed       [units] cruise speed, 1 unit = 2.8 mm/s (default 50)
//   ~seed        int     seed of this controller's random stream (default: hash of the namespace)
//   ~rate        [Hz]    control rate in sim time (default 10)
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sbot_msgs/TrackSpeed.h>

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
    sub_ = nh.subscribe("ground_truth", 1, &RandomWalk::onPose, this);
    timer_ = nh.createTimer(ros::Duration(1.0 / rate), &RandomWalk::onTimer, this);
  }

 private:
  void onPose(const nav_msgs::Odometry& odom) {
    x_ = odom.pose.pose.position.x;
    y_ = odom.pose.pose.position.y;
    const auto& q = odom.pose.pose.orientation;
    yaw_ = std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
    have_pose_ = true;
  }

  void onTimer(const ros::TimerEvent&) {
    if (!have_pose_) return;
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
        pub_.publish(cmd);
        return;
      }
    }
    const ros::Time now = ros::Time::now();  // sim time under /use_sim_time
    if (now >= next_change_) {
      std::uniform_real_distribution<double> curvature(-0.6, 0.6), hold(1.0, 4.0);
      bias_ = curvature(rng_);
      next_change_ = now + ros::Duration(hold(rng_));
    }
    // Stay within the simulator's +-70 unit limit instead of relying on its clamping.
    auto limited = [](double v) { return static_cast<int16_t>(std::lround(std::max(-70.0, std::min(70.0, v)))); };
    cmd.left = limited(speed_ * (1 - bias_));
    cmd.right = limited(speed_ * (1 + bias_));
    pub_.publish(cmd);
  }

  double arena_size_ = 4.0, margin_ = 0.35;
  int speed_ = 50;
  std::mt19937 rng_;
  double x_ = 0, y_ = 0, yaw_ = 0, bias_ = 0;
  bool have_pose_ = false;
  ros::Time next_change_;
  ros::Publisher pub_;
  ros::Subscriber sub_;
  ros::Timer timer_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "random_walk");
  ros::NodeHandle nh, pnh("~");
  RandomWalk walk(nh, pnh);
  ros::spin();
  return 0;
}
