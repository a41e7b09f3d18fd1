#include "experiments.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/sensor_suite.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace validation {
namespace {

WorldConfig configFor(const RobotDescription& d, std::uint64_t seed, const Drive& drive = Drive()) {
  WorldConfig c;
  c.step = d.recommended_step;
  c.gravity = d.gravity;
  c.seed = seed;
  if (drive.track_mu > 0) c.contact.material_mu["track"] = drive.track_mu;  // the apparatus' floor
  // The World raises the quickstep iterations to the level's need (RobotDescription::
  // solver_iterations). Medium: 25, where its force-limited treels' row converges. Detailed: 40: at
  // 20 the 22-body model jitters at rest (~0.5 rad/s), sits nose-down and topples off steps it
  // climbs cleanly at 40 and above.
  applyStudyKnobs(c);
  return c;
}

/// Per-trial generator of the start perturbations.
struct Jitter {
  std::mt19937_64 gen;
  Jitter(const std::string& what, double param, int trial)
      : gen(std::hash<std::string>()(what) ^ (static_cast<std::uint64_t>(std::lround(param * 1e6)) * 1000003ULL) ^
            (static_cast<std::uint64_t>(trial) * 0x9E3779B97F4A7C15ULL)) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen); }
};

Vec3 upOf(const Robot& r) { return r.basePose().orientation * Vec3::UnitZ(); }
double angleBetween(const Vec3& a, const Vec3& b) {
  return std::acos(std::max(-1.0, std::min(1.0, a.normalized().dot(b.normalized()))));
}
double headingOf(const Robot& r) {
  const Vec3 f = r.basePose().orientation * Vec3::UnitX();
  return std::atan2(f.y(), f.x());
}
/// How far the robot's heading has turned from `h0` [rad, 0..pi].
double headingChangeSince(const Robot& r, double h0) { return std::fabs(std::remainder(headingOf(r) - h0, 2 * M_PI)); }
/// Tables 4.6 and 4.2.4: a robot whose heading turned more than this has changed course ("c/c").
constexpr double kCourseChange = 0.35;  // [rad], 20 deg

/// Steps between two calls of runFor's check: ~0.05 s (every step for Fast's 0.1 s).
int checkEvery(const World& w) { return std::max(1, static_cast<int>(std::lround(0.05 / w.config().step))); }

bool g_trace = false;  // setTrace

/// One line of the --trace output (every 0.1 s of simulated time): the first robot's base pose and
/// attitude (pitch > 0 nose down, as REP-103), its driven wheels' load, its tracks' speeds (the
/// encoders), the turret's angle and the front gripper tip's height (what decides most of the
/// tables' cells).
void traceLine(World& w) {
  const std::vector<Robot*> robots = w.robots();
  if (robots.empty()) return;
  const Robot& r = *robots.front();
  const Pose b = r.basePose();
  const Vec3 f = b.orientation * Vec3::UnitX();
  const Vec3 l = b.orientation * Vec3::UnitY();
  const double deg = 180 / M_PI;
  std::printf("  t %6.2f s  x %7.4f  y %7.4f  z %7.4f m  pitch %6.1f  roll %6.1f  yaw %6.1f deg  wheel load %7.4f N",
              w.time(), b.position.x(), b.position.y(), b.position.z(), -std::asin(f.z()) * deg, std::asin(l.z()) * deg,
              std::atan2(f.y(), f.x()) * deg, r.driveWheelLoad());
  std::printf("  tracks %6.3f %6.3f m/s  turret %5.1f deg", r.trackSpeedLeft(), r.trackSpeedRight(), r.turretAngle() * deg);
  if (r.description().findLink("gripper_tip")) std::printf("  gripper tip z %7.4f m", r.linkPose("gripper_tip").position.z());
  std::printf("\n");
}

/// Step `w` for `seconds`, calling `check` every checkEvery(w) steps (~0.05 s); stop when it returns true.
template <typename F>
void runFor(World& w, double seconds, F check) {
  const int every = checkEvery(w);
  const int trace_every = std::max(1, static_cast<int>(std::lround(0.1 / w.config().step)));
  const int steps = static_cast<int>(std::ceil(seconds / w.config().step));
  for (int s = 0; s < steps; ++s) {
    w.step();
    if (g_trace && (s + 1) % trace_every == 0) traceLine(w);
    if ((s + 1) % every == 0 && check()) return;
  }
}

/// A box whose top face is a ramp of `angle` (rising along +x for angle > 0, falling for < 0)
/// starting at `foot` (the top face's edge at x = foot.x, height foot.z), `length` along the slope.
BoxObstacle ramp(const Vec3& foot, double angle, double length, const std::string& name) {
  const double t = 0.05;
  BoxObstacle b;
  b.name = name;
  b.size = Vec3(length, 1.0, t);
  b.pitch = -angle;  // pitch about +y turns +x toward -z: a rising ramp has negative pitch
  // Rotation about y by phi = -angle maps the local point (-L/2, 0, t/2) (the top face's start edge).
  const double phi = b.pitch;
  const Vec3 local(-length / 2, 0, t / 2);
  const Vec3 rotated(std::cos(phi) * local.x() + std::sin(phi) * local.z(), 0,
                     -std::sin(phi) * local.x() + std::cos(phi) * local.z());
  b.center = foot - rotated;
  return b;
}

/// Adds a block standing on the floor over [x0, x1], `top` high; none if top <= 0 (a 0 mm step is
/// the floor itself: a block of no height is a degenerate box that stops ODE with an assertion).
void addBlock(std::vector<BoxObstacle>& boxes, double x0, double x1, double top, const std::string& name) {
  if (!(top > 0)) return;
  BoxObstacle b;
  b.name = name;
  b.center = Vec3((x0 + x1) / 2, 0, top / 2);
  b.size = Vec3(x1 - x0, 1.0, top);
  boxes.push_back(b);
}

/// The front gripper's servos (elevation, jaws) are powered on the real robot and hold their
/// position; without the gripper module the core leaves them passive and the gripper would hang on
/// its stop and prop the robot up. Hold every servo joint that is neither a track, the turret nor
/// the side arm (the core holds that) with its own torque at the spawn position (elevation 0).
void holdServos(Robot& r) {
  const RobotDescription& d = r.description();
  for (const auto& j : d.joints) {
    if (j.type == JointDescription::Type::Fixed || j.effort <= 0) continue;
    if (j.name == d.turret.joint || j.name.rfind("side_arm", 0) == 0) continue;
    const auto& L = d.treels.left_joints;
    const auto& R = d.treels.right_joints;
    if (std::find(L.begin(), L.end(), j.name) != L.end() || std::find(R.begin(), R.end(), j.name) != R.end()) continue;
    r.holdJoint(j.name, j.effort);
  }
}

