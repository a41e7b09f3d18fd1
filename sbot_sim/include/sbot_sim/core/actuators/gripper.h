// Front gripper (seed 2.2.3, Table 2.4) behind the standard s-bot API (sbot.h setGripperElevation,
// getGripperElevation, setGripperAperture, getGripperAperture, getGripperElevationTorque,
// getGripperOpticalBarrier), for every model level, as the level's sidecar `gripper.type` says:
//
//   none   (Fast, Simple)  commands are accepted and do nothing physical (seed 2.2.3: these levels
//                          connect through static links declared in the scenario): the getters
//                          return the last commanded values, the torque 0; the optical barrier is
//                          still ray-traced when the level has the gripper / gripper_tip frames.
//   sticky (Basic, Medium) the box on gripper_elevation_joint is driven to the elevation; the
//                          aperture is a state set immediately (no time delay, 2.2.3). A connection
//                          (fixed ODE joint, world.connections()) is created only when a closing
//                          command (aperture 0) is issued while the grip point touches a
//                          `stickable` part of another robot (its turret); aperture > 0 releases.
//   jaws   (Detailed)      the two jaw hinges are driven at jaw_speed (1 rad/s) to aperture/2 each
//                          with jaw_torque (15 N at the grip point), the arm at elevation_speed
//                          (0.87 rad/s) with elevation_torque (0.5 N m). The aperture reading is the
//                          sum of the two jaw angles. A closing command creates the connection only
//                          once the jaws have closed on the other robot's ring (reached the target or
//                          stalled for 0.1 s): the seed's "time delay". Because the jaws alone cannot
//                          hold (2.2.3: the simulated forces are too large for a tight mechanical
//                          grip), the connection is a rigid fixed joint, strong enough to lift an s-bot.
//
// Ranges: elevation [-90, 90] deg; aperture [0, 45] deg (seed 2.2.3 text and Table 2.4; sbot.h says
// [0;40] in its comment for setGripperAperture: we accept up to 45 and report 45 as the maximum);
// out-of-range values are clamped to the nearest end (2.2.3) and the setter returns true.
// Elevation torque: the motor's torque about the hinge in units of elevation_torque / 127 (the
// motor's 0.5 N m maximum = 127), [-127, 127].
// Optical barrier [0, 700], 0 = obstructed, ~700 = empty (sbot.h); ray-traced, sensitivity 1..40 mm
// (Table 2.4): `external` casts a ray from the grip point forward 40 mm: 700 * (d - 1 mm) / 39 mm,
// 0 at or below 1 mm; `internal` casts a ray from the gripper hinge to the grip point (between the
// jaws): 700 * d / length; `combined` is the smaller of the two. The own robot is not seen.
//
// Call update(dt) once after every World::step(). Keeps references to the World and the Robot:
// destroy it before the robot is removed (the World removes the robot's connections itself).
#pragma once

#include <string>

#include "sbot_sim/core/actuators/connections.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;
class Robot;

namespace actuators {

struct BarrierReading {
  unsigned internal = 700, external = 700, combined = 700;
};

/// The optical-barrier value (0..700) of a ray hit at `distance` [m] for sensitivity [lo, hi] [m];
/// no hit (or beyond hi) = 700.
unsigned barrierValue(bool hit, double distance, double lo, double hi);

/// Is a sphere of `radius` at `point` touching a `stickable` geom of a robot other than `self`?
/// Sets `*who` (its name) and `*body` (the touched body) when given.
bool probeStickable(World& world, const Robot& self, const Vec3& point, double radius, std::string* who,
                    dBodyID* body);

/// The position servo every gripper motor runs (front gripper elevation and jaws, side arm): the hinge
/// `joint` of `robot` is driven toward `target` [rad] at 10 rad/s per rad of error, at most `speed`
/// [rad/s], with at most `fmax` [N m]. Does nothing when the robot has no such hinge.
void driveHinge(const Robot& robot, const std::string& joint, double target, double speed, double fmax);

/// Jaws closing on an object stop short of their target: they count as stalled once their fastest
/// joint has turned slower than kRate for kTime (the front gripper's jaws and the side arm's alike).
class JawStall {
 public:
  static constexpr double kRate = 0.05;  ///< [rad/s]
  static constexpr double kTime = 0.1;   ///< [s]
  /// One step of `dt` [s] with the jaws turning at `rate` [rad/s]; true once stalled.
  bool update(double rate, double dt) {
    time_ = rate < kRate ? time_ + dt : 0.0;
    return time_ >= kTime;
  }
  void reset() { time_ = 0; }

 private:
  double time_ = 0;  ///< [s] the jaws have been slower than kRate
};

class FrontGripper {
 public:
  enum class Type { None, Sticky, Jaws };
  static constexpr int kElevationMin = -90, kElevationMax = 90;  ///< [deg]
  static constexpr int kApertureMin = 0, kApertureMax = 45;      ///< [deg]
  static constexpr double kBarrierMin = 0.001, kBarrierMax = 0.040;  ///< [m] Table 2.4

  FrontGripper(World& world, Robot& robot);

  Type type() const { return type_; }
  const char* typeName() const;
  /// True for sticky and jaws (the gripper moves and can connect).
  bool physical() const { return type_ != Type::None; }

  // ---- sbot.h ------------------------------------------------------------------------------------
  /// [deg], clamped to [-90, 90]; returns true if clamped.
  bool setElevation(int degrees);
  /// [deg], clamped to [0, 45]; returns true if clamped. 0 closes (connects if touching), > 0 opens.
  bool setAperture(int degrees);
  int getElevation() const;          ///< [deg]
  int getAperture() const;           ///< [deg]
  int getElevationTorque() const;    ///< [-127, 127]
  BarrierReading getOpticalBarrier() const;

  // ---- simulation side ---------------------------------------------------------------------------
  void update(double dt);
  int commandedElevation() const { return cmd_elevation_; }
  int commandedAperture() const { return cmd_aperture_; }
  /// Whether a connection held by this gripper exists, and the name of the held robot.
  bool gripping() const;
  std::string gripped() const;
  /// Is the grip point touching a `stickable` geom of another robot? Sets `*who` and `*body`.
  bool touchingStickable(std::string* who, dBodyID* body) const;

 private:
  void tryConnect();
  World& world_;
  Robot& robot_;
  Type type_ = Type::None;
  std::string link_ = "gripper", tip_ = "gripper_tip";
  std::string elevation_joint_, jaw_upper_, jaw_lower_;
  double elevation_torque_ = 0.5, elevation_speed_ = 0.87;
  double jaw_speed_ = 1.0, jaw_torque_ = 0.18;
  double elevation_lower_ = -1.5707963, elevation_upper_ = 1.5707963;
  int cmd_elevation_ = 0;
  int cmd_aperture_ = 0;
  bool closing_ = false;       ///< a close command waits for the jaws (jaws) or the next update (sticky)
  JawStall stall_;             ///< jaws not moving while closing
  double close_elapsed_ = 0, close_delay_ = 0;  ///< [s] since the close command; jaw travel time
  /// Jaws: once connected they hold the angles at which they closed on the ring [rad]; servoing on
  /// towards 0 would press them against a ring that the rigid connection holds, and the 5 g jaws
  /// then bounce (the aperture read 2-14 deg while gripping).
  bool jaws_holding_ = false;
  double jaw_hold_upper_ = 0, jaw_hold_lower_ = 0;
};

}  // namespace actuators
}  // namespace sbot
