// Sleeping at rest (rest.h): robots commanded to stand stop creeping, and everything that should
// move them still does.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "sbot_sim/core/actuators/connections.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

WorldConfig flatWorldWithSleep(bool sleep, std::uint64_t seed = 1) {
  WorldConfig c = flatWorld(seed);
  c.rest.enabled = sleep;
  return c;
}

double planarDistance(const Pose& a, const Pose& b) { return (a.position - b.position).head<2>().norm(); }

class RestEveryLevel : public ::testing::TestWithParam<const char*> {};

// Under quickstep, awake, a standing Simple slides 19 mm in 10 s, a Basic 14, a Medium 8
// (docs/model.md, "Sleeping at rest"); asleep, it does not move at all.
TEST_P(RestEveryLevel, AStandingRobotFallsAsleepAndStaysPut) {
  World w(flatWorld(3));
  Robot& r = w.addRobot(loadLevel(GetParam()), {0.1, -0.2, 2.5}, "sbot_0");
  runFor(w, 4.0);
  ASSERT_TRUE(r.asleep()) << GetParam() << " still awake after 4 s at setSpeed(0, 0)";
  const Pose before = r.basePose();
  runFor(w, 10.0);
  EXPECT_TRUE(r.asleep());
  EXPECT_LT(planarDistance(r.basePose(), before), 1e-6);
  EXPECT_LT(r.basePose().orientation.angularDistance(before.orientation), 1e-6);
  // It still stands on its wheels as it did (the loads of the last solved step are kept).
  EXPECT_GT(r.driveWheelLoad(), 0.0);
}

TEST_P(RestEveryLevel, WithSleepOffItIsSolvedEveryStep) {
  WorldConfig c = flatWorld(3);
  c.rest.enabled = false;
  World w(c);
  Robot& r = w.addRobot(loadLevel(GetParam()), {0, 0, 0}, "sbot_0");
  for (int i = 0; i < 40; ++i) {
    runFor(w, 0.25);
    ASSERT_FALSE(r.asleep());
  }
}

INSTANTIATE_TEST_SUITE_P(Levels, RestEveryLevel, ::testing::Values("fast", "simple", "basic", "medium", "detailed"));

// Twenty standing Simples at assorted headings (the level that rocks most on its two wheels) are
// all asleep within 1.5 s; with 2 mm / 2 deg limits one of them took 7 s.
TEST(Rest, ASwarmOfStandingSimplesFallsAsleepQuickly) {
  World w(flatWorld());
  std::vector<Robot*> robots;
  for (int i = 0; i < 20; ++i)
    robots.push_back(&w.addRobot(loadLevel("simple"), {0.25 * (i % 10), 0.25 * (i / 10), 0.3 * i}, "sbot_" + std::to_string(i)));
  runFor(w, 1.5);
  for (const Robot* r : robots) EXPECT_TRUE(r->asleep()) << r->name();
}

// Wakes on a track command and then drives exactly as a robot that never slept: the same speed.
TEST(Rest, ASpeedCommandWakesItAndItDrivesAsBefore) {
  auto speedAfterStart = [](bool sleep) {
    World w(flatWorldWithSleep(sleep, 5));
    Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
    runFor(w, 3.0);
    EXPECT_EQ(r.asleep(), sleep);
    r.setSpeed(30, 30);
    runFor(w, 1.0);
    EXPECT_FALSE(r.asleep());
    const Pose a = r.basePose();
    runFor(w, 2.0);
    return planarDistance(r.basePose(), a) / 2.0;
  };
  const double slept = speedAfterStart(true), never = speedAfterStart(false);
  EXPECT_NEAR(slept, 30 * 0.0028, 0.05 * 30 * 0.0028);
  EXPECT_NEAR(slept, never, 0.02 * never);
}

// setSpeed(0, 0) sent every step (as controllers do) keeps it asleep; a turret command wakes it.
TEST(Rest, RepeatedStopsKeepItAsleepATurretCommandWakesIt) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("basic"), {0, 0, 0}, "sbot_0");
  runFor(w, 3.0);
  ASSERT_TRUE(r.asleep());
  for (int i = 0; i < 100; ++i) {
    r.setSpeed(0, 0);
    r.setTurretRotation(0);
    w.step();
  }
  EXPECT_TRUE(r.asleep());
  r.setTurretRotation(45);  // 90 deg
  EXPECT_FALSE(r.asleep());
  runFor(w, 5.0);
  EXPECT_NEAR(r.turretAngle(), M_PI / 2, 0.03);
}