Robot& spawn(World& w, const RobotDescription& d, const Pose2D& p) {
  Robot& r = w.addRobot(d, p, "sbot");
  holdServos(r);
  return r;
}

}  // namespace

void setTrace(bool on) { g_trace = on; }

void applyStudyKnobs(WorldConfig& c) {
  if (const char* e = std::getenv("SBOT_VALIDATE_ITERATIONS")) {
    char* end = nullptr;
    const long n = std::strtol(e, &end, 10);
    if (end == e || *end != '\0' || n < 1 || n > 10000)
      throw ConfigError("$SBOT_VALIDATE_ITERATIONS", "", std::string("expected a whole number in [1, 10000], found '") + e + "'");
    c.solver_iterations = static_cast<int>(n);
    c.level_iterations = false;
  }
  if (const char* e = std::getenv("SBOT_VALIDATE_SOLVER")) {
    c.solver = e;
    if (c.solver != "quickstep" && c.solver != "exact")
      throw ConfigError("$SBOT_VALIDATE_SOLVER", "", "expected 'quickstep' or 'exact', found '" + c.solver + "'");
  }
  // "1" welds, "0" or "" does not (set to 0, the variable does not weld).
  if (const char* e = std::getenv("SBOT_VALIDATE_WELD")) {
    const std::string v = e;
    if (v != "0" && v != "1" && !v.empty())
      throw ConfigError("$SBOT_VALIDATE_WELD", "", "expected 1 (weld idle turrets) or 0, found '" + v + "'");
    c.lock_idle_turret = v == "1";
  }
  // A number from the environment, or a ConfigError naming the variable.
  const auto number = [](const char* name, const char* text, double lo, double hi, const char* range) {
    char* end = nullptr;
    const double v = std::strtod(text, &end);
    if (end == text || *end != '\0' || !(v >= lo && v <= hi))
      throw ConfigError(std::string("$") + name, "", std::string("expected a number in ") + range + ", found '" + text + "'");
    return v;
  };
  // Friction study: the track material's mu on the floor, steps, gaps and ramps (Table 4.1's
  // polystyrene keeps kPolystyreneTrackMu); each level's treels.friction_scale still multiplies it.
  if (const char* e = std::getenv("SBOT_VALIDATE_TRACK_MU"))
    c.contact.material_mu["track"] = number("SBOT_VALIDATE_TRACK_MU", e, 0.0, 100.0, "[0, 100]");
  if (const char* e = std::getenv("SBOT_VALIDATE_SOR")) c.solver_sor = number("SBOT_VALIDATE_SOR", e, 0.1, kMaxSolverSor, "[0.1, 1.99]");
  // Contact softness study: ODE's soft_erp and soft_cfm of every contact.
  if (const char* e = std::getenv("SBOT_VALIDATE_CONTACT_ERP")) c.contact.erp = number("SBOT_VALIDATE_CONTACT_ERP", e, 0.01, 1.0, "[0.01, 1]");
  if (const char* e = std::getenv("SBOT_VALIDATE_CONTACT_CFM")) c.contact.cfm = number("SBOT_VALIDATE_CONTACT_CFM", e, 0.0, 1.0, "[0, 1]");
}

bool studyKnobsOk(const char* tool) {
  try {
    WorldConfig c;
    applyStudyKnobs(c);
    return true;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
    return false;
  }
}

// ---- Table 4.2 / 4.5: gap ------------------------------------------------------------------------

TrialWorld gapWorld(const std::string& level, double gap_m, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  Jitter j("gap" + level, gap_m, trial);
  TrialWorld t{configFor(d, 1000 + trial, drive)};
  const double top = 0.10;
  // The half-size Fast robot crosses the gap halved, as its terrain is halved in 4.2.2 "to retain
  // comparable conditions" (the seed's Fast passing 6 cm, longer than itself, needs it too).
  const double gap = gap_m * s;
  t.world.terrain.type = TerrainConfig::Type::Composite;
  addBlock(t.world.terrain.boxes, -1.0 - gap / 2, -gap / 2, top, "near_side");
  addBlock(t.world.terrain.boxes, gap / 2, 1.0 + gap / 2, top, "far_side");
  const double x0 = -gap / 2 - 0.075 * s + j.uniform(-0.005, 0.005) * s;
  t.start = {x0, j.uniform(-0.01, 0.01) * s, j.uniform(-0.05, 0.05)};
  t.units = drive.units;
  t.seconds = (gap + 0.30 * s) / drive.speed(d) + 4.0;
  return t;
}

namespace {

/// A trial's world built and its robot spawned and standing for t.settle, the drive then set.
struct StartedTrial {
  World world;
  Robot& robot;
  double z0;  ///< [m] the base's height after standing
  StartedTrial(const TrialWorld& t, const RobotDescription& d)
      : world(t.world), robot(spawn(world, d, t.start)) {
    robot.setSpeed(0, 0);
    world.stepN(static_cast<int>(t.settle / t.world.step));
    z0 = robot.basePose().position.z();
    robot.setSpeed(t.units, t.units);
  }
};

}  // namespace

Outcome gapTrial(const std::string& level, double gap_m, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  const double gap = gap_m * s;
  const TrialWorld t = gapWorld(level, gap_m, trial, drive);
  StartedTrial st(t, d);
  World& w = st.world;
  Robot& r = st.robot;
  const double z0 = st.z0;
  Outcome o{"stuck"};
  const double goal = gap / 2 + 0.09 * s;
  runFor(w, t.seconds, [&] {
    const Vec3 p = r.basePose().position;
    const double tilt = angleBetween(upOf(r), Vec3::UnitZ());
    // Not kToppledTilt: a robot wedged nose-first in the gap at 50-70 deg has fallen inside (the
    // seed's Figure 4.1), it has not toppled; toppling here is going over on its back or side.
    if (tilt > 80 * M_PI / 180) { o.label = "topple"; return true; }
    if (p.x() > goal && p.z() > z0 - 0.01 * s && tilt < kUprightTilt) { o.label = "pass"; return true; }
    return false;
  });
  o.value = r.basePose().position.x();
  o.value2 = z0 - r.basePose().position.z();
  // Not across: a base that dropped more than 2 cm (1 cm for the half-size Fast) went into the gap.
  if (o.label == "stuck" && o.value2 > 0.02 * s) o.label = "fall inside";
  return o;
}

