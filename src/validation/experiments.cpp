// The trials' shared set-up (worlds, spawning, stepping), the study knobs, the catalogue of trial
// kinds and the model facts. The trials themselves: experiments_terrain.cpp and
// experiments_efficiency.cpp; running them in worker processes: experiments_runner.cpp.
#include "experiments.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/world.h"

#include "experiments_internal.h"

namespace sbot {
namespace validation {
namespace detail {

WorldConfig configFor(const RobotDescription& d, std::uint64_t seed, const Drive& drive) {
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

}  // namespace detail

using namespace detail;

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
