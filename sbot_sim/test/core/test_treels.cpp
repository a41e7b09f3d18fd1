// Treels module acceptance (issue: foundation): speed in s-bot units, spinning on the spot,
// stalling against a wall, the acceleration phase, API clamping.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <algorithm>

#include <cmath>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "sbot_sim/core/effects.h"
#include "sbot_sim/core/errors.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

// The steady-speed measurement of every level (the Fast level must match the others): setSpeed(50, 50),
// 2 s of acceleration phase and settling, then the base position before and after 3 s more.
std::pair<Vec3, Vec3> steadyStretchAt50(World& w, Robot& r) {
  r.setSpeed(50, 50);
  runFor(w, 2.0);
  const Vec3 p0 = r.basePose().position;
  runFor(w, 3.0);
  return {p0, r.basePose().position};
}

/// The yaw [rad] the robot turns over the next `steps` steps, unwrapped (> 0 counter-clockwise).
double turnedOver(World& w, const Robot& r, int steps) {
  double turned = 0, last = r.basePose().yaw();
  for (int i = 0; i < steps; ++i) {
    w.step();
    turned += wrapAngle(r.basePose().yaw() - last);
    last = r.basePose().yaw();
  }
  return turned;
}

TEST(Treels, Speed50Gives14cmPerSecond) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  const auto [p0, p1] = steadyStretchAt50(w, r);
  const double speed = (p1 - p0).head<2>().norm() / 3.0;
  EXPECT_NEAR(speed, 0.140, 0.140 * 0.05) << "steady speed at setSpeed(50,50) [m/s]";
  // It drove forward (+x at yaw 0), not sideways.
  EXPECT_GT(p1.x() - p0.x(), 0.9 * (p1 - p0).head<2>().norm());
  int l, rr;
  r.getSpeed(&l, &rr);
  EXPECT_NEAR(l, 50, 2);
  EXPECT_NEAR(rr, 50, 2);
}

TEST(Treels, SpeedIsReachedOnlyAfterAnAccelerationPhase) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);  // settle on the ground
  r.setSpeed(70, 70);
  w.step();
  const double v_first = r.linearVelocity().head<2>().norm();
  EXPECT_LT(v_first, 0.5 * 70 * 0.0028) << "the body cannot reach the requested speed in one step";
  runFor(w, 1.0);
  const Vec3 p0 = r.basePose().position;
  runFor(w, 1.0);
  EXPECT_NEAR((r.basePose().position - p0).head<2>().norm(), 70 * 0.0028, 0.05 * 70 * 0.0028)
      << "mean speed over the second second [m/s]";
}

TEST(Treels, SpinOnTheSpotDriftsLessThan1cmPerTurn) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0.3, -0.2, 0.4}, "sbot_0");
  runFor(w, 0.5);
  const Vec3 start = r.basePose().position;
  r.setSpeed(50, -50);
  // Count turns by integrating yaw changes.
  double turned = 0, last = r.basePose().yaw();
  double max_drift = 0;
  while (std::abs(turned) < 2 * 2 * M_PI && w.time() < 60) {
    w.step();
    const double y = r.basePose().yaw();
    turned += wrapAngle(y - last);
    last = y;
    max_drift = std::max(max_drift, (r.basePose().position - start).head<2>().norm());
  }
  ASSERT_GE(std::abs(turned), 4 * M_PI) << "did not complete two turns within 60 s";
  EXPECT_LT(turned, 0) << "left forward, right backward turns clockwise (negative yaw)";
  const double drift = (r.basePose().position - start).head<2>().norm();
  EXPECT_LT(drift / 2.0, 0.01) << "centre drift per turn [m]";
  EXPECT_LT(max_drift, 0.02);
}

// Against a wall the robot stops. Its motors (10 N per track at the ground, Table 2.2) are stronger
// than the traction a 660 g robot gets (mu N = 6.5 N), so the tracks slip at the commanded speed
// and the torque reading is the traction limit, not the motor maximum; with the tracks held
// (traction above the motor force) the motor stalls at its maximum, 90 units.
TEST(Treels, DrivingIntoAWallStopsTheRobotAndSlipsTheTracks) {
  WorldConfig c = flatWorld();
  c.terrain.boxes.push_back({"wall", Vec3(0.25, 0, 0.1), Vec3(0.05, 1.0, 0.2), 0, 0, "wall"});
  World w(c);
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  r.setSpeed(50, 50);
  runFor(w, 3.0);
  const Vec3 before = r.basePose().position;
  runFor(w, 1.0);
  EXPECT_LT(r.basePose().position.x(), 0.25 - 0.025 - 0.05) << "turret front must stop at the wall face";
  EXPECT_LT(std::abs(r.basePose().position.x() - before.x()), 0.005) << "robot still advancing against the wall";
  int sl, sr;
  r.getSpeed(&sl, &sr);
  EXPECT_NEAR(sl, 50, 3) << "slipping tracks keep their commanded speed";
  // Mean torque over a second is bounded by traction: well below the 90-unit maximum.
  double mean_torque = 0;
  for (int i = 0; i < 100; ++i) {
    w.step();
    int tl, tr;
    r.getTrackTorque(&tl, &tr);
    mean_torque += 0.5 * (tl + tr) / 100.0;
  }
  const double mu = w.config().contact.muFor("track", "ground") * r.description().treels.friction_scale;
  const double traction_limit_units = mu * 0.66 * 9.81 / 2 * 0.022 / 0.0024412;  // mu m g / 2 * r
  EXPECT_LT(mean_torque, 0.5 * 90);
  EXPECT_LT(mean_torque, 1.2 * traction_limit_units);
}