// ---- Table 4.3: step ------------------------------------------------------------------------------

TrialWorld stepWorld(const std::string& level, double height_m, bool backward, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  Jitter j(std::string("step") + (backward ? "b" : "f") + level, height_m, trial);
  TrialWorld t{configFor(d, 2000 + trial, drive)};
  t.world.terrain.type = TerrainConfig::Type::Composite;
  addBlock(t.world.terrain.boxes, 0.0, 1.0, height_m * s, "step");  // halved for Fast, as its gaps
  const double x0 = -0.075 * s + j.uniform(-0.005, 0.005) * s;
  const double yaw = (backward ? M_PI : 0.0) + j.uniform(-0.03, 0.03);
  t.start = {x0, j.uniform(-0.01, 0.01) * s, yaw};
  t.units = backward ? -drive.units : drive.units;
  t.seconds = 0.25 * s / drive.speed(d) + 8.0;
  return t;
}

Outcome stepTrial(const std::string& level, double height_m, bool backward, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  const TrialWorld t = stepWorld(level, height_m, backward, trial, drive);
  StartedTrial st(t, d);
  World& w = st.world;
  Robot& r = st.robot;
  const double z0 = st.z0;
  Outcome o{"fail"};
  runFor(w, t.seconds, [&] {
    const Vec3 p = r.basePose().position;
    const double tilt = angleBetween(upOf(r), Vec3::UnitZ());
    // A robot that reverses up a step nose-first onto its held gripper stands at 70-77 deg and can
    // be carried onto the step that way (its base then lies high): toppled, not passed.
    if (tilt > kToppledTilt) { o.label = "topple"; return true; }
    if (p.x() > 0.09 * s && p.z() > z0 + (height_m - 0.006) * s && tilt < kUprightTilt) { o.label = "pass"; return true; }
    return false;
  });
  o.value = r.basePose().position.x();
  o.value2 = r.basePose().position.z() - z0;
  return o;
}

// ---- Table 4.1: slope, hold then climb ------------------------------------------------------------

void onPolystyrene(WorldConfig& c) { c.contact.material_mu["track"] = kPolystyreneTrackMu; }

Outcome slopeHoldClimbTrial(const std::string& level, double angle_rad, bool backward, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  Jitter j(std::string("slope") + (backward ? "b" : "f") + level, angle_rad, trial);
  WorldConfig c = configFor(d, 3000 + trial, drive);
  if (drive.track_mu <= 0) onPolystyrene(c);
  World w(c);
  // A tilted gravity is an infinite slope rising toward +x.
  const double g = c.gravity;
  w.setGravity(Vec3(-g * std::sin(angle_rad), 0, -g * std::cos(angle_rad)));
  const double yaw = (backward ? M_PI : 0.0) + j.uniform(-0.03, 0.03);
  Robot& r = spawn(w, d, {0, 0, yaw});
  r.setSpeed(0, 0);
  Outcome o{"full"};
  double max_tilt = 0;
  bool toppled = false;
  auto watch = [&] {
    const double tilt = angleBetween(upOf(r), Vec3::UnitZ());  // relative to the slope's normal
    max_tilt = std::max(max_tilt, tilt);
    // 45 deg: a robot tipped forward onto its held gripper rests at 56-59 deg off the slope's normal.
    if (tilt > kToppledTilt) { toppled = true; return true; }
    return false;
  };
  const double x_start = r.basePose().position.x();
  runFor(w, 3.0, watch);
  const double x_hold = r.basePose().position.x();
  const double slide = x_start - x_hold;
  const double hold_tilt = max_tilt;
  double progress = 0;
  if (!toppled) {
    const int u = backward ? -drive.units : drive.units;
    r.setSpeed(u, u);
    const double t_climb = 8.0;
    runFor(w, t_climb, watch);
    progress = r.basePose().position.x() - x_hold;
    o.value = progress / (drive.speed(d) * t_climb);
  }
  o.value2 = max_tilt;
  if (toppled) o.label = "topple b/w";
  else if (slide > 0.01 || progress < 0) o.label = "slide";
  else if (o.value < 0.85 || max_tilt - hold_tilt > 8 * M_PI / 180) o.label = "difficult";
  else o.label = "full";
  return o;
}

// ---- Table 4.6: uphill ramp from flat ground -----------------------------------------------------

TrialWorld uphillWorld(const std::string& level, double angle_rad, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  Jitter j("uphill" + level, angle_rad, trial);
  TrialWorld t{configFor(d, 4000 + trial, drive)};
  t.world.terrain.type = TerrainConfig::Type::Composite;
  t.world.terrain.boxes.push_back(ramp(Vec3(0, 0, 0), angle_rad, 0.6 * s, "ramp"));
  const double yaw0 = j.uniform(-0.05, 0.05);
  t.start = {-0.12 * s + j.uniform(-0.01, 0.01) * s, j.uniform(-0.01, 0.01) * s, yaw0};
  t.units = drive.units;
  t.seconds = (0.12 * s + 0.30 * s) / drive.speed(d) * 1.3 + 4.0;
  return t;
}

