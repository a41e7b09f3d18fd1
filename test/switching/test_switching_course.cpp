// Seed 4.3 on the composite course (config/scenarios/composite_course_switching.yaml): one run with
// the Detailed model only and one with dynamic model switching. The switched run reaches the goal,
// ends within 5 cm of the Detailed run, uses every level, spends most of its time in Basic, and costs
// less CPU. (The 10+10-run comparison with timing: switching_experiment, docs/swarm.md.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

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

// A route file is checked like every other input: it was read with bare yaml-cpp calls ("bad file",
// "bad conversion", NaN waypoints taken).
TEST(SwitchingCourse, ARouteFileIsCheckedByField) {
  const std::string path = "/tmp/sbot_route_test.route.yaml";
  const auto errorOf = [&](const std::string& text) {
    std::ofstream(path) << text;
    try {
      switching::loadRoute(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::pair<std::string, std::string> cases[] = {
      {"waypoints: [[0, 0], [1, .nan]]", "field 'waypoints[1]': must be finite"},
      {"waypoints: [[0, 0], [1]]", "field 'waypoints[1]': expected [x, y] in m"},
      {"waypoints: [[0, 0]]", "needs at least two waypoints"},
      {"waypoints: [[0, 0], [1, 0]]\ngoal_radius: -1", "field 'goal_radius': must be > 0 m"},
      {"waypoints: [[0, 0], [1, 0]]\ntime_limt: 5", "field 'time_limt': unknown field"},
      {"waypoints: [[0, 0], [1, x]]", "field 'waypoints[1]': expected a number"},
      {"waypoints: &w [*w]", "recursive YAML is refused"},
  };
  for (const auto& [text, says] : cases) {
    const std::string e = errorOf(text);
    EXPECT_NE(e.find(path), std::string::npos) << text << ": " << e;
    EXPECT_NE(e.find(says), std::string::npos) << text << ": " << e;
  }
  EXPECT_EQ(errorOf("waypoints: [[0, 0], [1, 0]]\ngoal_radius: 0.1"), "");
  std::remove(path.c_str());
  try {
    switching::loadRoute("/nonexistent.route.yaml");
    ADD_FAILURE() << "a missing route file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open route file"), std::string::npos) << e.what();
  }
}

}  // namespace
