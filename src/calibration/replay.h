// Replaying a dataset run in the simulator (the sbot_core library): commands in (drive runs) or
// placements (place runs), predicted measurements out, at the measurement time stamps.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "calibration/dataset.h"
#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot::calib {

/// What to simulate: a model level and the effects switched on (with their parameter values).
struct ModelSpec {
  std::string level;
  std::vector<EffectConfig> effects;
  std::string describe() const;  ///< "speed_scale(scale=1.04) + latency(delay=0.08)"
};

/// Everything needed to replay runs that is not the model: the dataset and the options.
struct ReplayOptions {
  bool keep_trace = false;   ///< keep the per-step trace (reports), not just predictions
  bool align = true;         ///< fit each drive run's start pose (dx, dy, dyaw) within the tracker noise
  double settle = 0.2;       ///< [s] at rest before t = 0 (robot dropped onto the terrain)
  /// Hidden truth for synthetic data: extra world geometry that the dataset does not describe.
  const WorldConfig* world_override = nullptr;
  /// Hidden truth: the floor tilted by this angle [rad] (gravity tilted instead, which is the same
  /// physics on a flat floor without the contact differences of a tilted box), downhill direction
  /// `tilt_direction` [rad]. Pitch and roll are then measured against the true vertical.
  double tilt = 0, tilt_direction = 0;
};

/// Per-step trace of a drive run (for plots and residual features).
struct Trace {
  std::vector<double> t, x, y, yaw, v, w, accel, speed_left, speed_right, torque_left, torque_right, pitch,
      roll, cmd_left, cmd_right;
  std::vector<char> contact;  ///< robot touching a static obstacle (not the floor)
};

struct RunPrediction {
  /// Predicted value of every measured channel, aligned with run.channels[c].t; NaN = not simulated.
  std::map<std::string, std::vector<double>> values;
  /// Features at every measured sample (same alignment): forward speed v [m/s], turn rate w
  /// [rad/s], acceleration [m/s^2], contact flag, and for sensors distance [m], incidence [rad].
  std::map<std::string, std::map<std::string, std::vector<double>>> features;
  std::map<std::string, std::vector<std::string>> surface;  ///< sensor channels: surface label hit
  Trace trace;
  Pose2D alignment;          ///< start-pose correction found (dx, dy, dyaw)
  std::vector<std::string> notes;  ///< e.g. channels that could not be simulated
};

RunPrediction replayRun(const Dataset& ds, const Run& run, const ModelSpec& model, const ReplayOptions& opt);

/// The world a replay runs in: the dataset's (or opt.world_override), with the model level's
/// recommended step and gravity unless the dataset wrote its own (Dataset::world_sets_*).
WorldConfig replayWorldConfig(const Dataset& ds, const RobotDescription& level, const ReplayOptions& opt);

/// Why a start pose or a placement of the dataset is not a place a `level` robot can be: the robot
/// there would sit deeper than World::kPlacementTolerance inside the ground (a place run's z below
/// the resting height) or an obstacle, naming the run, the row and the pose; "" if every one is.
/// Replayed, such a robot is thrown out by the contacts (drive) or reads the inside of a wall (place).
std::string impossiblePlacement(const Dataset& ds, const std::string& level);

/// True when the core can simulate this channel (sensor modules present for ir/ground/light).
bool canSimulateChannel(const std::string& channel);

/// Lateral distance between the driven wheels of a level [m].
double levelTrackWidth(const std::string& level);

/// The IR proximity sensors of a level: position in base_link [m] and axis direction [rad] each.
std::vector<std::pair<Vec3, double>> levelIrSensors(const std::string& level);

/// Number of run replays since the program started (all threads).
long replayCount();

/// Wrap an angle to (-pi, pi].
double wrapAngle(double a);

}  // namespace sbot::calib