Outcome uphillTrial(const std::string& level, double angle_rad, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  const TrialWorld t = uphillWorld(level, angle_rad, trial, drive);
  StartedTrial st(t, d);
  World& w = st.world;
  Robot& r = st.robot;
  const double h0 = headingOf(r);
  const double z0 = st.z0;
  const Vec3 normal(-std::sin(angle_rad), 0, std::cos(angle_rad));
  double best = 0;
  Outcome o{"stuck"};
  auto along = [&] {  // progress up the slope [m], 0 before the foot
    const Vec3 p = r.basePose().position;
    return p.x() > 0 ? std::hypot(p.x(), std::max(0.0, p.z() - z0)) : 0.0;
  };
  // Over the last 2 s (for a robot short of the goal): do the tracks still turn (mean encoder
  // speed relative to the command), do the driven wheels carry weight, has the robot moved?
  std::deque<double> track_ratio, load_ratio;
  std::deque<Vec3> positions;
  const double weight = d.totalMass() * t.world.gravity;
  const std::size_t window = static_cast<std::size_t>(std::lround(2.0 / (checkEvery(w) * t.world.step)));  // 2 s
  runFor(w, t.seconds, [&] {
    track_ratio.push_back(0.5 * (std::fabs(r.trackSpeedLeft()) + std::fabs(r.trackSpeedRight())) / drive.speed(d));
    load_ratio.push_back(r.driveWheelLoad() / weight);
    positions.push_back(r.basePose().position);
    if (track_ratio.size() > window) { track_ratio.pop_front(); load_ratio.pop_front(); positions.pop_front(); }
    // Toppled (over backwards): over, or tilted more than 75 deg off the normal of the surface
    // under its base, ramp or floor (a robot on the ramp leans back at most its own tipping angle;
    // one with its rear on the floor at the foot and its front up the face stands at 56-62 deg).
    // Counted only from 100 deg off vertical, a Medium that rears onto its tail at the foot of the
    // 1.0 rad ramp (86 deg) and falls on its side would be "slide back"
    // (gtest ValidationLabels.ARobotThatRearsOverAtTheRampsFootHasToppled).
    const Vec3 up = upOf(r);
    const Vec3 under = r.basePose().position.x() > 0 ? normal : Vec3(Vec3::UnitZ());
    if (angleBetween(up, Vec3::UnitZ()) > 100 * M_PI / 180 || angleBetween(up, under) > 75 * M_PI / 180) {
      o.label = "topple";
      return true;
    }
    best = std::max(best, along());
    if (along() > 0.25 * s) { o.label = "climb"; return true; }
    return false;
  });
  const double dh = headingChangeSince(r, h0);
  o.value = best;
  o.value2 = dh;
  if (o.label == "stuck") {
    double turning = 0, load = 0;
    for (double t : track_ratio) turning += t / track_ratio.size();
    for (double t : load_ratio) load += t / load_ratio.size();
    const double travel = (positions.back() - positions.front()).norm();
    // Over the last 2 s: "travelling" = at least a quarter of the commanded distance; "slipping"
    // needs tracks that turn (encoders >= 50 % of the command) while the driven wheels carry at
    // least a quarter of the weight. Tracks spinning free (the robot hung up on its chassis or
    // casters) do not slip: that robot is stuck.
    const bool travelling = travel >= 0.25 * drive.speed(d) * 2.0;
    if (best > 0.03 * s && along() < best - 0.03 * s) o.label = "slide back";
    else if (best <= 0.05 * s && dh > kCourseChange && travelling) o.label = "c/c";
    else if (turning >= 0.5 && load >= 0.25) o.label = "slipping";
  }
  return o;
}

namespace {
/// 4.2.4's ramp: this long along its slope [m], for a robot of length scale `s`.
double downhillRampLength(double s) { return 0.4 * s; }
}  // namespace

TrialWorld downhillWorld(const std::string& level, double angle_rad, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  Jitter j("downhill" + level, angle_rad, trial);
  TrialWorld t{configFor(d, 5000 + trial, drive)};
  t.world.terrain.type = TerrainConfig::Type::Composite;
  const double L = downhillRampLength(s);
  const double H = L * std::sin(angle_rad);
  addBlock(t.world.terrain.boxes, -1.0, 0.0, H, "plateau");
  t.world.terrain.boxes.push_back(ramp(Vec3(0, 0, H), -angle_rad, L + 0.05, "ramp"));
  t.start = {-0.10 * s + j.uniform(-0.01, 0.01) * s, j.uniform(-0.01, 0.01) * s, j.uniform(-0.05, 0.05)};
  t.units = drive.units;
  t.seconds = (0.10 * s + L + 0.1 * s) / drive.speed(d) * 1.3 + 4.0;
  return t;
}

Outcome downhillTrial(const std::string& level, double angle_rad, int trial, const Drive& drive) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  const double L = downhillRampLength(s);
  const TrialWorld t = downhillWorld(level, angle_rad, trial, drive);
  StartedTrial st(t, d);
  World& w = st.world;
  Robot& r = st.robot;
  const double h0 = headingOf(r);
  Outcome o{"stuck"};
  const double foot = L * std::cos(angle_rad), goal = foot + 0.10 * s;
  const Vec3 ramp_normal(std::sin(angle_rad), 0, std::cos(angle_rad));  // the ramp falls toward +x
  runFor(w, t.seconds, [&] {
    // Toppled forward: over, or tilted more than 45 deg off the normal of the surface under its
    // base (plateau, ramp, floor), i.e. pitched onto its nose or gripper (Table 4.3's rule). With
    // only "over" (100 deg), a Detailed robot that pitches 84 deg onto its gripper at 0.5 rad,
    // slides down on it and falls back would be a "pass".
    const double x = r.basePose().position.x();
    const Vec3 up = upOf(r);
    const double tilt = angleBetween(up, Vec3::UnitZ());
    const Vec3 normal = x > 0 && x < foot ? ramp_normal : Vec3(Vec3::UnitZ());
    if (tilt > 100 * M_PI / 180 || angleBetween(up, normal) > 45 * M_PI / 180) {
      o.label = "topple";
      return true;
    }
    if (x > goal && tilt < 0.3) { o.label = "pass"; return true; }
    return false;
  });
  o.value = r.basePose().position.x();
  o.value2 = headingChangeSince(r, h0);
  // Short of the goal, upright, but turned off its course (e.g. slewed across the ramp at the
  // plateau's edge and driving along it): that robot changed course; it is not stuck.
  if (o.label == "stuck" && o.value2 > kCourseChange) o.label = "c/c";
  return o;
}

// ---- Figure 4.4: rough terrain ------------------------------------------------------------------