// A robot driving into a sleeping one pushes it. A sleeper's terrain contacts are not made, so the
// world wakes it as soon as the pusher's contact is made, before the terrain is collided: woken
// later (by ODE's island walk, mid-step) it would be solved for a step without its floor and drop.
TEST(Rest, ARobotDrivingIntoASleepingOnePushesItWithoutDroppingIt) {
  World w(flatWorld());
  Robot& sleeper = w.addRobot(loadLevel("simple"), {0.3, 0, 0}, "sleeper");
  Robot& pusher = w.addRobot(loadLevel("simple"), {0, 0, 0}, "pusher");
  runFor(w, 3.0);
  ASSERT_TRUE(sleeper.asleep());
  const Pose before = sleeper.basePose();
  pusher.setSpeed(40, 40);
  double fastest_fall = 0, lowest = before.position.z();
  for (int i = 0; i < 600; ++i) {
    w.step();
    fastest_fall = std::max(fastest_fall, -dBodyGetLinearVel(sleeper.baseBody())[2]);
    lowest = std::min(lowest, sleeper.basePose().position.z());
  }
  EXPECT_GT(sleeper.basePose().position.x() - before.position.x(), 0.05);
  // Pushed, not dropped: one step without its floor is g dt = 0.098 m/s downward.
  EXPECT_LT(fastest_fall, 0.03) << "the sleeper fell when it was woken";
  EXPECT_GT(lowest, before.position.z() - 0.001);
  EXPECT_NEAR(sleeper.basePose().position.z(), before.position.z(), 0.003);
}

// A chain of three robots, each holding the next (fixed joints, as the front gripper's), asleep
// together. When the first drives, the joints wake the others link by link before the terrain is
// collided, so none of them is solved a step without its floor.
TEST(Rest, ASleepingChainWakesLinkByLinkWithoutDropping) {
  World w(flatWorld());
  std::vector<Robot*> chain;
  for (int i = 0; i < 3; ++i)
    chain.push_back(&w.addRobot(loadLevel("simple"), {-0.16 * i, 0, 0}, "sbot_" + std::to_string(i)));
  for (int i = 0; i + 1 < 3; ++i)
    w.connections().connect(chain[i]->name(), chain[i]->baseBody(), chain[i + 1]->name(), chain[i + 1]->baseBody(),
                            Connection::FrontGripper);
  runFor(w, 3.0);
  for (const Robot* r : chain) ASSERT_TRUE(r->asleep()) << r->name();
  const double z0 = chain[2]->basePose().position.z(), x0 = chain[2]->basePose().position.x();
  chain[0]->setSpeed(30, 30);
  double fastest_fall = 0;
  for (int i = 0; i < 300; ++i) {
    w.step();
    for (const Robot* r : chain) {
      EXPECT_FALSE(r->asleep()) << r->name() << " asleep at step " << i;
      fastest_fall = std::max(fastest_fall, -dBodyGetLinearVel(r->baseBody())[2]);
    }
  }
  EXPECT_LT(fastest_fall, 0.03) << "a woken link fell";
  EXPECT_GT(chain[2]->basePose().position.x() - x0, 0.01) << "the last link was towed";
  EXPECT_NEAR(chain[2]->basePose().position.z(), z0, 0.003);
}

// Wake-ups of `robots` over `seconds` (a robot asleep one step and awake the next).
int wakeUps(World& w, const std::vector<Robot*>& robots, double seconds) {
  std::vector<bool> was(robots.size());
  for (std::size_t i = 0; i < robots.size(); ++i) was[i] = robots[i]->asleep();
  int wakes = 0;
  for (int s = 0; s < static_cast<int>(seconds / w.config().step); ++s) {
    w.step();
    for (std::size_t i = 0; i < robots.size(); ++i) {
      wakes += was[i] && !robots[i]->asleep();
      was[i] = robots[i]->asleep();
    }
  }
  return wakes;
}

// 25 standing Simples on a 5 x 5 grid 11.8 cm apart: the 11.4 cm turrets touch as the robots settle.
std::vector<Robot*> touchingCluster(World& w) {
  std::vector<Robot*> cluster;
  for (int i = 0; i < 25; ++i)
    cluster.push_back(&w.addRobot(loadLevel("simple"), {0.118 * (i % 5), 0.118 * (i / 5), 0.7 * i}, "sbot_" + std::to_string(i)));
  return cluster;
}

