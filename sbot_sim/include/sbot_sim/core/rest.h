// Sleeping at rest: a robot that is commanded to stand and has stood still is taken out of the
// solve (its ODE bodies disabled) until something disturbs it.
//
// Why: ODE's iterative solver (quickstep, 20-40 iterations) does not converge on a standing
// robot's contacts and hinges. The residue moves robots that should stand: a Simple commanded
// setSpeed(0, 0) slid 19 mm sideways in 10 s, a Basic 14 mm, a Medium 8 mm and turned (docs/model.md,
// "Sleeping at rest"). Real treels on their 150:1 gears do not move. Game and robot simulators answer
// the same artefact the same way (ODE's own auto-disable, Bullet's deactivation); ours watches
// displacement over a window rather than instantaneous speed, because quickstep's jitter at rest
// (a standing Simple rocks by up to 1.3 deg) is faster than any speed threshold that would not also
// freeze real slow motion. Robots that touch or are joined settle at different times; World keeps
// them from waking each other (docs/model.md, "Sleeping at rest").
#pragma once

#include <limits>
#include <vector>

#include "sbot_sim/core/detail/ode_handles.h"
#include "sbot_sim/core/types.h"
#include "sbot_sim/core/world_config.h"

namespace sbot {

/// Watches one robot's bodies for rest over RestConfig::window_s, and averages its drive-contact
/// loads over the same window (a sleeping robot keeps their mean: one step's quickstep loads
/// scatter by +-25 % on a standing Basic).
class RestWatch {
 public:
  /// The next stoodStill() starts a new window (cheap: called every step a robot moves).
  void reset() { started_ = false; }
  /// Compare the bodies with the window's start (starting one at their current poses if there is
  /// none) and start a new one if any moved beyond the limits. True when they stayed within them
  /// for the whole window.
  bool stoodStill(const std::vector<dBodyID>& bodies, double now_s, const RestConfig& config);
  /// [s] when the bodies last moved beyond the limits (a window restarted by motion; -inf if never).
  /// reset() keeps it: a robot woken by a touch has not moved for that.
  double lastMoveAt() const { return last_move_s_; }
  /// One step's drive-contact load [N] and force [N], added to the current window's means.
  void addLoad(double load, const Vec3& force) {
    ++samples_;
    load_sum_ += load;
    force_sum_ += force;
  }
  double meanLoad() const { return samples_ ? load_sum_ / samples_ : 0.0; }
  Vec3 meanForce() const { return samples_ ? Vec3(force_sum_ / samples_) : Vec3::Zero(); }

 private:
  void start(const std::vector<dBodyID>& bodies, double now_s);
  bool started_ = false;
  double since_s_ = 0;
  double last_move_s_ = -std::numeric_limits<double>::infinity();
  std::vector<Vec3> positions_;
  std::vector<Quat> orientations_;
  std::vector<double> masses_;  ///< [kg] per body
  double total_mass_ = 0;      ///< [kg]
  int samples_ = 0;
  double load_sum_ = 0;         ///< [N]
  Vec3 force_sum_ = Vec3::Zero();  ///< [N]
};

}  // namespace sbot
