// Drive effects: what lies between the requested track speeds and the motion of the robot.
// Command-path effects transform the TrackCommand (requested speed per track [m/s], torque limit per
// track [N m]) every step; contact-path effects change the ODE surface of the track contacts.
//
// "Slip" effects (speed_scale, track_width, turn_skid) change how the ground moves for a given wheel
// rotation; the wheel encoders then still read the commanded rotation, so these effects also undo
// their own change on the track-speed channel (kTrackSpeedChannel). "Motor" effects (asymmetry,
// latency, dead-band, lag, saturation, sag) change the wheel rotation itself, which the encoders see.
#pragma once

#include <deque>
#include <map>
#include <string>

#include "sbot_sim/core/effects/effect_registry.h"

namespace sbot {

/// Lateral distance between the left and right driven wheels of `robot` [m] (from its links).
double trackWidthOf(const Robot& robot);
/// Maximum track speed of `robot` [m/s] (speed limit units x speed unit).
double maxTrackSpeedOf(const Robot& robot);

/// Ground speed = scale x commanded (effective wheel radius / nominal radius).
class SpeedScaleEffect : public ParametricEffect {
 public:
  explicit SpeedScaleEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void onSensor(const Robot& robot, SensorSample& sample) override;
};

/// Left motor gain (1 + a), right motor gain (1 - a).
class MotorAsymmetryEffect : public ParametricEffect {
 public:
  explicit MotorAsymmetryEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
};

/// Effective track width = ratio x geometric: the differential part of the command turns the body
/// 1/ratio as fast as wheel kinematics predicts (constant turn slip).
class TrackWidthEffect : public ParametricEffect {
 public:
  explicit TrackWidthEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void onSensor(const Robot& robot, SensorSample& sample) override;
  void reset() override { slip_.clear(); }

 private:
  PerRobot<std::pair<double, double>> slip_;  ///< commanded - applied, per track [m/s]
};

/// Skid growing with the turn rate: the differential part is divided by (1 + k |w_cmd|), w_cmd the
/// kinematic turn rate of the command [rad/s].
class TurnSkidEffect : public ParametricEffect {
 public:
  explicit TurnSkidEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void onSensor(const Robot& robot, SensorSample& sample) override;
  void reset() override { slip_.clear(); }

 private:
  PerRobot<std::pair<double, double>> slip_;
};

/// Pure transport delay of the speed command (fractional steps by linear interpolation).
class LatencyEffect : public ParametricEffect {
 public:
  explicit LatencyEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void reset() override { history_.clear(); }

 private:
  PerRobot<std::deque<std::pair<double, double>>> history_;  ///< newest first
};

/// Static friction in the drive: |v| - threshold, and nothing below the threshold.
class DeadBandEffect : public ParametricEffect {
 public:
  explicit DeadBandEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
};

/// First-order lag of the track speed behind the command (time constant tau).
class MotorLagEffect : public ParametricEffect {
 public:
  explicit MotorLagEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void reset() override { state_.clear(); }

 private:
  PerRobot<std::pair<double, double>> state_;
};

/// Acceleration saturation: the speed command is rate limited so that 0 -> max speed takes
/// ramp_time seconds.
class AccelLimitEffect : public ParametricEffect {
 public:
  explicit AccelLimitEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void reset() override { state_.clear(); }

 private:
  PerRobot<std::pair<double, double>> state_;
};

/// Torque saturation: the motors deliver only `scale` x the nominal maximum torque.
class TorqueSaturationEffect : public ParametricEffect {
 public:
  explicit TorqueSaturationEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
};

/// Battery sag: speed and torque fall linearly with the time since the battery was charged: the
/// robot's simulated time, plus an offset for runs recorded later in a session (setElapsed).
class BatterySagEffect : public ParametricEffect {
 public:
  explicit BatterySagEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
  void reset() override { elapsed_.clear(); }
  /// Battery time of `robot` now [s] (e.g. a dataset run's start_time in its session).
  void setElapsed(const std::string& robot, double seconds) { elapsed_(robot) = seconds; }

 private:
  PerRobot<double> elapsed_;
};

/// Rolling resistance of the tracks: a torque of coefficient x wheel radius x normal load per
/// track, opposing the wheels' rotation (TrackCommand::resist_torque_*).
class RollingResistanceEffect : public ParametricEffect {
 public:
  explicit RollingResistanceEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onCommand(const Robot& robot, TrackCommand& cmd, double dt) override;
};

/// Anisotropic track friction: along the track (robot heading) mu, across it lateral_ratio x mu.
/// lateral_ratio 1 is the core's friction exactly (its pyramid is aligned with the heading too).
class TrackFrictionAnisotropyEffect : public ParametricEffect {
 public:
  explicit TrackFrictionAnisotropyEffect(const std::map<std::string, double>& p);
  static EffectInfo describe();
  void onContact(ContactContext& ctx, dSurfaceParameters& surface) override;
};

}  // namespace sbot
