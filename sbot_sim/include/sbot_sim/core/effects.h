// Pluggable physical effects. An effect is a small object hooked into one or more of three paths:
//   command  — between the API's requested track speeds and the motors (latency, dead-band, lag,
//              rolling resistance, ...)
//   contact  — on every contact the world creates (friction anisotropy, ...)
//   sensor   — on every raw sensor value before quantisation (reflectance, gain, offset, ...)
// The calibration workbench fits effects' parameters; the simulator and scenarios load the same
// effects files, so an accepted effect becomes part of every simulation.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sbot_sim/core/detail/ode_handles.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class Robot;

/// What the motors are asked to do this step, in SI units at the track.
struct TrackCommand {
  double left = 0, right = 0;          ///< requested track surface speed [m/s]
  double max_torque_left = 0, max_torque_right = 0;  ///< [N m] available at the axle
  /// [N m] per track, opposing the wheels' rotation (rolling resistance): the robot applies it at
  /// the wheel axles every step, so the motors must supply it (higher torque readings, earlier
  /// saturation) and a free-rolling robot slows down.
  double resist_torque_left = 0, resist_torque_right = 0;
};

/// One contact about to be created between two geoms. `robot` is null for static geometry.
struct ContactContext {
  const Robot* robot_a = nullptr;
  const Robot* robot_b = nullptr;
  std::string material_a, material_b;
  Vec3 normal = Vec3::UnitZ();          ///< from b to a
  /// Heading of the robot involved (a's if both), projected on the contact plane and normalised;
  /// zero when no robot is involved.
  Vec3 heading = Vec3::Zero();
  /// First friction direction of ODE's friction pyramid: for robot-terrain contacts the way the
  /// robot's wheels roll in the contact plane (axle x normal: the heading on floors and ramps, up
  /// a face the robot is pressed against), so that friction does not depend on the world axes;
  /// zero (ODE's default) for robot-robot ones. Effects may change it and mu / mu2 in the surface;
  /// a non-zero value is copied into the contact with dContactFDir1.
  Vec3 fdir1 = Vec3::Zero();
};

/// One raw sensor value before it is converted to API units.
struct SensorSample {
  std::string channel;   ///< "ir", "ground", "light", ...
  int index = 0;         ///< sensor number within the channel
  double value = 0;      ///< raw physical value (distance [m] for IR, illuminance, ...)
  std::string surface;   ///< surface label hit, when the sensor hit one
  double incidence = 0;  ///< angle between ray and surface normal [rad], when known
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string name() const = 0;
  virtual void onCommand(const Robot& /*robot*/, TrackCommand& /*cmd*/, double /*dt*/) {}
  virtual void onContact(ContactContext& /*ctx*/, dSurfaceParameters& /*surface*/) {}
  virtual void onSensor(const Robot& /*robot*/, SensorSample& /*sample*/) {}
  /// Forget any per-robot state (World::reset).
  virtual void reset() {}
};

using EffectPtr = std::shared_ptr<Effect>;

}  // namespace sbot
