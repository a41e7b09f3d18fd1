// A robot at run time: the s-bot API's actuators (tracks, turret) and their motors each step,
// the read-out of its state (poses, velocities, joints, track speeds and torques), teleporting,
// and sleeping at rest. Building it from a description is robot_build.cpp.
#include "sbot_sim/core/robot.h"

#include <algorithm>
#include <cmath>

#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/world.h"
#include "robot_internal.h"

namespace sbot {
namespace {

constexpr int kApiLimit = 127;  // sbot.h: every track/torque value is in [-127,127]

int clampInt(int v, int lo, int hi) { return std::max(lo, std::min(hi, v)); }
int roundToUnits(double v, int limit) {
  if (!std::isfinite(v)) return 0;
  return clampInt(static_cast<int>(std::lround(v)), -limit, limit);
}


// The hinge rate is no test of rest: quickstep leaves it jittering by +-0.07 rad/s at the target.
constexpr double kTurretSettleTime = 0.2;                   // [s] within tolerance before welding
}  // namespace

double Robot::bodyDriveTrackSpeed(int side) const {
  // Chassis velocity in its own frame: forward component and yaw rate.
  dBodyID chassis = baseBody();
  const Quat q = bodyPose(chassis).orientation;
  const Vec3 v = q.inverse() * vec(dBodyGetLinearVel(chassis));
  const Vec3 w = q.inverse() * vec(dBodyGetAngularVel(chassis));
  return v.x() + (side == 0 ? -1 : 1) * 0.5 * track_width_ * w.z();
}

const Robot::Hinge* Robot::hinge(const std::string& joint) const {
  auto it = hinge_index_.find(joint);
  return it == hinge_index_.end() ? nullptr : &hinges_[it->second];
}

double Robot::hingeRate(const Hinge& h) const { return dJointGetHingeAngleRate(h.id); }
double Robot::hingeAngle(const Hinge& h) const { return h.angle; }

// ---- joint access for actuator modules ----------------------------------------------------------

dJointID Robot::hingeJoint(const std::string& joint) const {
  const Hinge* h = hinge(joint);
  if (h) return h->id;
  auto it = loop_index_.find(joint);  // side-arm loop closures built by addLoopJoints()
  return it == loop_index_.end() ? nullptr : it->second;
}

double Robot::jointAngle(const std::string& joint) const {
  if (turret_locked_ && joint == turret_joint_) return locked_angle_;
  const Hinge* h = hinge(joint);
  return h ? hingeAngle(*h) : 0.0;
}

double Robot::jointRate(const std::string& joint) const {
  const Hinge* h = hinge(joint);
  return h ? hingeRate(*h) : 0.0;
}

double Robot::jointEffort(const std::string& joint) const {
  const Hinge* h = hinge(joint);
  return h ? h->effort : 0.0;
}

bool Robot::holdJoint(const std::string& joint, double max_torque) {
  const dJointID h = hingeJoint(joint);
  if (!h) return false;
  dJointSetHingeParam(h, dParamVel, 0);
  dJointSetHingeParam(h, dParamFMax, max_torque);
  return true;
}

dBodyID Robot::linkBody(const std::string& link) const {
  auto it = link_index_.find(link);
  if (it == link_index_.end() || it->second.body < 0) return nullptr;
  return bodies_[it->second.body];
}

// ---- s-bot API ---------------------------------------------------------------------------------

bool Robot::setSpeed(int left, int right) {
  passive_ = false;
  const int limit = description_->treels.speed_limit_units;
  const int l = clampInt(clampInt(left, -kApiLimit, kApiLimit), -limit, limit);
  const int r = clampInt(clampInt(right, -kApiLimit, kApiLimit), -limit, limit);
  req_left_ = l * description_->treels.speed_unit;
  req_right_ = r * description_->treels.speed_unit;
  return l != left || r != right;
}

void Robot::setTrackSpeeds(double left_mps, double right_mps) {
  passive_ = false;
  const double vmax = description_->treels.speed_limit_units * description_->treels.speed_unit;
  auto limit = [vmax](double v) { return std::isfinite(v) ? std::max(-vmax, std::min(vmax, v)) : 0.0; };
  req_left_ = limit(left_mps);
  req_right_ = limit(right_mps);
}

double Robot::trackSpeedLeft() const {
  if (drive_linear_) return bodyDriveTrackSpeed(0);
  double sum = 0;
  for (int i : left_hinges_) sum += hingeRate(hinges_[i]) * description_->wheelRadius(hinges_[i].name);
  return left_hinges_.empty() ? 0 : sum / left_hinges_.size();
}

double Robot::trackSpeedRight() const {
  if (drive_linear_) return bodyDriveTrackSpeed(1);
  double sum = 0;
  for (int i : right_hinges_) sum += hingeRate(hinges_[i]) * description_->wheelRadius(hinges_[i].name);
  return right_hinges_.empty() ? 0 : sum / right_hinges_.size();
}

void Robot::updateCreepSlip(const TrackCommand& cmd) {
  creep_slip_[0] = creep_slip_[1] = 0;
  const TreelsSemantics& tr = description_->treels;
  if (tr.creep_stiffness <= 0 || drive_linear_ || passive_ || drive_contacts_ == 0 || drive_wheel_load_ <= 0) return;
  // ODE lets a contact with force-dependent slip k slide at k x its friction force. The track's
  // contacts share one slip velocity s |v|; with k = |v| n / (C N) for each of the n contacts
  // carrying the load N, their friction forces add up to F = C N s, i.e. s = (F / N) / C however
  // the load is shared among them. |v|: the track's speed, but no more than its motor is asked
  // for, so that held tracks, which quickstep lets jitter, do not creep.
  const double turning[2] = {std::fabs(trackSpeedLeft()), std::fabs(trackSpeedRight())};
  const double motor[2] = {std::fabs(cmd.left), std::fabs(cmd.right)};
  for (int track : {0, 1})
    creep_slip_[track] = std::min(turning[track], motor[track]) * drive_contacts_ / (tr.creep_stiffness * drive_wheel_load_);
}

double Robot::encoderSpeed(int side) const {
  SensorSample sample{kTrackSpeedChannel, side, side == 0 ? trackSpeedLeft() : trackSpeedRight(), "", 0};
  for (const auto& e : world_.effects()) e->onSensor(*this, sample);
  return sample.value;
}

void Robot::getSpeed(int* left, int* right) const {
  const double unit = description_->treels.speed_unit;
  if (left) *left = roundToUnits(encoderSpeed(0) / unit, kApiLimit);
  if (right) *right = roundToUnits(encoderSpeed(1) / unit, kApiLimit);
}

double Robot::trackTorqueLeft() const {
  return torque_history_.empty() ? 0 : torque_sum_[0] / torque_history_.size();
}

double Robot::trackTorqueRight() const {
  return torque_history_.empty() ? 0 : torque_sum_[1] / torque_history_.size();
}

void Robot::getTrackTorque(int* left, int* right) const {
  const double unit = description_->treels.torque_unit;
  if (left) *left = roundToUnits(trackTorqueLeft() / unit, kApiLimit);
  if (right) *right = roundToUnits(trackTorqueRight() / unit, kApiLimit);
}

bool Robot::setTurretRotation(int pos) {
  const int range = description_->turret.range_units;
  const int p = clampInt(pos, -range, range);
  if (p * description_->turret.unit != turret_target_) wake();
  turret_target_ = p * description_->turret.unit;
  return p != pos;
}

double Robot::turretAngle() const {
  if (turret_locked_) return locked_angle_;
  return turret_hinge_ < 0 ? 0 : hingeAngle(hinges_[turret_hinge_]);
}

int Robot::getTurretRotation() const {
  return roundToUnits(turretAngle() / description_->turret.unit, description_->turret.range_units);
}

int Robot::getTurretRotationTorque() const {
  if (turret_hinge_ < 0) return 0;
  return roundToUnits(hinges_[turret_hinge_].effort / description_->turret.torque_unit, kApiLimit);
}

void Robot::updateTurretLock(double dt) {
  if (!welds_turret_) return;  // (switchDescription frees a welded turret the new level does not weld)
  const double tolerance = 0.5 * description_->turret.unit;  // half an API unit (1 deg)
  if (turret_locked_) {
    if (std::abs(turret_target_ - locked_angle_) > tolerance) setTurretLocked(false);
    return;
  }
  if (turret_hinge_ < 0) return;
  const Hinge& h = hinges_[turret_hinge_];
  const bool at_target = std::abs(turret_target_ - hingeAngle(h)) < tolerance;
  turret_settled_for_ = at_target ? turret_settled_for_ + dt : 0.0;
  if (turret_settled_for_ >= kTurretSettleTime) setTurretLocked(true);
}

void Robot::setTurretLocked(bool locked) {
  if (locked == turret_locked_ || turret_joint_.empty()) return;
  turret_settled_for_ = 0;
  if (locked) {
    const double angle = turretAngle();
    std::unique_ptr<RobotDescription> welded = withTurretWelded(*description_, angle);
    rebuild(*welded);  // captures the free turret's angle from its hinge
    welded_model_ = std::move(welded);
    turret_locked_ = true;
    locked_angle_ = angle;
  } else {
    rebuild(*description_);  // captures the welded angle (turret_locked_ still true)
    turret_locked_ = false;
    welded_model_.reset();
  }
}

// ---- state ---------------------------------------------------------------------------------------

dBodyID Robot::baseBody() const { return bodies_.front(); }

Pose Robot::basePose() const { return bodyPose(baseBody()) * base_body_T_base_; }

Pose Robot::linkPose(const std::string& link) const {
  auto it = link_index_.find(link);
  if (it == link_index_.end()) throw UnknownName("robot " + name_ + " has no link '" + link + "'");
  return bodyPose(bodies_[it->second.body]) * it->second.body_T_link;
}

bool Robot::resolve(const LinkRef& link) const {
  if (link.build_ != build_id_) {
    auto it = link_index_.find(link.name_);
    link.build_ = build_id_;
    link.body_ = it == link_index_.end() ? -1 : it->second.body;
    if (it != link_index_.end()) link.body_T_link_ = it->second.body_T_link;
  }
  return link.body_ >= 0;
}

Pose Robot::linkPose(const LinkRef& link) const {
  if (!resolve(link)) throw UnknownName("robot " + name_ + " has no link '" + link.name_ + "'");
  return bodyPose(bodies_[link.body_]) * link.body_T_link_;
}

Vec3 Robot::linearVelocity() const {
  // Velocity of the base_link origin, not of the body's centre of mass.
  dVector3 v;
  const Vec3 p = basePose().position;
  dBodyGetPointVel(baseBody(), p.x(), p.y(), p.z(), v);
  return Vec3(v[0], v[1], v[2]);
}

Vec3 Robot::angularVelocity() const { return vec(dBodyGetAngularVel(baseBody())); }

Vec3 Robot::centreOfMass(double* mass_out) const {
  double m = 0;
  Vec3 com = Vec3::Zero();
  for (dBodyID b : bodies_) {
    dMass mass;
    dBodyGetMass(b, &mass);
    const dReal* p = dBodyGetPosition(b);
    com += mass.mass * Vec3(p[0], p[1], p[2]);
    m += mass.mass;
  }
  if (mass_out) *mass_out = m;
  return com / m;
}

void Robot::addBaseForce(const Vec3& force) { dBodyAddForce(baseBody(), force.x(), force.y(), force.z()); }

std::vector<JointState> Robot::jointStates() const {
  std::vector<JointState> out;
  out.reserve(hinges_.size());
  for (const auto& h : hinges_) out.push_back({h.name, hingeAngle(h), hingeRate(h), h.effort});
  if (turret_locked_) out.push_back({turret_joint_, locked_angle_, 0.0, 0.0});
  return out;
}

void Robot::setBasePose(const Pose& pose) {
  const std::string where = positionProblem(pose.position);
  if (!where.empty()) throw ConfigError("<world>", "robot " + name_, where);
  const Pose old_base_body = bodyPose(baseBody());
  const Pose new_base_body = pose * base_body_T_base_.inverse();
  for (dBodyID b : bodies_) {
    const Pose rel = old_base_body.inverse() * bodyPose(b);
    setBodyPose(b, new_base_body * rel);
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
    dBodyEnable(b);
  }
}

std::vector<Robot::BodyState> Robot::bodyStates() const {
  std::vector<BodyState> out;
  for (dBodyID b : bodies_) out.push_back({bodyPose(b), vec(dBodyGetLinearVel(b)), vec(dBodyGetAngularVel(b))});
  return out;
}

void Robot::setBodyStates(const std::vector<BodyState>& states) {
  for (std::size_t i = 0; i < bodies_.size() && i < states.size(); ++i) {
    setBodyPose(bodies_[i], states[i].pose);
    dBodySetLinearVel(bodies_[i], states[i].linear.x(), states[i].linear.y(), states[i].linear.z());
    dBodySetAngularVel(bodies_[i], states[i].angular.x(), states[i].angular.y(), states[i].angular.z());
    dBodyEnable(bodies_[i]);  // a sleeping robot moved by hand is awake (wakeIfDisturbed)
  }
}

// ---- sleeping at rest ----------------------------------------------------------------------------

void Robot::sleep() {
  for (dBodyID b : bodies_) {
    // At rest: what is left of the velocities is the solver's jitter, not motion.
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
    dBodyDisable(b);
  }
  asleep_ = true;
}

void Robot::wake() {
  wakeByTouch();
  last_command_wake_s_ = world_.time();
}

void Robot::wakeByTouch() {
  for (dBodyID b : bodies_) dBodyEnable(b);
  asleep_ = false;
  rest_watch_.reset();
}

void Robot::updateStanding() {
  standing_ = false;
  if (asleep_ || !commanded_still_ || world_.time() - last_command_wake_s_ < kServoSettle_s) return;
  if (world_.time() - rest_watch_.lastMoveAt() < kMovedRecently_s) return;  // pushed or dragged, not jittering
  constexpr double kTurretAtTarget = 0.02;  // [rad] the servo has settled
  if (turret_hinge_ >= 0 && std::abs(turretAngle() - turret_target_) > kTurretAtTarget) return;
  for (dBodyID b : bodies_) {
    const dReal* v = dBodyGetLinearVel(b);
    if (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > kStandingSpeed * kStandingSpeed) return;
  }
  standing_ = true;
}

void Robot::wakeIfDisturbed() {
  if (!asleep_) return;
  auto nonzero = [](const dReal* v) { return v[0] != 0 || v[1] != 0 || v[2] != 0; };
  for (dBodyID b : bodies_) {
    if (dBodyIsEnabled(b) || nonzero(dBodyGetForce(b)) || nonzero(dBodyGetTorque(b))) {
      wake();
      return;
    }
  }
}

void Robot::updateRest(const RestConfig& config) {
  rest_ready_ = false;
  if (asleep_) {
    if (dBodyIsEnabled(baseBody())) {
      wakeByTouch();  // ODE's island walk enabled it (and all it is jointed to): touched or held by an awake body
    } else {
      // The forces this robot's own command path added while it slept (rolling resistance, the
      // body drive) were not applied; clear them so that only new, external ones wake it.
      for (dBodyID b : bodies_) {
        dBodySetForce(b, 0, 0, 0);
        dBodySetTorque(b, 0, 0, 0);
      }
    }
    return;
  }
  if (!config.enabled || !commanded_still_) {
    rest_watch_.reset();
    return;
  }
  rest_ready_ = rest_watch_.stoodStill(bodies_, world_.time(), config);
  rest_watch_.addLoad(drive_wheel_load_, drive_contact_force_);
}

void Robot::sleepAtRest() {
  drive_wheel_load_ = rest_watch_.meanLoad();
  drive_contact_force_ = rest_watch_.meanForce();
  rest_ready_ = false;
  sleep();
}

// ---- stepping ------------------------------------------------------------------------------------

void Robot::applyCommands(double dt, const std::vector<EffectPtr>& effects) {
  updateTurretLock(dt);
  const TreelsSemantics& tr = description_->treels;
  TrackCommand cmd{req_left_, req_right_, tr.max_torque, tr.max_torque};
  for (const auto& e : effects) e->onCommand(*this, cmd, dt);

  auto drive = [this](const std::vector<int>& side, double speed, double max_torque) {
    // One motor per track drives all its wheels through the rubber band: each wheel turns at the
    // track speed and gets an equal share of the motor's torque.
    const double share = side.empty() ? 0 : std::max(0.0, max_torque) / side.size();
    for (int i : side) {
      const Hinge& h = hinges_[i];
      dJointSetHingeParam(h.id, dParamVel, speed / description_->wheelRadius(h.name));
      dJointSetHingeParam(h.id, dParamFMax, share);
    }
  };
  if (drive_linear_) {
    applyBodyDrive(cmd);
  } else if (passive_) {
    // Motors off: the gears resist rolling with back-drive friction; pulling the robot takes
    // backdrive_force in total, half of it on each track.
    const double holding = 0.5 * tr.backdrive_force * tr.wheel_radius;  // [N m] per track
    drive(left_hinges_, 0.0, holding);
    drive(right_hinges_, 0.0, holding);
  } else {
    drive(left_hinges_, cmd.left, cmd.max_torque_left);
    drive(right_hinges_, cmd.right, cmd.max_torque_right);
  }
  updateCreepSlip(cmd);  // once per step, for every terrain contact of the wheels that collision makes
  applyRollingResistance(cmd);
  // Standing is the command after the effects: a motor-noise effect that moves a "stopped" track
  // keeps the robot awake.
  commanded_still_ = cmd.left == 0 && cmd.right == 0;
  if (asleep_ && !commanded_still_) wake();

  if (turret_hinge_ >= 0) {
    // Position servo (the turret's PIC controller): proportional velocity demand capped at the
    // turret's rotation speed, torque capped at its motor torque.
    const TurretSemantics& ts = description_->turret;
    const Hinge& h = hinges_[turret_hinge_];
    constexpr double kGain = 8.0;  // [1/s]: settles within ~0.5 s, no overshoot at 10 ms steps
    const double err = turret_target_ - hingeAngle(h);
    dJointSetHingeParam(h.id, dParamVel, std::max(-ts.speed, std::min(ts.speed, kGain * err)));
    dJointSetHingeParam(h.id, dParamFMax, ts.max_torque);
  }
}

void Robot::applyRollingResistance(const TrackCommand& cmd) {
  if (cmd.resist_torque_left <= 0 && cmd.resist_torque_right <= 0) return;
  // Opposes the rotation with a smooth sign (tanh): a hard sign would chatter at standstill.
  constexpr double kRollingSpeed = 0.005;  // [m/s] below this the resistance fades out linearly
  const double r = description_->treels.wheel_radius;
  if (drive_linear_) {
    // Body drive (Fast): the two tracks' resistances as one force against the forward speed.
    const Quat q = bodyPose(baseBody()).orientation;
    const Vec3 heading = q * Vec3::UnitX();
    const double v = linearVelocity().dot(heading);
    const double f = (cmd.resist_torque_left + cmd.resist_torque_right) / r * std::tanh(v / kRollingSpeed);
    dBodyAddForce(baseBody(), -f * heading.x(), -f * heading.y(), -f * heading.z());
    return;
  }
  auto resist = [this](const std::vector<int>& side, double torque) {
    if (side.empty() || torque <= 0) return;
    for (int i : side) {
      const Hinge& h = hinges_[i];
      const double rim_speed = hingeRate(h) * description_->wheelRadius(h.name);
      // Between wheel and chassis, like bearing friction: the motor's constraint torque (the
      // torque reading) grows by the same amount.
      dJointAddHingeTorque(h.id, -torque / side.size() * std::tanh(rim_speed / kRollingSpeed));
    }
  };
  resist(left_hinges_, cmd.resist_torque_left);
  resist(right_hinges_, cmd.resist_torque_right);
}

void Robot::applyBodyDrive(const TrackCommand& cmd) {
  // (The wheel hinges stay as built: FMax 0, rolling freely.)
  const TreelsSemantics& tr = description_->treels;
  // Traction: mu(track, ground) times the load that pressed the chassis, casters and wheels onto
  // their support in the last step (driveContactForce along the chassis' up axis): nothing while
  // airborne or lifted by another robot, m g cos(slope) standing on a slope, and a wall or robot
  // pushing from the side adds none. The wheels are passive supports (frictionless, like casters:
  // friction at the wheel contacts would tip the light robot over in every turn); the drive's grip
  // is the track material's.
  const Quat q = bodyPose(baseBody()).orientation;
  const Vec3 up = q * Vec3::UnitZ();
  const double traction =
      world_.config().contact.muFor("track", "ground") * tr.friction_scale * std::max(0.0, driveContactForce().dot(up));
  drive_traction_ = traction;
  double v = 0, yaw_rate = 0, f_max = 0, t_max = 0;
  if (passive_) {
    f_max = std::min(traction, tr.backdrive_force);  // gear back-drive: the pull needed to move it
    t_max = 0.5 * f_max * track_width_;
  } else {
    const double f_left = std::max(0.0, cmd.max_torque_left) / tr.wheel_radius;  // [N] per track
    const double f_right = std::max(0.0, cmd.max_torque_right) / tr.wheel_radius;
    v = 0.5 * (cmd.left + cmd.right);
    yaw_rate = (cmd.right - cmd.left) / track_width_;
    f_max = std::min(traction, f_left + f_right);
    t_max = 0.5 * track_width_ * std::min(traction, std::min(f_left, f_right) * 2);
  }
  // The motors hold the tracks' speed relative to the chassis: while the chassis pitches about the
  // axle at rate w (> 0 nose down), a track on the ground moves it r w faster (a nose dropping into
  // a gap drives the robot on under it, as with a wheel drive; a tail dropping holds it back).
  if (driven_wheel_contacts_ > 0) v += tr.wheel_radius * (q.inverse() * vec(dBodyGetAngularVel(baseBody()))).y();
  dJointSetLMotorParam(drive_linear_, dParamVel, v);
  dJointSetLMotorParam(drive_linear_, dParamFMax, f_max);
  dJointSetLMotorParam(drive_linear_, dParamVel2, 0);  // no side slip below the traction limit
  dJointSetLMotorParam(drive_linear_, dParamFMax2, traction);
  dJointSetAMotorParam(drive_angular_, dParamVel, yaw_rate);
  dJointSetAMotorParam(drive_angular_, dParamFMax, t_max);
  applyDriveReaction(q);
}

void Robot::applyDriveReaction(const Quat& q) {
  // A wheel motor that pushes the robot forward with force F turns the chassis the other way with
  // F times the wheel radius: nose up when driving or pushing forward, nose down when braking. The
  // body drive's force acts at the chassis' centre, on the axle, so this torque is added here, from
  // the drive force of the last step. Only while a driven wheel touches something: a wheel in the
  // air spins free and loads its motor with nothing (so a hard start rears the robot onto its rear
  // caster, which lifts the wheels, and it drops back instead of flipping over). Without it the
  // Fast robot pitched nose-down into every halved gap from 4.5 cm (Table 4.5).
  if (driven_wheel_contacts_ == 0) return;
  const double push = (q.inverse() * vec(drive_linear_fb_->f1)).x();  // [N] along the heading
  const Vec3 axle = q * Vec3::UnitY();
  const double torque = -push * description_->treels.wheel_radius;  // [N m] about +y: > 0 nose down
  dBodyAddTorque(baseBody(), torque * axle.x(), torque * axle.y(), torque * axle.z());
}

void Robot::readFeedback(double dt) {
  for (auto& h : hinges_) {
    const double raw = dJointGetHingeAngle(h.id);
    h.angle += std::remainder(raw - h.raw_angle, 2 * M_PI);
    h.raw_angle = raw;
    // Torque the joint applied to the child body about the joint axis (motor + limit stops). The
    // child's centre of mass lies on or near the axis, so the constraint force adds ~nothing.
    dVector3 a;
    dJointGetHingeAxis(h.id, a);
    h.effort = vec(h.feedback->t1).dot(Vec3(a[0], a[1], a[2]));
  }
  if (drive_linear_) {
    // Motor forces back to per-track axle torques: forward force shared equally, yaw torque as a
    // force couple of the two tracks.
    const Quat q = bodyPose(baseBody()).orientation;
    const double forward = (q.inverse() * vec(drive_linear_fb_->f1)).x();
    const double yaw = (q.inverse() * vec(drive_angular_fb_->t1)).z();
    const double r = description_->treels.wheel_radius;
    drive_torque_[0] = (0.5 * forward - yaw / track_width_) * r;
    drive_torque_[1] = (0.5 * forward + yaw / track_width_) * r;
  }
  auto sum = [this](const std::vector<int>& side) {
    double t = 0;
    for (int i : side) t += hinges_[i].effort;
    return t;
  };
  const std::array<double, 2> now = drive_linear_ ? std::array<double, 2>{drive_torque_[0], drive_torque_[1]}
                                                  : std::array<double, 2>{sum(left_hinges_), sum(right_hinges_)};
  // The window's length in steps; rebuilt (and refilled from this step) if the step or the level changed.
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(description_->treels.torque_window / dt)));
  if (torque_history_.size() != n) {
    torque_history_.assign(n, now);
    torque_sum_ = {now[0] * n, now[1] * n};
    torque_next_ = 0;
    return;
  }
  for (int s = 0; s < 2; ++s) torque_sum_[s] += now[s] - torque_history_[torque_next_][s];
  torque_history_[torque_next_] = now;
  torque_next_ = (torque_next_ + 1) % n;
  if (torque_next_ == 0) {  // once per window: re-add, so rounding cannot accumulate over long runs
    torque_sum_ = {0, 0};
    for (const auto& h : torque_history_) torque_sum_[0] += h[0], torque_sum_[1] += h[1];
  }
}

}  // namespace sbot
