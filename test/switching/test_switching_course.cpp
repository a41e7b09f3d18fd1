// Seed 4.3 on the composite course (config/scenarios/composite_course_switching.yaml): one run with
// the Detailed model only and one with dynamic model switching. The switched run reaches the goal,
// ends within 5 cm of the Detailed run, uses every level, spends most of its time in Basic, and costs
// less CPU. (The 10+10-run comparison with timing: switching_experiment, docs/swarm.md.)
#include <gtest/gtest.h>

#include <cmath>

#include "course_run.h"
#include "sbot_sim/core/robot_description.h"

namespace {

TEST(SwitchingCourse, SwitchedRunMatchesDetailedRun) {
  const std::string scenario = sbot::descriptionDirectory() + "/../config/scenarios/composite_course_switching.yaml";
  const sbot::Scenario sc = sbot::loadScenario(scenario);
  const switching::Route route = switching::loadRoute(scenario.substr(0, scenario.size() - 5) + ".route.yaml");
  switching::CourseRunConfig config;
  const switching::RunResult d = switching::runCourse(config, sc, route, "detailed", 0);
  const switching::RunResult s = switching::runCourse(config, sc, route, "switching", 0);
  std::printf("detailed: %s, CPU %.3f s, final (%.4f, %.4f)\nswitching: %s, CPU %.3f s, final (%.4f, %.4f), "
              "%d switches, basic %.1f s, medium %.1f s, detailed %.1f s\n",
              d.end.c_str(), d.cpu, d.x, d.y, s.end.c_str(), s.cpu, s.x, s.y, s.switches, s.level_time.at("basic"),
              s.level_time.at("medium"), s.level_time.at("detailed"));
  ASSERT_TRUE(d.reached) << d.end;
  ASSERT_TRUE(s.reached) << s.end;
  EXPECT_LT(std::hypot(s.x - d.x, s.y - d.y), 0.05);
  EXPECT_GE(s.switches, 6);  // three gaps, a slope, two rough fields: in and out
  EXPECT_GT(s.level_time.at("basic"), 0.5 * s.sim);
  EXPECT_GT(s.level_time.at("medium"), 0.0);
  EXPECT_GT(s.level_time.at("detailed"), 0.0);
  EXPECT_LT(s.level_time.at("detailed"), 0.2 * s.sim);
  EXPECT_LT(s.cpu, d.cpu);  // loose: CPU time of one run on a shared machine
}

}  // namespace