Outcome roughTrial(const std::string& level, double hr_cm, int trial, const std::string& heightmap_png) {
  const RobotDescription& d = loadLevel(level);
  const double s = lengthScale(level);
  Jitter j("rough" + level, hr_cm, trial);
  WorldConfig c = configFor(d, 6000 + trial);
  c.terrain.type = TerrainConfig::Type::Rough;
  c.terrain.heightmap_image = heightmap_png;
  c.terrain.heightmap_seed = 7;
  c.terrain.size_x = c.terrain.size_y = 5.0 * s;  // 4.2.2: the Fast model's terrain is halved
  // HR in cm: the seed's simulator worked in CGS units (Tables 2.2-2.13: cm, dyne, dyne cm), and
  // its labels (HR 1 "almost flat" ... 32 "very rough") fit centimetres: on the default image HR 32 cm
  // has slopes of 10 deg on average and up to 40, HR 32 mm nothing over 5 deg (read in mm, every
  // level would keep its course at every HR).
  c.terrain.height_range = hr_cm / 100.0 * s;
  World w(c);
  // A random heading, then a random start from which the whole ideal path (1.52 m, the same for the
  // half-size Fast on its halved terrain) stays 15 cm inside the height field: there is no ground
  // beyond its edge (from starts drawn over +-1.5 m some runs would drive off it).
  constexpr double kPath = 0.1524 * 10.0, kEdgeMargin = 0.15;  // [m]
  const double yaw = j.uniform(-M_PI, M_PI);
  const double inner = 0.5 * c.terrain.size_x - kEdgeMargin;
  auto start = [&](double along) {  // along: the path's extent on this axis [m]
    return j.uniform(-inner - std::min(0.0, along), inner - std::max(0.0, along));
  };
  const double x0 = start(kPath * std::cos(yaw)), y0 = start(kPath * std::sin(yaw));
  Robot& r = spawn(w, d, {x0, y0, yaw});
  r.setSpeed(0, 0);
  w.stepN(static_cast<int>(1.0 / c.step));
  const Vec3 p0 = r.basePose().position;
  const double h0 = headingOf(r);
  r.setTrackSpeeds(0.1524, 0.1524);  // 4.2.2: "medium speed (15.24 cm/s)"
  runFor(w, 10.0, [] { return false; });
  const Vec3 p1 = r.basePose().position;
  Outcome o{"ok"};
  o.value = (p1 - p0).dot(Vec3(std::cos(h0), std::sin(h0), 0));
  o.value2 = headingChangeSince(r, h0);
  return o;
}

// ---- Table 4.4: efficiency ------------------------------------------------------------------------

namespace {

volatile unsigned g_sensor_sink = 0;

/// Table 4.4's workload: one s-bot of `level` on flat ground, a new random setSpeed every simulated
/// second, and (with_sensors) the proximity ring, ground and light sensors read every step, as the
/// seed's controllers do. Returns the wall time [s]; `sensor_s` (optional) gets the sensors' share.
double randomWalk(World& w, Robot& r, double sim_seconds, bool with_sensors, double* sensor_s = nullptr) {
  using Clock = std::chrono::steady_clock;
  sensors::Environment env(w);
  sensors::SensorSuite suite(w, r, env);
  const bool ground = suite.available(sensors::SensorChannel::Ground);
  const bool light = suite.available(sensors::SensorChannel::Light);
  const double dt = w.config().step;
  const int steps = static_cast<int>(sim_seconds / dt);
  const int change_every = std::max(1, static_cast<int>(1.0 / dt));
  unsigned sink = 0;
  double sensing = 0;
  const auto t0 = Clock::now();
  for (int i = 0; i < steps; ++i) {
    if (i % change_every == 0) {
      r.setSpeed(static_cast<int>(r.random().uniform("walk", -70, 70)),
                 static_cast<int>(r.random().uniform("walk", -70, 70)));
    }
    w.step();
    if (!with_sensors) continue;
    const auto s0 = sensor_s ? Clock::now() : Clock::time_point();
    suite.update(dt);
    for (unsigned v : suite.getAllProximitySensors()) sink += v;
    if (ground) for (unsigned v : suite.getAllGroundSensors()) sink += v;
    if (light) for (unsigned v : suite.getAllLightSensors()) sink += v;
    if (sensor_s) sensing += std::chrono::duration<double>(Clock::now() - s0).count();
  }
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  if (sensor_s) *sensor_s = sensing;
  g_sensor_sink = sink;  // keeps the reads from being optimised away
  return wall;
}

}  // namespace

Outcome rtmTrial(const std::string& level, double sim_seconds, bool with_sensors) {
  const RobotDescription& d = loadLevel(level);
  World w(configFor(d, 7));
  Robot& r = spawn(w, d, {0, 0, 0});
  const double wall = randomWalk(w, r, sim_seconds, with_sensors);
  Outcome o{"ok"};
  o.value = w.time() / wall;
  o.value2 = 1000.0 * wall / static_cast<double>(w.stepCount());
  return o;
}

StepCost profileTrial(const std::string& level, double sim_seconds) {
  const RobotDescription& d = loadLevel(level);
  World w(configFor(d, 7));
  Robot& r = spawn(w, d, {0, 0, 0});
  w.stepN(static_cast<int>(0.5 / w.config().step));  // settle; not profiled
  w.enableProfile(true);
  const double t_sim0 = w.time();
  double sensing = 0;
  const double wall = randomWalk(w, r, sim_seconds, true, &sensing);
  const World::StepProfile& p = w.profile();
  StepCost c;
  c.rtm = (w.time() - t_sim0) / wall;
  c.wall_us_per_step = 1e6 * wall / static_cast<double>(p.steps);
  c.commands = p.commands_s / wall;
  c.collision = p.collision_s / wall;
  c.solver = p.solver_s / wall;
  c.feedback = p.feedback_s / wall;
  c.sensors = sensing / wall;
  c.contacts_per_step = static_cast<double>(p.contacts) / static_cast<double>(p.steps);
  c.bodies = static_cast<int>(r.bodyCount());
  c.iterations = w.solverIterations();
  c.step_s = w.config().step;
  return c;
}

Outcome steadySpeedTrial(const std::string& level, int units) {
  const RobotDescription& d = loadLevel(level);
  WorldConfig c = configFor(d, 8);
  World w(c);
  Robot& r = spawn(w, d, {0, 0, 0});
  r.setSpeed(units, units);
  runFor(w, 3.0, [] { return false; });
  const Vec3 a = r.basePose().position;
  runFor(w, 3.0, [] { return false; });
  const Vec3 b = r.basePose().position;
  Outcome o{"ok"};
  o.value = (b - a).head<2>().norm() / 3.0;
  return o;
}

