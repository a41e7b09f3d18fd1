#include "sbot_sim/core/effects/drive_effects.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "sbot_sim/core/robot.h"

namespace sbot {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Differential decomposition of a track command: mean (forward) and half-difference (turn).
struct Split {
  double mean, half_diff;
};
Split split(const TrackCommand& c) { return {0.5 * (c.left + c.right), 0.5 * (c.right - c.left)}; }
void join(TrackCommand& c, const Split& s) {
  c.left = s.mean - s.half_diff;
  c.right = s.mean + s.half_diff;
}

// Encoders read the commanded wheel rotation plus the tracking error: undo a slip effect's change.
void undoSlip(PerRobot<std::pair<double, double>>& slip, const Robot& robot, SensorSample& s) {
  if (s.channel != kTrackSpeedChannel || !slip.has(robot.name())) return;
  const auto& d = slip(robot.name());
  s.value += s.index == 0 ? d.first : d.second;
}

}  // namespace

double trackWidthOf(const Robot& robot) { return robot.trackWidth(); }

double maxTrackSpeedOf(const Robot& robot) {
  const TreelsSemantics& t = robot.description().treels;
  return t.speed_limit_units * t.speed_unit;
}

// ---- speed_scale ---------------------------------------------------------------------------------

SpeedScaleEffect::SpeedScaleEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo SpeedScaleEffect::describe() {
  return {"speed_scale",
          "Speed scale (effective wheel radius)",
          "command",
          "The ground moves scale x the commanded track speed: the effective rolling radius of the "
          "tracks differs from the nominal 2.2 cm. Encoders still read the commanded rotation.",
          {"pose", "speed"},
          "straight runs at several speeds, timed over a known distance",
          {{"scale", "1", 1.0, 0.7, 1.3, 0.05, "effective / nominal wheel radius"}}};
}

void SpeedScaleEffect::onCommand(const Robot&, TrackCommand& cmd, double) {
  const double s = param("scale");
  cmd.left *= s;
  cmd.right *= s;
}

void SpeedScaleEffect::onSensor(const Robot&, SensorSample& sample) {
  if (sample.channel == kTrackSpeedChannel) sample.value /= param("scale");
}

// ---- motor_asymmetry -----------------------------------------------------------------------------

MotorAsymmetryEffect::MotorAsymmetryEffect(const std::map<std::string, double>& p)
    : ParametricEffect(describe(), p) {}

EffectInfo MotorAsymmetryEffect::describe() {
  return {"motor_asymmetry",
          "Left/right motor asymmetry",
          "command",
          "The left motor runs (1 + a) and the right (1 - a) times the commanded speed: a straight "
          "command curves. The encoders see the difference.",
          {"pose", "speed"},
          "long straight runs in both directions",
          {{"asymmetry", "1", 0.0, -0.3, 0.3, 0.02, "relative gain difference (left - right) / 2"}}};
}

void MotorAsymmetryEffect::onCommand(const Robot&, TrackCommand& cmd, double) {
  const double a = param("asymmetry");
  cmd.left *= 1 + a;
  cmd.right *= 1 - a;
}

// ---- track_width ---------------------------------------------------------------------------------

TrackWidthEffect::TrackWidthEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo TrackWidthEffect::describe() {
  return {"track_width",
          "Effective track width (turn slip)",
          "command",
          "Skid-steered tracks slip sideways when turning: the body turns as if the tracks were "
          "ratio x the geometric 8.2 cm apart. Forward motion is unaffected; the encoders read the "
          "commanded rotation.",
          {"pose"},
          "spins on the spot and arcs (turn angle against wheel travel)",
          {{"ratio", "1", 1.0, 0.6, 2.0, 0.1, "effective / geometric track width"}}};
}

void TrackWidthEffect::onCommand(const Robot& robot, TrackCommand& cmd, double) {
  const TrackCommand before = cmd;
  Split s = split(cmd);
  s.half_diff /= param("ratio");
  join(cmd, s);
  slip_(robot.name()) = {before.left - cmd.left, before.right - cmd.right};
}

void TrackWidthEffect::onSensor(const Robot& robot, SensorSample& sample) { undoSlip(slip_, robot, sample); }

// ---- turn_skid -----------------------------------------------------------------------------------

TurnSkidEffect::TurnSkidEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo TurnSkidEffect::describe() {
  return {"turn_skid",
          "Turn-rate-dependent skid",
          "command",
          "Lateral skid that grows with the turn rate: the body turns at w / (1 + k |w|) for a "
          "kinematic turn rate w of the command. Slow turns are nearly exact, fast spins lose more.",
          {"pose"},
          "spins on the spot at several speeds",
          {{"k", "s/rad", 0.0, 0.0, 2.0, 0.05, "skid per unit turn rate"}}};
}

void TurnSkidEffect::onCommand(const Robot& robot, TrackCommand& cmd, double) {
  const TrackCommand before = cmd;
  Split s = split(cmd);
  const double w = 2 * s.half_diff / trackWidthOf(robot);
  s.half_diff /= 1 + param("k") * std::abs(w);
  join(cmd, s);
  slip_(robot.name()) = {before.left - cmd.left, before.right - cmd.right};
}