TEST(Treels, HeldTracksStallAtMaximumTorque) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.3);
  // Hold the chassis in place (a fixed joint to the world) and give the wheels unlimited grip: the
  // external block the seed's API text describes.
  dJointID hold = dJointCreateFixed(w.odeWorld(), nullptr);
  dJointAttach(hold, r.baseBody(), nullptr);
  dJointSetFixed(hold);
  r.setSpeed(50, 50);
  for (dBodyID b : r.bodies()) {
    if (b == r.baseBody()) continue;
    dJointID lock = dJointCreateFixed(w.odeWorld(), nullptr);  // wheel and turret locked to the world
    dJointAttach(lock, b, nullptr);
    dJointSetFixed(lock);
  }
  runFor(w, 0.5);
  int sl, sr, tl, tr;
  r.getSpeed(&sl, &sr);
  r.getTrackTorque(&tl, &tr);
  EXPECT_LE(std::abs(sl), 1);
  EXPECT_LE(std::abs(sr), 1);
  EXPECT_NEAR(tl, 90, 1) << "a blocked motor pushes with its full 0.21971 N m";
  EXPECT_NEAR(tr, 90, 1);
  // On free ground the same command needs only a small fraction of it.
  World free_world(flatWorld());
  Robot& f = free_world.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  f.setSpeed(50, 50);
  runFor(free_world, 3.0);
  double free_torque = 0;
  for (int i = 0; i < 100; ++i) {
    free_world.step();
    int fl, fr;
    f.getTrackTorque(&fl, &fr);
    free_torque += 0.5 * (fl + fr) / 100.0;
  }
  EXPECT_LT(std::abs(free_torque), 20) << "mean torque on free ground [units]";
}

// getTrackTorque reports the mean motor torque over treels.torque_window (0.1 s), not one step's
// constraint torque, which jitters with the contact solver (quickstep, six wheels).
TEST(Treels, TrackTorqueIsTheMeanOverItsWindow) {
  World w(flatWorld());
  const RobotDescription d = loadLevel("medium");
  Robot& r = w.addRobot(d, {0, 0, 0}, "sbot_0");
  const int n = static_cast<int>(std::lround(d.treels.torque_window / w.config().step));
  ASSERT_GT(n, 1);
  r.setSpeed(40, 40);
  runFor(w, 2.0);
  std::vector<double> steps;  // per-step left-track torque [N m] from the joints' efforts
  std::vector<double> readings;
  for (int i = 0; i < 300; ++i) {
    w.step();
    double t = 0;
    for (const auto& j : r.jointStates())
      if (std::find(d.treels.left_joints.begin(), d.treels.left_joints.end(), j.name) != d.treels.left_joints.end())
        t += j.effort;
    steps.push_back(t);
    if (steps.size() >= static_cast<std::size_t>(n)) {
      double mean = 0;
      for (int k = 0; k < n; ++k) mean += steps[steps.size() - 1 - k] / n;
      ASSERT_NEAR(r.trackTorqueLeft(), mean, 1e-12) << "step " << i;
    }
    if (i % n == 0) readings.push_back(r.trackTorqueLeft() / d.treels.torque_unit);
  }
  auto sd = [](const std::vector<double>& v) {
    double m = 0, s = 0;
    for (double x : v) m += x / v.size();
    for (double x : v) s += (x - m) * (x - m) / v.size();
    return std::sqrt(s);
  };
  std::vector<double> step_units;
  for (double t : steps) step_units.push_back(t / d.treels.torque_unit);
  EXPECT_GT(sd(step_units), 2.0) << "the per-step torque jitters (if not, the window is not needed)";
  EXPECT_LT(sd(readings), 0.5 * sd(step_units)) << "readings at 10 Hz, API units";
}

TEST(Treels, ApiRangeIsClampedThenLimitedTo70) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  EXPECT_FALSE(r.setSpeed(70, -70));
  EXPECT_DOUBLE_EQ(r.requestedLeft(), 70 * 0.0028);
  EXPECT_TRUE(r.setSpeed(127, -500));
  EXPECT_DOUBLE_EQ(r.requestedLeft(), 70 * 0.0028);
  EXPECT_DOUBLE_EQ(r.requestedRight(), -70 * 0.0028);
  r.setTrackSpeeds(std::nan(""), 1.0);
  EXPECT_DOUBLE_EQ(r.requestedLeft(), 0.0) << "NaN must not reach the motors";
  EXPECT_DOUBLE_EQ(r.requestedRight(), 70 * 0.0028);
}

}  // namespace
}  // namespace sbot::test