Outcome spinRateTrial(const std::string& level, int units) {
  const RobotDescription& d = loadLevel(level);
  World w(configFor(d, 8));
  Robot& r = spawn(w, d, {0, 0, 0});
  r.setSpeed(units, -units);
  runFor(w, 1.0, [] { return false; });  // past the acceleration phase
  constexpr double kSpan = 3.0;           // [s] measured
  double turned = 0, last = headingOf(r);
  const int n = static_cast<int>(std::lround(kSpan / w.config().step));
  for (int i = 0; i < n; ++i) {
    w.step();
    turned += std::remainder(headingOf(r) - last, 2 * M_PI);
    last = headingOf(r);
  }
  Outcome o{"ok"};
  o.value = -turned / kSpan;  // left forward, right back: clockwise, negative yaw
  o.value2 = 2 * units * d.treels.speed_unit / r.trackWidth();
  return o;
}

Outcome connectedPairTrial(const std::string& level) {
  const RobotDescription& d = loadLevel(level);
  WorldConfig c = configFor(d, 9);
  World w(c);
  Robot& holder = w.addRobot(d, {0, 0, 0}, "holder");
  Robot& held = w.addRobot(d, {0.3 * lengthScale(level), 0, 0}, "held");
  holdServos(holder);
  holdServos(held);
  swarm::createStaticLink(w, {"holder", "held", swarm::kFrontGripper});
  auto distance = [&] { return (held.basePose().position - holder.basePose().position).head<2>().norm(); };
  runFor(w, 1.0, [] { return false; });
  Outcome o{"ok"};
  o.value = distance();
  holder.setSpeed(-30, -30);
  held.setSpeed(-30, -30);
  runFor(w, 2.0, [] { return false; });
  o.value2 = distance();
  return o;
}

// ---- the catalogue of trial kinds ----------------------------------------------------------------

namespace {
std::string g_rough_heightmap;  // setRoughHeightmap
}  // namespace

void setRoughHeightmap(const std::string& png) { g_rough_heightmap = png; }

const std::vector<ExperimentKind>& experimentKinds() {
  static const std::vector<ExperimentKind> kinds = {
      {"gap", "gap width, m", 0.0, 0.3, {"pass", "fall inside", "stuck", "topple"}, {"base x at the end (gap centre at 0)", "m"},
       {"base drop", "m"},
       [](const std::string& l, double p, int i, const Drive& d) { return gapTrial(l, p, i, d); },
       [](const std::string& l, double p, int i, const Drive& d) { return gapWorld(l, p, i, d); }},
      {"step", "step height, m", 0.0, 0.1, {"pass", "fail", "topple"}, {"base x at the end (step edge at 0)", "m"},
       {"base rise", "m"},
       [](const std::string& l, double p, int i, const Drive& d) { return stepTrial(l, p, false, i, d); },
       [](const std::string& l, double p, int i, const Drive& d) { return stepWorld(l, p, false, i, d); }},
      {"stepb", "step height, m", 0.0, 0.1, {"pass", "fail", "topple"}, {"base x at the end (step edge at 0)", "m"},
       {"base rise", "m"},
       [](const std::string& l, double p, int i, const Drive& d) { return stepTrial(l, p, true, i, d); },
       [](const std::string& l, double p, int i, const Drive& d) { return stepWorld(l, p, true, i, d); }},
      {"slope", "slope, deg", 0.0, 89.0, {"full", "difficult", "slide", "topple b/w"}, {"climb efficiency", ""}, {"max tilt", "rad"},
       [](const std::string& l, double p, int i, const Drive& d) { return slopeHoldClimbTrial(l, p * M_PI / 180, false, i, d); }},
      {"slopeb", "slope, deg", 0.0, 89.0, {"full", "difficult", "slide", "topple b/w"}, {"climb efficiency", ""}, {"max tilt", "rad"},
       [](const std::string& l, double p, int i, const Drive& d) { return slopeHoldClimbTrial(l, p * M_PI / 180, true, i, d); }},
      {"uphill", "ramp angle, rad", 0.0, 1.5, {"climb", "c/c", "stuck", "slipping", "slide back", "topple"},
       {"furthest up the ramp", "m"}, {"heading change", "rad"},
       [](const std::string& l, double p, int i, const Drive& d) { return uphillTrial(l, p, i, d); },
       [](const std::string& l, double p, int i, const Drive& d) { return uphillWorld(l, p, i, d); }},
      {"downhill", "ramp angle, rad", 0.0, 1.5, {"pass", "topple", "c/c", "stuck"}, {"base x at the end (plateau edge at 0)", "m"},
       {"heading change", "rad"},
       [](const std::string& l, double p, int i, const Drive& d) { return downhillTrial(l, p, i, d); },
       [](const std::string& l, double p, int i, const Drive& d) { return downhillWorld(l, p, i, d); }},
      {"rough", "height range HR, cm", 0.0, 100.0, {}, {"distance along the start heading", "m"}, {"heading change", "rad"},
       [](const std::string& l, double p, int i, const Drive&) { return roughTrial(l, p, i, g_rough_heightmap); }},
      {"rtm", "simulated time, s", 0.1, 3600.0, {}, {"real-time multiplier", ""}, {"wall time per step", "ms"}, [](const std::string& l, double p, int, const Drive&) { return rtmTrial(l, p); }},
      {"speed", "setSpeed units", -70.0, 70.0, {}, {"steady speed", "m/s"}, {},
       [](const std::string& l, double p, int, const Drive&) { return steadySpeedTrial(l, static_cast<int>(std::lround(p))); }},
      {"spin", "setSpeed units (left forward, right back)", -70.0, 70.0, {}, {"spin rate", "rad/s"}, {"2 v / trackWidth", "rad/s"},
       [](const std::string& l, double p, int, const Drive&) { return spinRateTrial(l, static_cast<int>(std::lround(p))); }},
  };
  return kinds;
}

const ExperimentKind* findExperimentKind(const std::string& name) {
  for (const ExperimentKind& k : experimentKinds())
    if (name == k.name) return &k;
  return nullptr;
}

std::string experimentKindNames(bool labelled) {
  std::string names;
  for (const ExperimentKind& k : experimentKinds())
    if (!labelled || !k.labels.empty()) names += (names.empty() ? "" : ", ") + k.name;
  return names;
}

double Drive::speed(const RobotDescription& d) const { return units * d.treels.speed_unit; }

double lengthScale(const std::string& level) { return level == "fast" ? 0.5 : 1.0; }

// ---- infrastructure -------------------------------------------------------------------------------