void TurnSkidEffect::onSensor(const Robot& robot, SensorSample& sample) { undoSlip(slip_, robot, sample); }

// ---- latency -------------------------------------------------------------------------------------

LatencyEffect::LatencyEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo LatencyEffect::describe() {
  return {"latency",
          "Actuator latency",
          "command",
          "The motors act on the speed command `delay` seconds late (bus and controller latency). "
          "Fractions of a step are interpolated so the effect is smooth in the delay.",
          {"pose", "speed"},
          "speed steps and start/stop runs, encoders logged at >= 10 Hz",
          {{"delay", "s", 0.0, 0.0, 0.5, 0.03, "transport delay of the speed command"}}};
}

void LatencyEffect::onCommand(const Robot& robot, TrackCommand& cmd, double dt) {
  auto& h = history_(robot.name());
  h.emplace_front(cmd.left, cmd.right);
  const double q = std::max(0.0, param("delay")) / dt;
  const std::size_t j0 = static_cast<std::size_t>(std::floor(q));
  const double f = q - j0;
  // Before the run started the robot stood still: missing history reads as zero.
  auto at = [&h](std::size_t j) { return j < h.size() ? h[j] : std::pair<double, double>(0, 0); };
  const auto a = at(j0), b = at(j0 + 1);
  cmd.left = (1 - f) * a.first + f * b.first;
  cmd.right = (1 - f) * a.second + f * b.second;
  while (h.size() > j0 + 2) h.pop_back();
}

// ---- dead_band -----------------------------------------------------------------------------------

DeadBandEffect::DeadBandEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo DeadBandEffect::describe() {
  return {"dead_band",
          "Command dead-band",
          "command",
          "Static friction in gear and motor: a track command below the threshold does not move the "
          "track, above it the track runs threshold slower.",
          {"pose", "speed"},
          "straight runs at low and high speed (an offset, not a ratio)",
          {{"threshold", "m/s", 0.0, 0.0, 0.06, 0.005, "speed lost to static friction"}}};
}

void DeadBandEffect::onCommand(const Robot&, TrackCommand& cmd, double) {
  const double th = param("threshold");
  auto band = [th](double v) { return std::copysign(std::max(0.0, std::abs(v) - th), v); };
  cmd.left = band(cmd.left);
  cmd.right = band(cmd.right);
}

// ---- motor_lag -----------------------------------------------------------------------------------

MotorLagEffect::MotorLagEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo MotorLagEffect::describe() {
  return {"motor_lag",
          "First-order motor lag",
          "command",
          "The track speed follows the command through a first-order lag with time constant tau "
          "(motor inductance, speed controller bandwidth).",
          {"pose", "speed"},
          "speed steps with encoders logged at >= 10 Hz (a lag rounds a step, a delay shifts it)",
          {{"tau", "s", 0.0, 0.0, 1.0, 0.03, "time constant"}}};
}

void MotorLagEffect::onCommand(const Robot& robot, TrackCommand& cmd, double dt) {
  auto& y = state_(robot.name());
  const double tau = param("tau");
  const double alpha = tau > 1e-9 ? 1 - std::exp(-dt / tau) : 1.0;
  y.first += alpha * (cmd.left - y.first);
  y.second += alpha * (cmd.right - y.second);
  cmd.left = y.first;
  cmd.right = y.second;
}

// ---- accel_limit ---------------------------------------------------------------------------------

AccelLimitEffect::AccelLimitEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo AccelLimitEffect::describe() {
  return {"accel_limit",
          "Acceleration saturation",
          "command",
          "The motor controller limits the acceleration of each track: 0 -> maximum speed takes "
          "ramp_time seconds (a linear ramp instead of a step).",
          {"pose", "speed"},
          "large speed steps (0 -> 70 units) with encoders logged",
          {{"ramp_time", "s", 0.0, 0.0, 3.0, 0.05, "time from standstill to maximum speed"}}};
}

void AccelLimitEffect::onCommand(const Robot& robot, TrackCommand& cmd, double dt) {
  auto& y = state_(robot.name());
  const double ramp = param("ramp_time");
  const double step = ramp > 1e-9 ? maxTrackSpeedOf(robot) / ramp * dt : kInf;
  auto limit = [step](double target, double& v) {
    v += std::max(-step, std::min(step, target - v));
    return v;
  };
  cmd.left = limit(cmd.left, y.first);
  cmd.right = limit(cmd.right, y.second);
}

// ---- torque_saturation ---------------------------------------------------------------------------

TorqueSaturationEffect::TorqueSaturationEffect(const std::map<std::string, double>& p)
    : ParametricEffect(describe(), p) {}

EffectInfo TorqueSaturationEffect::describe() {
  return {"torque_saturation",
          "Torque saturation",
          "command",
          "The motors deliver only scale x the nominal maximum track torque (90 units): slower "
          "acceleration, earlier stall, lower torque readings at the limit.",
          {"pose", "speed", "torque"},
          "pushing against a wall or a load, hard accelerations with torque logged",
          {{"scale", "1", 1.0, 0.02, 2.0, 0.1, "available / nominal maximum torque", /*scan_first=*/true}}};
}

