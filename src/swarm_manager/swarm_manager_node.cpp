// swarm_manager: dynamic model switching for a running simulation (seed 2.1.3, 4.3). For every robot
// on /swarm/graph it decides the model level from the terrain ahead of it (sbot::swarm::LevelPolicy,
// core/swarm/level_policy.h: Basic on flat ground; Medium for gaps up to small_gap_max, slopes,
// steps and moderate roughness; Detailed for wider gaps, very rough terrain and robots that grip or
// are gripped) and calls /sim/set_model_level when it changes. Demotion waits ~demote_delay
// (hysteresis). The terrain comes from the scenario file the simulator runs (~scenario), loaded with
// the core library: a robot-less sbot::World answers terrainHeight() (memoised on a 5 mm grid).
//
// Parameters (private):
//   ~scenario            path of the simulator's scenario YAML (required)
//   ~rate                [Hz, sim time] decisions per robot, default 5
//   ~detailed_when_gripping  default true: a robot in a connection (graph) gets the detailed level
//   ~lookahead ~lookbehind ~half_width ~sample ~gap_depth ~small_gap_max ~step_medium ~step_detailed
//   ~slope_medium ~slope_detailed ~slope_window ~rough_medium ~rough_detailed ~demote_delay
//   ~flat_level ~medium_level ~detailed_level      LevelPolicyConfig fields, SI units, same defaults
// Services:
//   ~set_override (sbot_msgs/SetModelLevel)  pin robot to level; empty level = automatic again
// Logs every switch with the terrain features that caused it.
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include <ros/ros.h>
#include <sbot_msgs/SetModelLevel.h>
#include <sbot_msgs/SwarmGraph.h>

#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/swarm/level_policy.h"
#include "sbot_sim/core/world.h"
#include "sbot_sim/ros/typed_param.h"

namespace {

class SwarmManager {
 public:
  bool init() {
    ros::NodeHandle pnh("~");
    std::string scenario;
    if (!pnh.getParam("scenario", scenario) || scenario.empty()) {
      ROS_FATAL("swarm_manager: ~scenario (the simulator's scenario YAML) is required");
      return false;
    }
    try {
      // Its terrain only; read whole, as the simulator does (robots and their links checked too).
      const sbot::Scenario s = sbot::loadScenario(scenario);
      terrain_ = std::make_unique<sbot::World>(s.world);
    } catch (const std::exception& e) {
      ROS_FATAL("swarm_manager: %s", e.what());
      return false;
    }
    height_ = std::make_unique<sbot::swarm::HeightCache>(
        [this](double x, double y) { return terrain_->terrainHeight(x, y); });
    sbot::swarm::LevelPolicyConfig c;
    bool ok = true;
    auto param = [&](const char* name, double& v) {
      ok &= sbot_ros_params::readTypedParam(pnh, name, v, "swarm_manager");
      if (ok && v < 0) {
        ROS_FATAL("swarm_manager: ~%s must be >= 0, got %g", name, v);
        ok = false;
      }
    };
    param("lookahead", c.lookahead);
    param("lookbehind", c.lookbehind);
    param("half_width", c.half_width);
    param("sample", c.sample);
    param("gap_depth", c.gap_depth);
    param("small_gap_max", c.small_gap_max);
    param("step_medium", c.step_medium);
    param("step_detailed", c.step_detailed);
    param("slope_medium", c.slope_medium);
    param("slope_detailed", c.slope_detailed);
    param("slope_window", c.slope_window);
    param("rough_medium", c.rough_medium);
    param("rough_detailed", c.rough_detailed);
    param("demote_delay", c.demote_delay);
    ok &= sbot_ros_params::readTypedParam(pnh, "flat_level", c.flat_level, "swarm_manager");
    ok &= sbot_ros_params::readTypedParam(pnh, "medium_level", c.medium_level, "swarm_manager");
    ok &= sbot_ros_params::readTypedParam(pnh, "detailed_level", c.detailed_level, "swarm_manager");
    ok &= sbot_ros_params::readTypedParam(pnh, "rate", rate_, "swarm_manager");
    ok &= sbot_ros_params::readTypedParam(pnh, "detailed_when_gripping", gripping_detailed_, "swarm_manager");
    if (!ok) return false;
    for (const std::string* l : {&c.flat_level, &c.medium_level, &c.detailed_level}) {
      if (!known(*l)) {
        ROS_FATAL("swarm_manager: unknown level '%s' (levels: fast, simple, basic, medium, detailed)", l->c_str());
        return false;
      }
    }
    if (!(c.sample > 0) || !(c.lookahead + c.lookbehind > c.sample)) {
      ROS_FATAL("swarm_manager: ~sample must be > 0 and smaller than ~lookahead + ~lookbehind");
      return false;
    }
    policy_ = std::make_unique<sbot::swarm::LevelPolicy>(c);
    if (!(rate_ > 0)) {
      ROS_FATAL("swarm_manager: ~rate must be > 0 Hz, got %g", rate_);
      return false;
    }
    ROS_INFO("swarm_manager: terrain of %s; levels %s / %s / %s; small gaps <= %.0f mm; look-ahead %.2f m; "
             "demote after %.1f s; %.1f Hz", scenario.c_str(), c.flat_level.c_str(), c.medium_level.c_str(),
             c.detailed_level.c_str(), c.small_gap_max * 1000, c.lookahead, c.demote_delay, rate_);
    set_level_ = nh_.serviceClient<sbot_msgs::SetModelLevel>("/sim/set_model_level", /*persistent=*/false);
    override_srv_ = pnh.advertiseService("set_override", &SwarmManager::onOverride, this);
    graph_sub_ = nh_.subscribe("/swarm/graph", 10, &SwarmManager::onGraph, this);
    return true;
  }

