// World::enableProfile: the step's wall time split by phase (the "what limits it" table of the
// validation report's Table 4.4 and of sbot_bench --profile).
#include <gtest/gtest.h>

#include <chrono>

#include "sim_fixture.h"

namespace sbot::test {
namespace {

Vec3 endOfDrive(bool profiling) {
  World w(flatWorld(3));
  Robot& r = w.addRobot(loadLevel("medium"), {0, 0, 0.3}, "sbot");
  w.enableProfile(profiling);
  r.setSpeed(40, 20);
  runFor(w, 3.0);
  return r.basePose().position;
}

TEST(WorldProfile, OffByDefaultButContactsAreCounted) {
  World w(flatWorld());
  w.addRobot(loadLevel("simple"), {0, 0, 0}, "sbot");
  runFor(w, 0.5);
  const World::StepProfile& p = w.profile();
  EXPECT_EQ(p.total_s(), 0.0) << "no clock is read unless profiling is on";
  EXPECT_EQ(p.steps, 50u);
  EXPECT_GT(p.contacts, 50u) << "a robot resting on the floor touches it every step";
}

TEST(WorldProfile, PhasesAddUpToNoMoreThanTheWallTime) {
  World w(flatWorld());
  Robot& r = w.addRobot(loadLevel("detailed"), {0, 0, 0}, "sbot");
  runFor(w, 0.2);
  w.enableProfile(true);
  EXPECT_EQ(w.profile().steps, 0u) << "enabling resets the profile";
  r.setSpeed(30, 30);
  const auto t0 = std::chrono::steady_clock::now();
  w.stepN(100);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const World::StepProfile& p = w.profile();
  EXPECT_EQ(p.steps, 100u);
  EXPECT_GT(p.solver_s, 0.0);
  EXPECT_GT(p.collision_s, 0.0);
  EXPECT_GT(p.commands_s, 0.0);
  EXPECT_GT(p.feedback_s, 0.0);
  EXPECT_LE(p.total_s(), wall);
  // 22 bodies and six teethed wheels: the solver, not collision detection, takes most of the time.
  EXPECT_GT(p.solver_s, p.collision_s);
  // Six wheels on the floor, each a cylinder with teeth: several contacts per step.
  EXPECT_GT(static_cast<double>(p.contacts) / static_cast<double>(p.steps), 4.0);
}

TEST(WorldProfile, ProfilingDoesNotChangeThePhysics) {
  const Vec3 a = endOfDrive(false);
  const Vec3 b = endOfDrive(true);
  EXPECT_EQ(a.x(), b.x());  // bit-identical, not merely close
  EXPECT_EQ(a.y(), b.y());
  EXPECT_GT(a.head<2>().norm(), 0.1) << "the robot drove";
}

}  // namespace
}  // namespace sbot::test