void TorqueSaturationEffect::onCommand(const Robot&, TrackCommand& cmd, double) {
  const double s = param("scale");
  cmd.max_torque_left *= s;
  cmd.max_torque_right *= s;
}

// ---- battery_sag ---------------------------------------------------------------------------------

BatterySagEffect::BatterySagEffect(const std::map<std::string, double>& p) : ParametricEffect(describe(), p) {}

EffectInfo BatterySagEffect::describe() {
  return {"battery_sag",
          "Battery sag",
          "command",
          "The battery voltage falls as it discharges: the motors' speed and torque drop by `rate` "
          "(fraction per minute) of their nominal values per minute since the battery was charged "
          "(datasets give each run's start_time in the session).",
          {"pose", "speed"},
          "the same straight run repeated early and late in a long session",
          {{"rate", "1/min", 0.0, 0.0, 0.5, 0.02, "fractional loss of motor speed per minute"}}};
}

void BatterySagEffect::onCommand(const Robot& robot, TrackCommand& cmd, double dt) {
  double& t = elapsed_(robot.name());
  const double f = std::max(0.0, 1 - param("rate") * t / 60.0);
  t += dt;
  cmd.left *= f;
  cmd.right *= f;
  cmd.max_torque_left *= f;
  cmd.max_torque_right *= f;
}

// ---- rolling_resistance --------------------------------------------------------------------------

RollingResistanceEffect::RollingResistanceEffect(const std::map<std::string, double>& p)
    : ParametricEffect(describe(), p) {}

EffectInfo RollingResistanceEffect::describe() {
  return {"rolling_resistance",
          "Rolling resistance",
          "command",
          "Deformation of the rubber tracks resists rolling: a torque of coefficient x wheel radius x "
          "normal load (half the robot's weight per track, times the cosine of its tilt) opposes "
          "each track's rotation. The motors must supply it: higher torque readings, slower "
          "coasting, earlier saturation.",
          {"torque", "speed"},
          "constant-speed runs with track torque logged",
          // scan_first: the load is a smooth function of the coefficient, but the six-wheel
          // robot's response is slightly chaotic; a coarse scan finds the right basin.
          {{"coefficient", "1", 0.0, 0.0, 0.3, 0.02, "rolling resistance coefficient C_rr", /*scan_first=*/true}}};
}

void RollingResistanceEffect::onCommand(const Robot& robot, TrackCommand& cmd, double /*dt*/) {
  const double c = param("coefficient");
  if (c <= 0) return;
  // Why not ODE's contact rolling friction (dContactRolling, the first version): it is a stick-slip
  // torque limit inside the LCP, and with it the simulation's response to the coefficient is
  // chaotic (for a true 0.2 the cost had a narrow dip at exactly 0.2 and a local minimum at 0.012):
  // not identifiable. A smooth torque at the axles is.
  const RobotDescription& d = robot.description();
  const Vec3 up = robot.basePose().orientation * Vec3::UnitZ();
  const double load = 0.5 * d.totalMass() * d.gravity * std::max(0.0, up.z());  // [N] per track
  const double torque = c * d.treels.wheel_radius * load;
  cmd.resist_torque_left += torque;
  cmd.resist_torque_right += torque;
}

// ---- track_friction_anisotropy -------------------------------------------------------------------

TrackFrictionAnisotropyEffect::TrackFrictionAnisotropyEffect(const std::map<std::string, double>& p)
    : ParametricEffect(describe(), p) {}

EffectInfo TrackFrictionAnisotropyEffect::describe() {
  return {"track_friction_anisotropy",
          "Anisotropic track friction",
          "contact",
          "Rubber tracks grip differently along and across the track: friction along the track "
          "direction is mu, across it lateral_ratio x mu. Changes how skid-steered (6-wheel) models "
          "turn and how robots slide sideways when pushed.",
          {"pose"},
          "spins and tight arcs with the medium/detailed model; lateral pushes",
          // scan_first: the error is a smooth function of the ratio, but the six-wheel robot's
          // trajectories (quickstep) are not, sample by sample, so finite differences from 1.0
          // stalled at 0.98 for a true 0.5.
          {{"lateral_ratio", "1", 1.0, 0.1, 3.0, 0.1, "lateral / longitudinal friction coefficient", /*scan_first=*/true}}};
}

void TrackFrictionAnisotropyEffect::onContact(ContactContext& ctx, dSurfaceParameters& surface) {
  const double ratio = param("lateral_ratio");
  const bool track = (ctx.robot_a && ctx.material_a == "track") || (ctx.robot_b && ctx.material_b == "track");
  if (!track || ratio == 1.0 || ctx.heading.squaredNorm() == 0) return;
  // The pyramid's first direction along the track (the core's own on terrain: the way the wheels
  // roll), the second across; robot-robot contacts have none from the core and take the heading.
  if (ctx.fdir1.squaredNorm() == 0) ctx.fdir1 = ctx.heading;
  surface.mode |= dContactMu2;
  surface.mu2 = surface.mu * ratio;
}

}  // namespace sbot