// Neighbours that touch and settle at different times fall asleep and stay asleep: a sleeper stands
// as a static body for a neighbour that is itself standing. Before, a settling neighbour woke it:
// in this cluster each robot was asleep 32 % of the steps, with 1366 wake-ups in 10 s.
TEST(Rest, TouchingNeighboursThatSettleAtDifferentTimesStayAsleep) {
  World w(flatWorld());
  const std::vector<Robot*> cluster = touchingCluster(w);
  runFor(w, 8.0);
  for (const Robot* r : cluster) EXPECT_TRUE(r->asleep()) << r->name();
  EXPECT_EQ(wakeUps(w, cluster, 3.0), 0);
}

// Whether the geoms of two robots touch, as the robot-robot pass would find it.
bool touching(const Robot& a, const Robot& b) {
  int contacts = 0;
  dSpaceCollide2(reinterpret_cast<dGeomID>(a.space()), reinterpret_cast<dGeomID>(b.space()), &contacts,
                 [](void* count, dGeomID g1, dGeomID g2) {
                   dContactGeom c;
                   *static_cast<int*>(count) += dCollide(g1, g2, 1, &c, sizeof c);
                 });
  return contacts > 0;
}

// Two sleepers' contacts would join no island, so the robot-robot pass does not make them (in a
// resting cluster of 100 they were 53 contact joints a step, half the step's time). A sleeper that
// a touch wakes is collided with its sleeping neighbours before the solve, so the robots it rests
// against wake in the same step, as ODE's island walk woke them while those contacts were made.
TEST(Rest, ASleepingClusterMakesNoContactsAndATouchWakesWhatItTouchesInTheSameStep) {
  World w(flatWorld());
  const std::vector<Robot*> cluster = touchingCluster(w);
  runFor(w, 8.0);
  w.enableProfile(true);
  runFor(w, 1.0);
  EXPECT_EQ(w.profile().contacts, 0u) << "contact joints made in 1 s of a cluster asleep";
  std::vector<std::pair<Robot*, Robot*>> touches;
  for (std::size_t i = 0; i < cluster.size(); ++i)
    for (std::size_t j = i + 1; j < cluster.size(); ++j)
      if (touching(*cluster[i], *cluster[j])) touches.emplace_back(cluster[i], cluster[j]);
  // Nudge a robot whose neighbour rests against a third: the third wakes only by the second pass.
  std::map<Robot*, int> degree;
  for (const auto& [a, b] : touches) ++degree[a], ++degree[b];
  Robot* nudged = nullptr;
  for (const auto& [a, b] : touches) {
    if (degree[b] >= 2) nudged = a;
    else if (degree[a] >= 2) nudged = b;
    if (nudged) break;
  }
  ASSERT_NE(nudged, nullptr) << "no three robots of the cluster rest against each other";
  dBodyAddForce(nudged->baseBody(), 0, 0, 0.01);  // wakes it
  w.step();
  for (const auto& [a, b] : touches)
    EXPECT_EQ(a->asleep(), b->asleep()) << a->name() << " and " << b->name() << " touch";
}

// A robot that drives into a neighbour that stands beside a sleeper pushes the sleeper as far as
// with sleep off. (The neighbour, just set down, is not standing yet here; in the next test it
// stands when the push starts.)
TEST(Rest, ARobotPushedIntoASleeperPushesIt) {
  const auto sleeperShift = [](bool sleep) {
    World w(flatWorldWithSleep(sleep));
    Robot& sleeper = w.addRobot(loadLevel("simple"), {0.232, 0, 0}, "sleeper");
    runFor(w, 3.0);
    EXPECT_EQ(sleeper.asleep(), sleep);
    const double x0 = sleeper.basePose().position.x();
    w.addRobot(loadLevel("simple"), {0.116, 0, 0}, "neighbour");
    w.addRobot(loadLevel("simple"), {0, 0, 0}, "pusher").setSpeed(40, 40);
    runFor(w, 3.0);
    EXPECT_FALSE(sleeper.asleep());
    return sleeper.basePose().position.x() - x0;
  };
  const double asleep = sleeperShift(true), solved = sleeperShift(false);
  ASSERT_GT(solved, 0.003);
  EXPECT_GT(asleep, 0.5 * solved) << "pushed " << asleep << " m against " << solved << " m with sleep off";
}