namespace sbot::test {
namespace {

// Seed Table 2.2 / 2.4.1: pulling an s-bot takes 1.2 N. We reproduce it with the motors off
// (passive treels, gear back-drive): ramp a horizontal pull up slowly and note the force at which
// the robot breaks away: rolls faster than 1 cm/s for 0.1 s. (Not a distance moved: standing on its
// wheels under quickstep the robot creeps a few mm per second before it breaks away, and a 1 cm
// displacement read that creep at 1.0 N; the converged solver gives 1.4 N, the reflected rotor
// inertia's share of the ramp.)
double breakawayForce() {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  r.setTracksPassive(true);
  runFor(w, 0.5);
  const double ramp = 0.2;  // [N/s]
  const int rolling_steps = static_cast<int>(0.1 / w.config().step + 0.5);
  int rolling = 0;
  for (double force = 0; force < 3.0; force += ramp * w.config().step) {
    const Vec3 p = r.basePose().position;
    dBodyAddForceAtPos(r.baseBody(), force, 0, 0, p.x(), p.y(), p.z());
    w.step();
    rolling = dBodyGetLinearVel(r.baseBody())[0] > 0.01 ? rolling + 1 : 0;
    if (rolling >= rolling_steps) return force;
  }
  return 3.0;
}

TEST(Treels, PassiveRobotBreaksAwayAtTheSeeds1_2Newton) {
  EXPECT_NEAR(breakawayForce(), 1.2, 0.15) << "pull force [N] at which a passive s-bot starts rolling";
}

// Friction must not depend on the world axes: ODE's default pyramid directions are fixed in the
// world (a Medium robot spun 323 deg in 3 s from heading 0 but 333 deg from 45 deg). The exact
// solver, because quickstep's unconverged contacts alone scatter a Medium spin by ~2 %.
TEST(Treels, SpinDoesNotDependOnTheStartHeading) {
  for (const std::string level : {"simple", "medium"}) {
    std::vector<double> turned;
    for (double yaw0 : {0.0, M_PI / 8, M_PI / 4}) {
      WorldConfig c = flatWorld();
      c.solver = "exact";
      World w(c);
      Robot& r = w.addRobot(loadLevel(level), {0, 0, yaw0}, "sbot_0");
      runFor(w, 0.3);
      r.setSpeed(30, -30);
      turned.push_back(turnedOver(w, r, 300));
    }
    const auto [lo, hi] = std::minmax_element(turned.begin(), turned.end());
    std::printf("%s spin 3 s from 0/22.5/45 deg: %.1f %.1f %.1f deg\n", level.c_str(), turned[0] * 180 / M_PI,
                turned[1] * 180 / M_PI, turned[2] * 180 / M_PI);
    EXPECT_LT(*hi - *lo, 0.003 * std::abs(*hi)) << level;
  }
}

// ---- world.solver: exact (dWorldStep) --------------------------------------------------------

/// Heading change [deg] of a robot of `level` driving setSpeed(units, units) for 10 s.
double headingChange(const std::string& level, const std::string& solver, int units, bool weld = false) {
  WorldConfig c = flatWorld();
  c.solver = solver;
  c.lock_idle_turret = weld;
  World w(c);
  Robot& r = w.addRobot(loadLevel(level), {0, 0, 0}, "sbot_0");
  r.setSpeed(units, units);
  const double yaw0 = r.basePose().yaw();
  runFor(w, 10.0);
  return wrapAngle(r.basePose().yaw() - yaw0) * 180 / M_PI;
}

TEST(Treels, WeldedTurretsKeepTheHeadingUnderQuickstep) {
  // Quickstep does not converge on the turret hinged 3 cm off its centre of mass: standing or at
  // 60 units, Basic and Medium turn 5-7 deg in 10 s. Welded while idle (opt-in WorldConfig::
  // lock_idle_turret) they turn 0.0-1.4 deg (docs/model.md, "Yaw drift under quickstep").
  for (const std::string level : {"simple", "basic", "medium", "detailed"}) {
    EXPECT_LT(std::abs(headingChange(level, "quickstep", 0, true)), 2.0) << level << " standing";
    // Detailed hardly drifts on its hinge (-0.9 deg driving); welded it turns +0.7 deg. The weld
    // is for Basic and Medium (+0.7 and -0.8 deg driving).
    const double driving_bound = level == "detailed" ? 5.0 : 4.0;
    EXPECT_LT(std::abs(headingChange(level, "quickstep", 60, true)), driving_bound) << level << " driving";
  }
  // The drift the weld removes (Medium -5.0 deg driving, Basic -6.4; with Table 2.3's turret
  // centre of mass, 4 cm off its axis, -6.7 and -7.5).
  EXPECT_GT(std::abs(headingChange("medium", "quickstep", 60)), 3.0) << "the drift the weld removes";
  EXPECT_GT(std::abs(headingChange("basic", "quickstep", 60)), 3.0) << "the drift the weld removes";
}

TEST(TreelsExactSolver, SymmetricCommandsDriveStraight) {
  for (const std::string level : {"simple", "basic", "medium"}) {
    // Medium's force-limited treels (sidecar friction_law) drift 0.68 deg in 10 s (Coulomb: < 0.5).
    const double driving_bound = level == "medium" ? 1.0 : 0.5;
    EXPECT_LT(std::abs(headingChange(level, "exact", 60)), driving_bound) << level << " driving";
    EXPECT_LT(std::abs(headingChange(level, "exact", 0)), 0.2) << level << " standing";
  }
  EXPECT_THROW(headingChange("simple", "fancy", 10), ConfigError);
}

// ---- Load on the driven wheels (Robot::driveWheelLoad) --------------------------------------------

/// Mean drive-wheel load over `seconds` as a fraction of the robot's weight.
double driveWheelShare(World& w, Robot& r, double seconds) {
  double sum = 0;
  const int n = static_cast<int>(seconds / w.config().step);
  for (int i = 0; i < n; ++i) {
    w.step();
    sum += r.driveWheelLoad();
  }
  return sum / n / (r.description().totalMass() * w.config().gravity);
}

TEST(DriveWheelLoad, SixDrivenWheelsCarryTheWholeWeight) {
  for (const std::string level : {"medium", "detailed"}) {
    World w(flatWorld());
    Robot& r = w.addRobot(loadLevel(level), {0, 0, 0}, "sbot_0");
    runFor(w, 1.0);
    EXPECT_NEAR(driveWheelShare(w, r, 1.0), 1.0, 0.05) << level;
  }
}

TEST(DriveWheelLoad, SimpleStandsOnItsWheelsUnderQuickstep) {
  // The casters are 2 mm above the wheels' ground plane, so the wheels should carry the weight.
  // With 20 g wheels they do not at 20 quickstep iterations: the hinges sag ~1.4 mm under the
  // 360 g turret and the chassis sits on its frictionless casters (48 % on the wheels). The 45 g
  // wheels carry it (docs/model.md, "Casters and running gear").
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(w, 1.0);
  EXPECT_GT(driveWheelShare(w, r, 1.0), 0.9) << "quickstep, 20 iterations";
  WorldConfig converged = flatWorld();
  converged.solver = "exact";
  World x(converged);
  Robot& rx = x.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
  runFor(x, 1.0);
  EXPECT_GT(driveWheelShare(x, rx, 1.0), 0.95) << "exact solver";
}

// The share of a Basic robot's weight its wheels carry by statics, as it stands now: the two
// spherical wheels and the front caster carry it, so with the centre of mass between the wheels'
// and the caster's ground contacts (x_w, x_c, x_f) the wheels take (x_f - x_c) / (x_f - x_w).
// Spheres on flat ground touch it straight below their centres, so the x are taken horizontally
// in the world, along the robot's heading (the robot leans onto its caster, 2 mm lower than the
// wheels' plane, and under quickstep its wheel hinges sag).
double basicWheelShareByStatics(const Robot& r) {
  const Vec3 heading = r.basePose().orientation * Vec3::UnitX();
  const auto along = [&](const Vec3& p) { return p.head<2>().dot(heading.head<2>().normalized()); };
  double mass = 0, moment = 0;
  for (dBodyID b : r.bodies()) {
    dMass m;
    dBodyGetMass(b, &m);
    const dReal* p = dBodyGetPosition(b);
    mass += m.mass;
    moment += m.mass * along(Vec3(p[0], p[1], p[2]));
  }
  const double x_c = moment / mass;
  const double x_w = 0.5 * (along(r.linkPose("left_wheel").position) + along(r.linkPose("right_wheel").position));
  const double x_f = along(r.linkPose("caster_front").position);
  EXPECT_GT(x_c - along(r.basePose().position), 0.01) << "Basic's offset centre of mass";
  return (x_f - x_c) / (x_f - x_w);
}

TEST(DriveWheelLoad, BasicLeansOnItsFrontCasterAsItsCentreOfMassSays) {
  // Converged (exact solver) the wheels carry what statics say. Quickstep at 20 iterations leaves
  // the wheel hinges sagging a little and the casters take a few % of the weight more (with 20 g
  // wheels: 0.506 against 0.556).
  const std::map<std::string, double> tolerance{{"exact", 0.01}, {"quickstep", 0.07}};
  for (const auto& [solver, tol] : tolerance) {
    WorldConfig c = flatWorld();
    c.solver = solver;
    World w(c);
    Robot& r = w.addRobot(loadLevel("basic"), {0, 0, 0}, "sbot_0");
    runFor(w, 1.0);
    const double statics = basicWheelShareByStatics(r);
    EXPECT_NEAR(driveWheelShare(w, r, 1.0), statics, tol) << solver;
  }
}

TEST(DriveWheelLoad, NothingWhileAirborne) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("medium"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  EXPECT_GT(r.driveWheelLoad(), 1.0);
  Pose lifted = r.basePose();
  lifted.position.z() += 0.5;
  r.setBasePose(lifted);
  w.step();
  EXPECT_EQ(r.driveWheelLoad(), 0.0);
}

// ---- Fast level: body drive in 1/50 g at 100 ms steps (sidecar treels.drive: body) -------------

WorldConfig fastWorld() {
  const RobotDescription& d = loadLevel("fast");
  WorldConfig c;
  c.step = d.recommended_step;
  c.gravity = d.gravity;
  return c;
}

TEST(Treels, EveryLevelDrivesAlongItsHeadingWhateverItsSpawnYaw) {
  // A robot spawned facing any way drives where it faces (the Fast drive's motor axes once stayed
  // along world +x: spawned facing +y it drove sideways). Tolerances allow quickstep's yaw drift.
  for (const std::string level : {"fast", "simple", "basic", "medium", "detailed"}) {
    for (const double yaw : {0.0, 1.6, -2.5, 3.0}) {
      World w(level == "fast" ? fastWorld() : flatWorld());
      Robot& r = w.addRobot(loadLevel(level), {0.3, -0.2, yaw}, "sbot_0");
      const auto [p0, p1] = steadyStretchAt50(w, r);
      const Vec3 moved = p1 - p0;
      const Vec3 heading = r.basePose().orientation * Vec3::UnitX();
      EXPECT_NEAR(moved.head<2>().norm() / 3.0, 0.140, 0.140 * 0.05) << level << " yaw " << yaw;
      EXPECT_GT(moved.head<2>().normalized().dot(heading.head<2>().normalized()), 0.99) << level << " yaw " << yaw;
      EXPECT_NEAR(wrapAngle(r.basePose().yaw() - yaw), 0.0, 0.25) << level << " yaw " << yaw;  // Basic drifts 9 deg in 5 s
    }
  }
}

// cmd_vel turns at w = (v_r - v_l) / trackWidth(): the width must be the one the robot turns on,
// the centre wheels' 8.2 cm (Table 2.2) on every full-size level. Medium's mean over its six
// wheels, 5.5 cm, turned it at 58-68 % of the commanded rate. A slow spin (10 units, ~0.7 rad/s)
// turns Fast, Simple, Basic and Medium within 5 % of that rate. Detailed's teethed wheels skid
// (about 70 % of it at 10 units): its own physics, not its width (docs/model.md, "The levels turn at different rates").
TEST(Treels, TrackWidthIsTheWidthTheRobotTurnsOn) {
  for (const std::string level : {"fast", "simple", "basic", "medium", "detailed"}) {
    const RobotDescription& d = loadLevel(level);
    World w(level == "fast" ? fastWorld() : flatWorld());
    Robot& r = w.addRobot(d, {0, 0, 0}, "sbot_0");
    EXPECT_NEAR(r.trackWidth(), level == "fast" ? 0.041 : 0.082, 1e-6) << level;
    if (level == "detailed") continue;
    runFor(w, 0.5);
    r.setSpeed(10, -10);
    runFor(w, 1.0);
    const double turned = turnedOver(w, r, static_cast<int>(std::lround(3.0 / w.config().step)));
    const double commanded = 2 * 10 * d.treels.speed_unit / r.trackWidth();
    EXPECT_NEAR(std::abs(turned) / 3.0, commanded, 0.05 * commanded) << level;
  }
}

TEST(TreelsFast, SameSteadySpeedAsTheOtherLevels) {
  ASSERT_EQ(loadLevel("fast").treels.drive, "body");
  World w(fastWorld());
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  const auto [p0, p1] = steadyStretchAt50(w, r);
  EXPECT_NEAR((p1 - p0).head<2>().norm() / 3.0, 0.140, 0.140 * 0.03) << "seed 2.1.3: the same steady speed";
  EXPECT_GT(p1.x() - p0.x(), 0.99 * (p1 - p0).head<2>().norm()) << "straight ahead";
  EXPECT_GT((r.basePose().orientation * Vec3::UnitZ()).z(), 0.99) << "upright";
  int l, rr;
  r.getSpeed(&l, &rr);
  EXPECT_NEAR(l, 50, 1);
  EXPECT_NEAR(rr, 50, 1);
}

TEST(TreelsFast, SpinsAtTheDifferentialDriveRate) {
  World w(fastWorld());
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  r.setSpeed(-20, 20);
  runFor(w, 1.0);
  const Vec3 start = r.basePose().position;
  const double turned = turnedOver(w, r, 20);  // 2 s
  // Wheels 4.1 cm apart: yaw rate = 2 * 20 * 2.8 mm/s / 0.041 m = 2.73 rad/s.
  EXPECT_NEAR(turned / 2.0, 2 * 20 * 0.0028 / 0.041, 0.05 * 2.73);
  EXPECT_LT((r.basePose().position - start).head<2>().norm(), 0.005) << "on the spot";
}

TEST(TreelsFast, AccelerationIsTractionLimitedAndTorqueIsRead) {
  World w(fastWorld());
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  r.setSpeed(70, 70);
  w.step();
  // mu 1 in 1/50 g: at most 0.196 m/s^2, so one 100 ms step gains at most ~2 cm/s of the 19.6.
  EXPECT_LT(r.linearVelocity().head<2>().norm(), 0.025);
  EXPECT_GT(r.linearVelocity().head<2>().norm(), 0.010);
  int tl, tr;
  r.getTrackTorque(&tl, &tr);
  EXPECT_GT(tl, 5) << "the drive's force shows as track torque while accelerating";
  EXPECT_GT(tr, 5);
  EXPECT_NEAR(tl, tr, 10) << "straight: the yaw motor only holds small disturbances";
}

TEST(TreelsFast, AHardStartRearsTheRobotOnItsMotorsReactionAndItDropsBack) {
  // The body drive pushes at the chassis' centre; the wheel motors' reaction (push x wheel radius,
  // Robot::applyDriveReaction) pitches the nose up while the robot accelerates at its traction
  // limit, until its rear caster (2.25 cm behind the axle, 1 mm clear of the ground) touches at
  // atan(1 / 22.5) = 2.5 deg; without the reaction it pitches 0.1 deg. It then drops back.
  World w(fastWorld());
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  auto nose_up_deg = [&] { return std::asin((r.basePose().orientation * Vec3::UnitX()).z()) * 180 / M_PI; };
  EXPECT_NEAR(nose_up_deg(), 0.0, 1.0) << "level at rest";
  r.setSpeed(70, 70);
  double most = -90;
  for (int i = 0; i < 10; ++i) {  // 1 s of accelerating
    w.step();
    most = std::max(most, nose_up_deg());
  }
  EXPECT_GT(most, 2.0) << "the motors' reaction rears it onto its rear caster";
  EXPECT_LT(most, 20.0) << "but does not flip it";
  runFor(w, 3.0);
  EXPECT_NEAR(nose_up_deg(), 0.0, 2.0) << "back on its wheels at steady speed";
  EXPECT_NEAR(r.linearVelocity().x(), 70 * 0.0028, 0.01);
}

TEST(TreelsFast, NoPushWhileAirborne) {
  // The drive's traction is the tracks' load: lifted off the ground (by a hand, another robot's
  // gripper, over a cliff) the robot must not fly along its heading.
  World w(fastWorld());
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  Pose lifted = r.basePose();
  lifted.position.z() += 0.3;  // falls 0.3 m in 1/50 g: 1.75 s
  r.setBasePose(lifted);
  w.step();  // the load is measured in a step: the next one knows the robot left the ground
  r.setSpeed(50, 50);
  runFor(w, 1.2);
  EXPECT_LT(r.linearVelocity().head<2>().norm(), 0.001) << "no horizontal speed in free fall";
  EXPECT_GT(r.basePose().position.z(), 0.05) << "still falling";
  runFor(w, 4.0);
  EXPECT_NEAR(r.linearVelocity().x(), 0.14, 0.01) << "drives again once landed";
}

TEST(TreelsFast, TractionComesFromTheLoadNotFromASidePush) {
  // A Fast robot pressed sideways against a wall: the wall's push shows in the contact force but
  // not along the chassis' up axis, which is what the drive's traction is taken from.
  WorldConfig c = fastWorld();
  c.terrain.type = TerrainConfig::Type::Composite;
  BoxObstacle wall;
  wall.name = "wall";
  wall.center = Vec3(0, 0.0315 + 0.01, 0.02);  // its face where the wheels end (y = 2.05 + 1.1 cm)
  wall.size = Vec3(0.2, 0.02, 0.04);
  c.terrain.boxes.push_back(wall);
  World w(c);
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  runFor(w, 0.5);
  const double weight = r.description().totalMass() * w.config().gravity;
  const Vec3 up = r.basePose().orientation * Vec3::UnitZ();
  EXPECT_NEAR(r.driveContactForce().dot(up), weight, 0.05 * weight) << "standing: the weight";
  const double push = 2 * weight;
  for (int i = 1; i <= 30; ++i) {  // ramped over 1 s, then held 2 s: a jolt would roll the light robot
    dBodyAddForce(r.baseBody(), 0, push * std::min(1.0, i / 10.0), 0);
    w.step();
  }
  const Vec3 f = r.driveContactForce();
  EXPECT_LT(f.y(), -0.3 * weight) << "the wall pushes back on the wheel and chassis";
  EXPECT_GT(r.driveWheelLoad(), 1.3 * weight) << "the wall's push is in the contacts' normal load";
  EXPECT_NEAR(f.dot(r.basePose().orientation * Vec3::UnitZ()), weight, 0.2 * weight)
      << "but not in the load along the chassis' up axis";
  w.step();  // the drive's traction for the next step comes from that load: mu (track 1.0) x weight
  const double mu = w.config().contact.muFor("track", "ground");
  EXPECT_NEAR(r.bodyDriveTraction(), mu * weight, 0.2 * mu * weight) << "not mu x the normal forces' sum";
}

TEST(TreelsFast, PassiveFastRobotHoldsBelowItsScaledBackDriveForce) {
  World w(fastWorld());
  const RobotDescription& d = loadLevel("fast");
  Robot& r = w.addRobot(d, {0, 0, 0}, "sbot_0");
  r.setTracksPassive(true);
  runFor(w, 0.5);
  auto pulled = [&](double force) {
    const double x0 = r.basePose().position.x();
    for (int i = 0; i < 20; ++i) {
      const Vec3 p = r.baseBody() ? r.basePose().position : Vec3::Zero();
      dBodyAddForceAtPos(r.baseBody(), force, 0, 0, p.x(), p.y(), p.z());
      w.step();
    }
    return r.basePose().position.x() - x0;
  };
  EXPECT_LT(pulled(0.7 * d.treels.backdrive_force), 0.002);
  EXPECT_GT(pulled(2.0 * d.treels.backdrive_force), 0.01);
}

// ---- Track creep (treels.creep_stiffness) ---------------------------------------------------------

/// A world whose gravity is tilted by `deg` (an infinite slope rising toward +x), with treels mu 2
/// so that they do not slide, holding one Detailed s-bot facing uphill; without creep when `creep`
/// is false. Keeps the description the robot points to.
struct DetailedOnSlope {
  RobotDescription description;
  std::unique_ptr<World> world;
  Robot* robot = nullptr;
  DetailedOnSlope(double deg, bool creep) : description(loadLevel("detailed")) {
    if (!creep) description.treels.creep_stiffness = 0;
    WorldConfig c = flatWorld();
    c.contact.material_mu["track"] = 2.0;
    world = std::make_unique<World>(c);
    const double a = deg * M_PI / 180;
    dWorldSetGravity(world->odeWorld(), -c.gravity * std::sin(a), 0, -c.gravity * std::cos(a));
    robot = &world->addRobot(description, {0, 0, 0}, "sbot_0");
  }
};

/// Progress along the slope over `climb_s` at `units` after 1 s to get going, as a fraction of the
/// commanded distance.
double climbEfficiency(double deg, int units, bool creep, double climb_s = 4.0) {
  DetailedOnSlope s(deg, creep);
  s.robot->setSpeed(units, units);
  runFor(*s.world, 1.0);
  const double x0 = s.robot->basePose().position.x();
  runFor(*s.world, climb_s);
  return (s.robot->basePose().position.x() - x0) / (units * s.description.treels.speed_unit * climb_s);
}

TEST(TrackCreep, ClimbingTracksSlipByTheirTractionRatioOverTheCreepStiffness) {
  const double C = loadLevel("detailed").treels.creep_stiffness;
  ASSERT_GT(C, 0) << "the levels creep";
  // Flat: hardly any traction, hardly any creep.
  EXPECT_NEAR(climbEfficiency(0, 10, true), climbEfficiency(0, 10, false), 0.01);
  // Climbing, the tracks pull with F/N = tan(slope): the speed lost is tan(slope) / C. Measured:
  // 17-31 % more than that at 20-35 deg, with Table 2.3's and with the calibrated turret COM
  // (35 deg: 27 % and 31 %); why it exceeds tan / C is not analysed.
  for (double deg : {20.0, 30.0, 35.0}) {
    const double without = climbEfficiency(deg, 10, false), with = climbEfficiency(deg, 10, true);
    const double lost = without - with;
    const double expected = std::tan(deg * M_PI / 180) / C;
    std::printf("%.0f deg: efficiency %.3f without creep, %.3f with (lost %.3f, tan / C %.3f)\n", deg, without, with, lost, expected);
    EXPECT_NEAR(lost, expected, 0.35 * expected) << deg << " deg";
  }
  // A slip ratio, not a slip speed: the fraction lost does not depend on the speed.
  const double slow = climbEfficiency(30, 10, false) - climbEfficiency(30, 10, true);
  const double fast = climbEfficiency(30, 40, false, 2.0) - climbEfficiency(30, 40, true, 2.0);
  EXPECT_NEAR(fast, slow, 0.3 * slow);
}

TEST(TrackCreep, StandingTracksDoNotCreep) {
  // Holding (setSpeed(0, 0)) on 40 deg, front uphill: creep needs a moving track, so the robot
  // stands as it does without. (Both settle by a few mm: quickstep's own creep under load.)
  double moved[2];
  for (bool creep : {true, false}) {
    DetailedOnSlope s(40, creep);
    s.robot->setSpeed(0, 0);
    runFor(*s.world, 0.5);
    const double x0 = s.robot->basePose().position.x();
    runFor(*s.world, 3.0);
    moved[creep] = s.robot->basePose().position.x() - x0;
  }
  // 3.4 mm both; a creep acting on held tracks (their load is F/N = tan 40 deg) adds ~1 cm, and
  // one taking the speed of the held, jittering wheels (not bounded by the motor's) 0.6 mm.
  EXPECT_NEAR(moved[true], moved[false], 0.0003);
}

TEST(TrackCreep, NotForTheBodyDrive) {
  World w(fastWorld());
  Robot& r = w.addRobot(loadLevel("fast"), {0, 0, 0}, "sbot_0");
  r.setSpeed(50, 50);
  runFor(w, 1.0);
  EXPECT_GT(r.driveWheelLoad(), 0);
  EXPECT_EQ(r.trackCreepSlip(0), 0.0);
  EXPECT_EQ(r.trackCreepSlip(1), 0.0);
}

// ---- Treels friction of a level (treels.friction_scale) -------------------------------------------

/// How far [m] an s-bot holding (setSpeed(0, 0)) front uphill slides down a slope of `deg` (tilted
/// gravity) in 2 s after settling for 0.5 s, the track material's mu being `track_mu`.
double slidHolding(const RobotDescription& d, double deg, double track_mu) {
  WorldConfig c = flatWorld();
  c.contact.material_mu["track"] = track_mu;
  World w(c);
  const double a = deg * M_PI / 180;
  dWorldSetGravity(w.odeWorld(), -c.gravity * std::sin(a), 0, -c.gravity * std::cos(a));
  Robot& r = w.addRobot(d, {0, 0, 0}, "sbot_0");
  r.setSpeed(0, 0);
  runFor(w, 0.5);
  const double x0 = r.basePose().position.x();
  runFor(w, 2.0);
  return x0 - r.basePose().position.x();
}

TEST(TreelsFriction, TheLevelsScaleMultipliesTheTrackMaterialsMu) {
  // A Detailed s-bot holding (setSpeed(0, 0)) front uphill on 35 deg (tilted gravity) on a surface
  // where the track material's mu is 0.5 < tan 35 deg = 0.70: it slides; with the level's friction
  // scale at 2 (mu 1.0) it stands. Nothing else differs.
  double slid[2];
  for (int doubled : {0, 1}) {
    RobotDescription d = loadLevel("detailed");
    ASSERT_EQ(d.treels.friction_scale, 1.0) << "Detailed is the reference level";
    if (doubled) d.treels.friction_scale = 2.0;
    slid[doubled] = slidHolding(d, 35, 0.5);
  }
  EXPECT_GT(slid[0], 0.05) << "mu 0.5 on 35 deg";
  EXPECT_LT(slid[1], 0.005) << "mu 0.5 x 2 on 35 deg";
}

TEST(TreelsFriction, ForceLimitLawHoldsEachContactToAFixedForce) {
  // The seed's friction law (sidecar treels.friction_law: force_limit; Medium uses it, see
  // docs/model.md, "Friction"): each terrain contact holds up to
  // friction_force_limit whatever its load. A Medium s-bot holding (setSpeed(0, 0)) on 30 deg
  // needs 6.5 N x sin 30 = 3.2 N: its six spheres at 1.2 N each hold it, at 0.3 N each (1.8 N in
  // all) it slides; Coulomb (mu 1 > tan 30) holds.
  using Law = TreelsSemantics::FrictionLaw;
  auto slid = [](Law law, double limit) {
    RobotDescription d = loadLevel("medium");
    d.treels.friction_law = law;
    d.treels.friction_force_limit = limit;
    return slidHolding(d, 30, 1.0);
  };
  EXPECT_LT(slid(Law::Coulomb, 0.3), 0.01) << "the limit is ignored under Coulomb";
  EXPECT_LT(slid(Law::ForceLimit, 1.2), 0.01);
  EXPECT_GT(slid(Law::ForceLimit, 0.3), 0.05);
}

/// Records the first friction direction of every robot contact with the terrain: on faces (normal
/// within 17 deg of horizontal) and on the floor (normal within 17 deg of vertical).
class FrictionDirections : public Effect {
 public:
  std::string name() const override { return "friction_directions"; }
  void onContact(ContactContext& ctx, dSurfaceParameters&) override {
    if (ctx.fdir1.squaredNorm() == 0) return;
    if (std::abs(ctx.normal.z()) < 0.3) face.push_back(ctx.fdir1);
    if (std::abs(ctx.normal.z()) > 0.95) floor.push_back({ctx.fdir1, ctx.heading});
  }
  std::vector<Vec3> face;
  std::vector<std::pair<Vec3, Vec3>> floor;  // (fdir1, heading in the contact plane)
};

TEST(TreelsFriction, APyramidOnAFaceAheadRunsUpTheFace) {
  // ODE's friction pyramid bounds friction along each of its two directions separately, so along
  // its diagonal friction reaches 1.41 mu N. On a floor its first direction is the heading. On a
  // face the robot drives into, the heading's projection is only the remnant of a small yaw: a
  // direction that turned the pyramid about the face's normal and let a Detailed robot at mu 0.5
  // hold itself up a step's face on 0.69 N per 1 N pressed. The first direction is
  // the way the wheels roll instead: up the face, the heading on the floor.
  WorldConfig c = flatWorld();
  c.terrain.boxes.push_back({"wall", Vec3(0.20, 0, 0.1), Vec3(0.05, 1.0, 0.2), 0, 0, "wall"});
  World w(c);
  auto seen = std::make_shared<FrictionDirections>();
  w.addEffect(seen);
  Robot& r = w.addRobot(loadLevel("detailed"), {0, 0, 2.0 * M_PI / 180}, "sbot_0");  // 2 deg off square
  r.setSpeed(30, 30);
  runFor(w, 3.0);
  ASSERT_GT(seen->face.size(), 50u) << "the front wheels never pressed against the wall";
  for (const Vec3& d : seen->face) ASSERT_GT(std::abs(d.z()), 0.98) << "on the face: " << d.transpose();
  ASSERT_GT(seen->floor.size(), 100u);
  for (const auto& [d, heading] : seen->floor) ASSERT_GT(std::abs(d.dot(heading)), 0.999) << "on the floor";
}

TEST(TreelsFriction, OnlySimpleCalibratesItsOwn) {
  // The calibration is documented in sbot_parameters.yaml (simple.treels.friction_scale): Basic,
  // which must stand in for Medium and Detailed on the fly, and Fast keep the reference.
  for (const std::string level : {"fast", "basic", "medium", "detailed"})
    EXPECT_EQ(loadLevel(level).treels.friction_scale, 1.0) << level;
  EXPECT_EQ(loadLevel("simple").treels.friction_scale, 2.0);
}

}  // namespace
}  // namespace sbot::test