namespace {

// The workers of the round in progress and their result files, for the interrupt handler: a
// Ctrl-C or SIGTERM of sbot_validate must not leave workers running on, re-parented to init, nor
// result files in /tmp. Plain arrays: a signal handler may only touch what is async-signal-safe.
constexpr int kMaxWorkers = 256;
volatile sig_atomic_t g_worker_count = 0;
pid_t g_worker_pids[kMaxWorkers];
char g_worker_files[kMaxWorkers][32];

void stopWorkersAndExit(int sig) {
  for (int k = 0; k < g_worker_count; ++k) {
    if (g_worker_pids[k] > 0) kill(g_worker_pids[k], SIGKILL);
    unlink(g_worker_files[k]);
  }
  _exit(128 + sig);
}

/// One round: `jobs` spread over up to `processes` workers (worker k takes jobs k, k + P, ...).
/// Fills `out` with what the workers reported; returns the jobs a crashed worker did not report,
/// in the order it would have run them, one list per crashed worker.
std::vector<std::vector<int>> runRound(const std::vector<int>& jobs, int processes, const std::function<Outcome(int)>& fn,
                                       std::vector<Outcome>& out, std::vector<bool>& reported) {
  const int n = static_cast<int>(jobs.size());
  processes = std::max(1, std::min({processes, n, kMaxWorkers}));
  std::vector<std::string> files;
  std::vector<pid_t> pids;
  std::vector<int> slice;  // the worker index k of each started worker
  std::fflush(stdout);
  std::fflush(stderr);
  struct sigaction stop {}, old_int {}, old_term {};
  stop.sa_handler = stopWorkersAndExit;
  sigemptyset(&stop.sa_mask);
  sigaction(SIGINT, &stop, &old_int);
  sigaction(SIGTERM, &stop, &old_term);
  g_worker_count = 0;
  for (int k = 0; k < processes; ++k) {
    char tmpl[] = "/tmp/sbot_validate_XXXXXX";
    const int fd = mkstemp(tmpl);
    if (fd < 0) {  // its trials stay "error" in the report; say why
      std::fprintf(stderr, "sbot_validate: worker %d of %d not started: cannot create a result file in /tmp: %s\n", k + 1,
                   processes, std::strerror(errno));
      continue;
    }
    close(fd);
    const pid_t pid = fork();
    if (pid < 0) {
      std::fprintf(stderr, "sbot_validate: worker %d of %d not started: fork: %s\n", k + 1, processes, std::strerror(errno));
      std::remove(tmpl);
      continue;
    }
    if (pid == 0) {
      signal(SIGINT, SIG_DFL);
      signal(SIGTERM, SIG_DFL);
      std::ofstream f(tmpl);
      for (int i = k; i < n; i += processes) {
        const int job = jobs[i];
        Outcome o{"error"};
        try {
          o = fn(job);
        } catch (const std::exception& e) {
          std::fprintf(stderr, "sbot_validate: job %d: %s\n", job, e.what());
        }
        std::string label = o.label;
        std::replace(label.begin(), label.end(), '\t', ' ');
        f << job << '\t' << label << '\t' << o.value << '\t' << o.value2 << '\n';
        f.flush();
      }
      f.close();
      std::_Exit(0);
    }
    std::snprintf(g_worker_files[g_worker_count], sizeof(g_worker_files[0]), "%s", tmpl);
    g_worker_pids[g_worker_count] = pid;
    g_worker_count = g_worker_count + 1;
    files.push_back(tmpl);
    pids.push_back(pid);
    slice.push_back(k);
  }
  std::vector<bool> crashed(pids.size(), false);
  for (std::size_t w = 0; w < pids.size(); ++w) {
    int status = 0;
    waitpid(pids[w], &status, 0);
    if (WIFSIGNALED(status)) {
      crashed[w] = true;
      std::fprintf(stderr, "sbot_validate: a worker process died of signal %d (%s)\n", WTERMSIG(status),
                   strsignal(WTERMSIG(status)));
    }
  }
  for (const auto& name : files) {
    std::ifstream f(name);
    std::string line;
    while (std::getline(f, line)) {
      std::stringstream ss(line);
      std::string idx, label, v1, v2;
      std::getline(ss, idx, '\t');
      std::getline(ss, label, '\t');
      std::getline(ss, v1, '\t');
      std::getline(ss, v2, '\t');
      const int i = std::atoi(idx.c_str());
      if (i >= 0 && i < static_cast<int>(out.size())) {
        out[i] = Outcome{label, std::atof(v1.c_str()), std::atof(v2.c_str())};
        reported[i] = true;
      }
    }
    std::remove(name.c_str());
  }
  g_worker_count = 0;
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  std::vector<std::vector<int>> unfinished;
  for (std::size_t w = 0; w < pids.size(); ++w) {
    if (!crashed[w]) continue;
    std::vector<int> left;
    for (int i = slice[w]; i < n; i += processes)
      if (!reported[jobs[i]]) left.push_back(jobs[i]);
    unfinished.push_back(left);
  }
  return unfinished;
}

}  // namespace

std::vector<Outcome> runParallel(int n, int processes, const std::function<Outcome(int)>& fn) {
  std::vector<Outcome> out(n, Outcome{"error"});
  std::vector<bool> reported(n, false);
  std::vector<int> pending(n);
  for (int i = 0; i < n; ++i) pending[i] = i;
  // A worker that crashes (a signal, e.g. an ODE assertion) takes down the trial it was running:
  // that one stays "error"; the trials it had not reached run again in the next round, so that one
  // bad cell does not cost its neighbours their results.
  while (!pending.empty()) {
    const std::vector<std::vector<int>> unfinished = runRound(pending, processes, fn, out, reported);
    pending.clear();
    for (const std::vector<int>& left : unfinished) {
      if (left.empty()) continue;
      std::fprintf(stderr, "sbot_validate: job %d crashed its worker and is marked error; %zu unfinished job(s) run again\n",
                   left.front(), left.size() - 1);
      pending.insert(pending.end(), left.begin() + 1, left.end());
    }
    std::sort(pending.begin(), pending.end());
  }
  return out;
}

bool accepts(const std::string& expected, const std::string& ours) {
  std::stringstream ss(expected);
  for (std::string e; std::getline(ss, e, '|');) {
    if (e == ours) return true;
    if (e == "stuck" && ours == "fall inside") return true;
    if (e == "fall inside" && ours == "stuck") return true;
    if (e == "fail" && ours == "topple") return true;
  }
  return false;
}