// Two Fast robots (33 g) that stood for 3 s on the floor, sleep at rest on or off: `sleeper` at
// x = sleeper_x, `neighbour` at x = 0.116 m.
struct StandingFastPair {
  StandingFastPair(bool sleep, double sleeper_x)
      : w(flatWorldWithSleep(sleep)),
        sleeper(w.addRobot(loadLevel("fast"), {sleeper_x, 0, 0}, "sleeper")),
        neighbour(w.addRobot(loadLevel("fast"), {0.116, 0, 0}, "neighbour")) {
    runFor(w, 3.0);
    EXPECT_EQ(sleeper.asleep(), sleep);
  }
  World w;
  Robot& sleeper;
  Robot& neighbour;
};

// A neighbour asleep 1.7 cm from a sleeper, woken by a pusher driving slower than
// Robot::kStandingSpeed, is shoved into the sleeper, which must move as far as with sleep off. The
// neighbour stands when the push starts (3 s since its last command, its bodies slow). Without
// World::releaseHeldBackContacts it would lean on the sleeper as on a wall (pushing it 0.047 m
// against 0.071 m); with Robot::standing asking for no move past the rest limits in 0.25 s, the
// shoved neighbour does not stand and this holds without the release too (docs/model.md,
// "Sleeping at rest"). (The two are Fast robots, 33 g: a Simple does not shove two of its own kind.)
TEST(Rest, ASleeperIsPushedThroughAStandingNeighbourThatADrivingRobotShoves) {
  const auto sleeperShift = [](bool sleep) {
    StandingFastPair pair(sleep, 0.19);
    EXPECT_EQ(pair.neighbour.asleep(), sleep);
    const double x0 = pair.sleeper.basePose().position.x();
    pair.w.addRobot(loadLevel("simple"), {0.02, 0, 0}, "pusher").setSpeed(10, 10);  // 2.8 cm/s
    bool stood_while_pushed = false;
    for (int i = 0; i < 300; ++i) {
      pair.w.step();
      stood_while_pushed = stood_while_pushed || pair.neighbour.standing();
    }
    if (sleep) {
      EXPECT_TRUE(stood_while_pushed) << "the neighbour must stand at some step of the push";
    }
    return pair.sleeper.basePose().position.x() - x0;
  };
  const double asleep = sleeperShift(true), solved = sleeperShift(false);
  ASSERT_GT(solved, 0.03);
  EXPECT_GT(asleep, 0.9 * solved) << "pushed " << asleep << " m against " << solved << " m with sleep off";
}

// A standing robot moved by something that is not a robot in contact (here a pull on a spring, as
// a user's drag or a gripper's would) wakes a sleeper it is moved into: having moved past the rest
// limits in the last Robot::kMovedRecently_s, it does not stand. Standing, it leaned on the sleeper
// as on a wall and the pull stalled until the spring had stretched 8 mm. The drag starts 2.5 s
// before the robots meet, past the 2 s in which the pull's own wake keeps the robot from standing.
TEST(Rest, ARobotDraggedIntoASleeperPushesItWithoutStalling) {
  struct Drag {
    double sleeper_shift;  ///< [m]
    double max_lag;        ///< [m] of the dragged robot behind the spring's end
  };
  const auto drag = [](bool sleep) {
    StandingFastPair pair(sleep, 0.223);
    World& w = pair.w;
    const Robot& sleeper = pair.sleeper;
    Robot& dragged = pair.neighbour;
    const double x0 = sleeper.basePose().position.x(), start = dragged.basePose().position.x();
    constexpr double kSpeed = 0.02, kStiffness = 50, kDamping = 2;  // [m/s], [N/m], [N s/m]
    Drag d{0, 0};
    for (int i = 1; i <= 500; ++i) {
      const double target = start + kSpeed * i * w.config().step;
      const double x = dragged.basePose().position.x(), v = dBodyGetLinearVel(dragged.baseBody())[0];
      dBodyAddForce(dragged.baseBody(), kStiffness * (target - x) - kDamping * (v - kSpeed), 0, 0);
      w.step();
      d.max_lag = std::max(d.max_lag, target - x);
    }
    d.sleeper_shift = sleeper.basePose().position.x() - x0;
    return d;
  };
  const Drag asleep = drag(true), solved = drag(false);
  ASSERT_GT(solved.sleeper_shift, 0.02);
  EXPECT_GT(asleep.sleeper_shift, 0.9 * solved.sleeper_shift);
  EXPECT_LT(asleep.max_lag, 2 * solved.max_lag) << "lagged " << asleep.max_lag << " m against " << solved.max_lag << " m with sleep off";
}

