// Inclinometer (seed 2.2.9; sbot.h getSlope(int *pitch, int *roll), degrees in [-180, 180]).
//
// "The inclination is defined as the pitch (forward inclination) and roll (lateral inclination) of
// the tracks system": we read the orientation of base_link (the treels), not of the turret.
// Angles are the ZYX (yaw-pitch-roll) Euler angles of base_link in the world (as tf2 getRPY), with
// the s-bot API's signs chosen as (sbot.h gives none):
//   pitch > 0  NOSE UP   (the front, toward the gripper, higher than the back; climbing a ramp
//                         forward reads positive). This is MINUS the REP-103 pitch (rotation about
//                         +y = left, which is nose down).
//   roll  > 0  RIGHT SIDE DOWN (rotation about the forward axis +x by the right-hand rule, i.e. the
//                         REP-103 roll: the left track higher than the right).
// Range: roll in [-180, 180], pitch in [-90, 90] (ZYX convention; a capsized robot shows roll
// near +-180). Rounded to whole degrees like the API's int outputs. No noise (the seed gives none),
// no effects (no physical raw value to modify).
// For sensor_msgs/Imu: orientation() is the base_link quaternion in the world frame (REP-103,
// REP-145: ENU world, body x forward); angularVelocity() is in the base_link frame [rad/s].
#pragma once

#include "sbot_sim/core/types.h"

namespace sbot {

class Robot;

namespace sensors {

/// API pitch and roll [deg, unrounded] of an orientation, signs as documented above.
struct Slope {
  double pitch = 0;  ///< [deg] nose up positive
  double roll = 0;   ///< [deg] right side down positive
};
Slope slopeOf(const Quat& orientation);

class Inclinometer {
 public:
  explicit Inclinometer(const Robot& robot) : robot_(robot) {}
  /// getSlope: pitch and roll [deg] rounded, in [-180, 180].
  void getSlope(int* pitch, int* roll) const;
  Slope slope() const;            ///< unrounded [deg]
  Quat orientation() const;       ///< base_link in the world
  Vec3 angularVelocity() const;   ///< base_link frame [rad/s]

 private:
  const Robot& robot_;
};

}  // namespace sensors
}  // namespace sbot