std::vector<std::string> modalLabels(const std::vector<Outcome>& outcomes, int* count) {
  std::map<std::string, int> counts;
  int best_n = 0;
  for (const auto& o : outcomes) best_n = std::max(best_n, ++counts[o.label]);
  // A second pass in input order: a label joins when its running count reaches the modal count.
  std::map<std::string, int> running;
  std::vector<std::string> labels;
  for (const auto& o : outcomes)
    if (++running[o.label] == best_n) labels.push_back(o.label);
  if (count) *count = best_n;
  return labels;
}

std::string modal(const std::vector<Outcome>& outcomes, int* count) {
  const std::vector<std::string> labels = modalLabels(outcomes, count);
  return labels.empty() ? std::string() : labels.front();
}

}  // namespace validation
}  // namespace sbot

namespace sbot {
namespace validation {

namespace {

/// A robot of `level` resting on flat ground for 2 s (the model facts' set-up).
struct RestingRobot {
  const RobotDescription& d;
  WorldConfig c;
  World w;
  Robot& r;
  explicit RestingRobot(const std::string& level)
      : d(loadLevel(level)), c(configFor(d, 9)), w(c), r(spawn(w, d, {0, 0, 0})) {
    r.setSpeed(0, 0);
    w.stepN(static_cast<int>(2.0 / c.step));
  }
};

const JointDescription& jointNamed(const RobotDescription& d, const std::string& name) {
  for (const auto& j : d.joints)
    if (j.name == name) return j;
  throw ConfigError(d.urdf_path, name, "no such joint");
}

}  // namespace

SideView sideView(const std::string& level) {
  RestingRobot rest(level);
  const RobotDescription& d = rest.d;
  // The left track's wheels: the centre one nearest the middle, the front one furthest ahead.
  const auto& wheels = d.treels.left_joints;
  if (wheels.empty()) throw ConfigError(d.sidecar_path, "treels.left_joints", "no driven wheels");
  const JointDescription* centre = &jointNamed(d, wheels.front());
  const JointDescription* front = centre;
  for (const auto& name : wheels) {
    const JointDescription& j = jointNamed(d, name);
    if (std::abs(j.origin.position.x()) < std::abs(centre->origin.position.x())) centre = &j;
    if (j.origin.position.x() > front->origin.position.x()) front = &j;
  }
  if (front == centre)
    throw ConfigError(d.sidecar_path, "treels.left_joints",
                      "the step statics need a front wheel ahead of the centre wheel, found only '" + centre->name + "'");
  for (const JointDescription* j : {centre, front})
    if (j->parent != d.root_link)
      throw ConfigError(d.urdf_path, j->name, "a wheel hinge on '" + j->parent + "', expected one on " + d.root_link);
  const Vec3 c = centre->origin.position, f = front->origin.position;
  const Vec3 com = rest.r.basePose().inverse().transform(rest.r.centreOfMass());
  SideView s;
  s.centre_radius = d.wheelRadius(centre->name);
  s.front_radius = d.wheelRadius(front->name);
  s.front_axle_x = f.x() - c.x();
  s.front_axle_z = f.z() - c.z();
  s.com_x = com.x() - c.x();
  s.com_z = com.z() - c.z();
  return s;
}

double turretMassShare(const std::string& level) {
  const RobotDescription& d = loadLevel(level);
  const std::string& turret = jointNamed(d, d.turret.joint).child;
  for (const auto& l : d.links)
    if (l.name == turret) return l.mass / d.totalMass();
  throw ConfigError(d.urdf_path, turret, "no such link");
}

std::string restFacts(const std::string& level) {
  RestingRobot rest(level);
  Robot& r = rest.r;
  double m = 0;
  const Vec3 com = r.centreOfMass(&m);
  const Pose base = r.basePose();
  const Vec3 com_b = base.inverse().transform(com);
  const Vec3 rpy = rpyFromQuat(base.orientation);
  std::ostringstream s;
  s << level << ": mass " << m << " kg, bodies " << r.bodyCount()
    << (r.turretLocked() ? " (turret welded to the treels while idle)" : "") << ", COM in base frame (" << com_b.x() << ", "
    << com_b.y() << ", " << com_b.z() << ") m, COM height above ground " << com.z() << " m, base height "
    << base.position.z() << " m, rest roll " << rpy.x() * 180 / M_PI << " deg pitch " << rpy.y() * 180 / M_PI
    << " deg";
  return s.str();
}

Outcome tippingAngle(const std::string& level, bool backward, int iterations) {
  const RobotDescription& d = loadLevel(level);
  WorldConfig c = configFor(d, 11);
  if (iterations > 0) {
    c.solver_iterations = iterations;
    c.level_iterations = false;
  }
  World w(c);
  Robot& r = spawn(w, d, {0, 0, backward ? M_PI : 0.0});
  r.setSpeed(0, 0);
  w.stepN(static_cast<int>(1.0 / c.step));
  constexpr double kRate = 1.0;  // [deg/s] slow against the robot's dynamics: quasi-static
  Outcome o{"upright", 90, 90};  // value: tipping angle, value2: angle at which it slides
  std::deque<std::pair<Vec3, double>> trail;  // base position and tilt over the last second
  const std::size_t window = static_cast<std::size_t>(std::lround(1.0 / c.step)) + 1;
  for (double t = 0; t < 90 / kRate; t += c.step) {
    const double a = kRate * t * M_PI / 180;
    w.setGravity(Vec3(-c.gravity * std::sin(a), 0, -c.gravity * std::cos(a)));
    w.step();
    // Sliding: 1 cm (scaled) in the last second with the attitude unchanged (within 2 deg: not
    // the start of a tip). Creep is ~1 mm/s; the instantaneous velocity carries quickstep's jitter.
    const double tilt = angleBetween(upOf(r), Vec3::UnitZ());
    trail.push_back({r.basePose().position, tilt});
    if (trail.size() > window) trail.pop_front();
    if (o.value2 == 90 && trail.size() == window &&
        (trail.back().first - trail.front().first).norm() > 0.01 * lengthScale(level) &&
        std::fabs(trail.back().second - trail.front().second) < 2 * M_PI / 180)
      o.value2 = kRate * t;
    if (tilt > 45 * M_PI / 180) {
      o.label = "tipped";
      o.value = kRate * t;
      break;
    }
  }
  return o;
}

}  // namespace validation
}  // namespace sbot
