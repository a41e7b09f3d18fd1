// Flexible side arm (seed 2.2.4, Table 2.5; Detailed level only) behind sbot.h setSideArmPos,
// getSideArmPos, getSideArmTorque, setSideArmOpened, setSideArmClosed, getSideArmOpticalBarrier.
//
// Servo mapping (sbot_description/README.md "Side arm"): with q_e, q_l, q_r the elevation and the
// two root (rotation_left/right) joint angles, s = link_length, n = rhombi, a0 = rest_half_angle:
//   elevation = q_e;  rotation = (q_l + q_r) / 2;  half-opening a = a0 + (q_l - q_r) / 2;
//   depth = 2 n s cos(a)
// and its inverse a = acos(depth / (2 n s)), q_l = rotation + (a - a0), q_r = rotation - (a - a0).
// API units (sbot.h says "To be measured"; our choice, documented):
//   elevation, rotation  [units of `unit` = 0.458 deg, Table 2.5], relative to the rest position
//                        (110 deg from the front gripper axis); ranges +-45 deg (elevation joint
//                        limit) = +-98 units and +-rotation_range (60 deg) = +-131 units;
//   depth                [mm] from the arm pivot to the tip, [21, 118] (half-opening 80..10 deg).
// Torques (getSideArmTorque) in units of the servo's maximum / 127: elevation = q_e torque;
// rotation = mean of the two horizontal servo torques; depth = their difference (seed).
// Jaws: setSideArmOpened drives both jaws to aperture_max (45 deg), setSideArmClosed to 0 at
// jaw_speed (1 rad/s) with jaw_torque. A close that ends (jaws shut or stalled 0.1 s) with the grip
// point between the jaws within 12 mm of a `stickable` part (turret) of another robot creates a weak
// connection (ConnectionManager, kind SideArm: a ball joint) that
// breaks when the force it transmits, low-pass filtered over 0.1 s, exceeds jaw_force x 5 (the 1 N
// grasping force of Table 2.5 with a friction-cone margin: the arm "is not rigid nor strong enough
// to lift or push", 2.2.4). Opening releases.
// Optical barrier: as the front gripper's (gripper.h), from the tip link along the arm axis.
// The scissor loops: URDF is a tree, so the sidecar's `loop_joints` (3 pins) are added here as ODE
// hinges when the module is created (and destroyed with it), unless the robot already has them.
// Levels without a side arm: available() is false, setters return false and do nothing, getters 0.
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/actuators/gripper.h"

namespace sbot {

class World;
class Robot;

namespace actuators {

class SideArm {
 public:
  SideArm(World& world, Robot& robot);
  ~SideArm();
  SideArm(const SideArm&) = delete;
  SideArm& operator=(const SideArm&) = delete;
  bool available() const { return available_; }

  /// Clamp to the ranges above; returns true if any value was clamped. No-op when not available.
  bool setPos(int elevation, int rotation, int depth);
  void getPos(int* elevation, int* rotation, int* depth) const;
  void getTorque(int* elevation, int* rotation, int* depth) const;
  void setOpened();
  void setClosed();
  bool jawsClosedCommanded() const { return closed_cmd_; }
  BarrierReading getOpticalBarrier() const;

  void update(double dt);
  bool gripping() const;
  std::string gripped() const;

  int elevationLimit() const { return elev_limit_units_; }
  int rotationLimit() const { return rot_limit_units_; }
  int depthMin() const { return depth_min_mm_; }
  int depthMax() const { return depth_max_mm_; }
  /// Inverse kinematics [rad]: (elevation, rotation, depth [m]) -> (q_e, q_l, q_r).
  void inverse(double elevation, double rotation, double depth, double* qe, double* ql, double* qr) const;
  /// Forward kinematics [rad, m].
  void forward(double qe, double ql, double qr, double* elevation, double* rotation, double* depth) const;

 private:
  void closeLoops(const YAML::Node& loops);
  std::vector<dJointID> loop_joints_;  ///< the sidecar's loop closures (URDF is a tree), owned here
  World& world_;
  Robot& robot_;
  bool available_ = false;
  std::string j_elev_, j_left_, j_right_, j_jaw_a_, j_jaw_b_, tip_link_;
  double unit_ = 0.0079936081, s_ = 0.02, a0_ = 1.0471976, a_min_ = 0.17453293, a_max_ = 1.3962634;
  int rhombi_ = 3;
  double rotation_range_ = 1.0471976, elev_range_ = 0.78539816;
  double elevation_torque_ = 0.04, horizontal_torque_ = 0.07, servo_speed_ = 0.87;
  double jaw_force_ = 1, jaw_torque_ = 0.006, jaw_speed_ = 1, aperture_max_ = 0.78539816;
  int elev_limit_units_ = 98, rot_limit_units_ = 131, depth_min_mm_ = 21, depth_max_mm_ = 118;
  double t_qe_ = 0, t_ql_ = 0, t_qr_ = 0;  ///< servo targets [rad]
  int cmd_e_ = 0, cmd_r_ = 0, cmd_d_ = 60;
  bool closed_cmd_ = false, closing_ = false;
  JawStall stall_;
  double force_lp_ = 0;
};

}  // namespace actuators
}  // namespace sbot