// Robots joined by static links fall asleep as one group and stay asleep: a sleeper jointed to an
// awake robot is woken, so links that settled at different times woke each other (20 standing
// chains of 5: 95 of 100 asleep at the end).
TEST(Rest, StandingChainsFallAsleepTogetherAndStayAsleep) {
  World w(flatWorld());
  std::vector<Robot*> robots;
  for (int c = 0; c < 4; ++c) {
    for (int j = 0; j < 5; ++j) {
      const std::string name = "sbot_" + std::to_string(5 * c + j);
      robots.push_back(&w.addRobot(loadLevel("simple"), {-0.147 * j, 0.4 * c, 0}, name));
      if (j > 0) swarm::createStaticLink(w, {name, "sbot_" + std::to_string(5 * c + j - 1), swarm::kFrontGripper});
    }
    robots[5 * c]->setTurretRotation(5);  // its leader turns 10 deg and settles after the others
  }
  runFor(w, 6.0);
  for (const Robot* r : robots) EXPECT_TRUE(r->asleep()) << r->name();
  EXPECT_EQ(wakeUps(w, robots, 3.0), 0);
}

// One Simple on the flat floor, asleep after 3 s of standing.
class SleepingSimple : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(r.asleep()); }
  static Robot& standFor3s(World& world) {
    Robot& robot = world.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");
    runFor(world, 3.0);
    return robot;
  }
  World w{flatWorld()};
  Robot& r = standFor3s(w);
};

// An external force (a user's push, the calibration workbench's pull) wakes it.
TEST_F(SleepingSimple, AnExternalForceWakesIt) {
  const Pose before = r.basePose();
  for (int i = 0; i < 100; ++i) {
    dBodyAddForce(r.baseBody(), 0, 20.0, 0);  // sideways, above the treels' grip (mu 2 x 6.5 N)
    w.step();
  }
  EXPECT_FALSE(r.asleep());
  EXPECT_GT(planarDistance(r.basePose(), before), 0.01);
}

// Tilting gravity (the slope experiments do) wakes it, and a robot that slides never falls asleep.
TEST_F(SleepingSimple, TiltedGravityWakesItAndASlidingRobotStaysAwake) {
  const Pose before = r.basePose();
  const double g = w.config().gravity, a = 50 * M_PI / 180;  // past its 31 deg sliding angle
  dWorldSetGravity(w.odeWorld(), -g * std::sin(a), 0, -g * std::cos(a));
  for (int i = 0; i < 20; ++i) {
    runFor(w, 0.1);
    EXPECT_FALSE(r.asleep()) << "at " << w.time() << " s";
  }
  EXPECT_LT(r.basePose().position.x() - before.position.x(), -0.05);
}

// Standing on a 20 deg slope its motors hold it and it sleeps; released (passive treels: only the
// gears' 1.2 N back-drive friction against 2.2 N downhill) it must roll down.
TEST(Rest, ReleasingTheTracksOfARobotAsleepOnASlopeLetsItRoll) {
  World w(flatWorld());
  const double g = w.config().gravity, a = 20 * M_PI / 180;
  dWorldSetGravity(w.odeWorld(), -g * std::sin(a), 0, -g * std::cos(a));
  Robot& r = w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot_0");  // facing uphill: downhill is -x
  runFor(w, 3.0);
  ASSERT_TRUE(r.asleep());
  const Pose before = r.basePose();
  r.setTracksPassive(true);
  runFor(w, 2.0);
  EXPECT_FALSE(r.asleep());
  EXPECT_LT(r.basePose().position.x() - before.position.x(), -0.05);
}

// Moving a sleeping robot by hand (setBasePose, the scenario tools) wakes it: it falls back down.
TEST_F(SleepingSimple, TeleportingASleepingRobotWakesIt) {
  Pose up = r.basePose();
  up.position.z() += 0.05;
  r.setBasePose(up);
  runFor(w, 1.0);
  EXPECT_LT(r.basePose().position.z(), up.position.z() - 0.04);  // it fell back onto the floor
}

}  // namespace
}  // namespace sbot::test