 private:
  static bool known(const std::string& level) {
    for (const auto& l : sbot::modelLevels())
      if (l == level) return true;
    return false;
  }

  void apply(const std::string& robot, const std::string& level, const std::string& why) {
    auto it = current_.find(robot);
    if (it != current_.end() && it->second == level) return;
    sbot_msgs::SetModelLevel srv;
    srv.request.robot = robot;
    srv.request.level = level;
    if (!set_level_.call(srv)) {
      ROS_WARN_THROTTLE(5, "swarm_manager: /sim/set_model_level unavailable");
      return;
    }
    if (!srv.response.success) {
      ROS_WARN("swarm_manager: %s -> %s refused: %s", robot.c_str(), level.c_str(), srv.response.message.c_str());
      current_[robot] = level;  // do not retry every cycle
      return;
    }
    ROS_INFO("swarm_manager: %s %s -> %s (%s)", robot.c_str(), it == current_.end() ? "?" : it->second.c_str(),
             level.c_str(), why.c_str());
    current_[robot] = level;
  }

  void onGraph(const sbot_msgs::SwarmGraph::ConstPtr& g) {
    const double t = g->header.stamp.toSec();
    if (t < last_ + 1.0 / rate_ - 1e-6 && t >= last_) return;
    // A message from another publisher can be malformed: the connection matrix was read past its end.
    if (g->names.size() != g->n || g->positions.size() != g->n || g->connections.size() != std::size_t(g->n) * g->n ||
        (!g->headings.empty() && g->headings.size() != g->n)) {
      ROS_WARN_THROTTLE(5, "swarm_manager: /swarm/graph message ignored: n = %u needs %u names and positions, "
                           "%u connections and 0 or %u headings; it has %zu, %zu, %zu and %zu",
                        g->n, g->n, g->n * g->n, g->n, g->names.size(), g->positions.size(), g->connections.size(),
                        g->headings.size());
      return;
    }
    last_ = t;
    for (std::size_t i = 0; i < g->n; ++i) {
      if (!std::isfinite(g->positions[i].x) || !std::isfinite(g->positions[i].y)) continue;  // no terrain to read there
      bool connected = false;
      for (std::size_t j = 0; j < g->n && gripping_detailed_; ++j)
        connected |= g->connections[i * g->n + j] != 0 || g->connections[j * g->n + i] != 0;
      const sbot::Pose2D pose{g->positions[i].x, g->positions[i].y, i < g->headings.size() ? g->headings[i] : 0.0};
      const std::string level = policy_->decide(g->names[i], t, height_->function(), pose, connected);
      const std::string over = policy_->overrideOf(g->names[i]);
      apply(g->names[i], level,
            !over.empty() ? "manual override"
                          : (connected ? "connected; " : "") + sbot::swarm::describe(policy_->lastFeatures(g->names[i])));
    }
  }

  bool onOverride(sbot_msgs::SetModelLevel::Request& req, sbot_msgs::SetModelLevel::Response& res) {
    if (!req.level.empty() && !known(req.level)) {
      res.success = false;
      res.message = "unknown model level '" + req.level + "' (levels: fast, simple, basic, medium, detailed)";
      return true;
    }
    policy_->setOverride(req.robot, req.level);
    res.success = true;
    res.message = req.level.empty() ? req.robot + ": automatic" : req.robot + ": pinned to " + req.level;
    if (!req.level.empty()) apply(req.robot, req.level, "manual override");
    ROS_INFO("swarm_manager: %s", res.message.c_str());
    return true;
  }

  ros::NodeHandle nh_;
  std::unique_ptr<sbot::World> terrain_;
  std::unique_ptr<sbot::swarm::HeightCache> height_;
  std::unique_ptr<sbot::swarm::LevelPolicy> policy_;
  double rate_ = 5, last_ = -1e9;
  bool gripping_detailed_ = true;
  std::map<std::string, std::string> current_;
  ros::ServiceClient set_level_;
  ros::ServiceServer override_srv_;
  ros::Subscriber graph_sub_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "swarm_manager");
  SwarmManager m;
  if (!m.init()) return 1;
  ros::spin();
  return 0;
}
