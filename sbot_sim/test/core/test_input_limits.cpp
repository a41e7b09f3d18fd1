// Bad input is refused by name, never by a signal: special and oversized files (input_file.h), the
// geometry limits (input_limits.h; the scenario fields' ranges and YAML null: test_scenario.cpp), and ODE's own
// errors ending the run with a message naming the step, robot and body (src/core/ode_errors.h).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include <ode/ode.h>

#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace {

/// What loading `path` with `load` says, and that it said so within seconds.
template <class Load>
std::string refusalOf(const std::string& path, Load load) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string what;
  try {
    load(path);
  } catch (const ConfigError& e) {
    what = e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0) << path;
  return what;
}

std::string tempPath(const std::string& name) { return testing::TempDir() + "input_limits_" + name; }

TEST(InputFile, SpecialFilesAreRefusedNamingThePath) {
  const std::string fifo = tempPath("fifo");
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string dir = tempPath("dir");
  ::mkdir(dir.c_str(), 0700);
  const auto scenario = [](const std::string& p) { loadScenario(p); };
  const auto effects = [](const std::string& p) { loadEffectsConfig(p); };
  for (const std::string& path : {std::string("/dev/zero"), fifo}) {
    for (const std::string& e : {refusalOf(path, scenario), refusalOf(path, effects)}) {
      EXPECT_NE(e.find(path + ": is not a regular file"), std::string::npos) << e;
    }
  }
  EXPECT_NE(refusalOf(dir, scenario).find(dir + ": is a folder, not a scenario file"), std::string::npos);
  EXPECT_NE(refusalOf("/nonexistent/x.yaml", scenario).find("/nonexistent/x.yaml: cannot open scenario file (No such file or directory)"), std::string::npos);
  ::unlink(fifo.c_str());
}

TEST(InputFile, AFileAboveTheLimitIsRefusedAndOneBelowIsRead) {
  const std::string big = tempPath("big.yaml");
  {
    const int fd = ::open(big.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, static_cast<off_t>(kMaxInputFileBytes) + 1), 0);  // sparse: no disk used
    ::close(fd);
  }
  const std::string e = refusalOf(big, [](const std::string& p) { readInputFile(p); });
  EXPECT_NE(e.find(big + ": is 256 MiB, larger than the 256 MiB an input file may have"), std::string::npos) << e;
  ::unlink(big.c_str());
  const std::string small = tempPath("small.yaml");
  std::ofstream(small) << "seed: 3\n";
  EXPECT_EQ(readInputFile(small), "seed: 3\n");
  EXPECT_EQ(inputFileProblem(small), "");
}

TEST(GeometryLimits, UrdfShapesAndBoxesBuiltDirectlyAreRefusedTooSmall) {
  EXPECT_NE(geomSizeProblem(1e-20), "");
  EXPECT_NE(geomSizeProblem(std::nan("")), "");
  EXPECT_EQ(geomSizeProblem(kMinGeomSize), "");
  WorldConfig c;
  c.terrain.boxes.push_back({"thin", Vec3(0.3, 0, 0.05), Vec3(1e-20, 0.6, 0.1), 0, 0, "ground"});
  try {
    World w(c);
    ADD_FAILURE() << "a 1e-20 m box was built";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("terrain.boxes (thin)"), std::string::npos) << e.what();
  }
}

// A robot driven into the thinnest box accepted: the contacts stay well defined (a 1e-20 m box made
// ODE fail !bSafeNormalize3Fault and abort).
TEST(GeometryLimits, ARobotDrivesIntoTheThinnestBoxAccepted) {
  const Scenario s = parseScenario(R"(
world: {terrain: {type: composite, boxes: [{name: thin, center: [0.12, 0, 0.05], size: [1e-4, 0.6, 0.1]}]}}
robots: [{name: a, level: simple, pose: {x: 0, y: 0, yaw: 0}}]
)", "thin.yaml");
  World w(s.world);
  Robot& r = w.addRobot(loadLevel("simple"), s.robots[0].pose, "a");
  r.setSpeed(60, 60);
  w.stepN(static_cast<int>(3.0 / s.world.step));
  EXPECT_TRUE(r.basePose().position.allFinite());
}

/// An effect whose contact hook makes an ODE call ODE refuses (a plane has no position).
class BreaksOde : public Effect {
 public:
  std::string name() const override { return "breaks_ode"; }
  void onContact(ContactContext&, dSurfaceParameters&) override {
    dGeomSetPosition(dCreatePlane(nullptr, 0, 0, 1, 0), 1, 2, 3);
  }
};

TEST(OdeErrors, AnOdeErrorInAStepEndsTheRunNamingStepRobotAndBody) {
  EXPECT_EXIT(
      {
        WorldConfig c;
        World w(c);
        w.addRobot(loadLevel("simple"), Pose2D{0, 0, 0}, "sbot_7");
        w.addEffect(std::make_shared<BreaksOde>());
        w.stepN(5);
      },
      testing::ExitedWithCode(1),
      "ODE (error|internal check failed) \\([0-9]+\\) at step [0-9]+ \\(t = [0-9.]+ s\\), colliding (robot 'sbot_7' link '[a-z_]+' \\(body at .*\\)"
      " with terrain 'ground_plane'|terrain 'ground_plane' with robot 'sbot_7' link).*: geom must be placeable in "
      "dGeomSetPosition\\(\\); ending the run \\(exit status 1\\)");
}

TEST(OdeErrors, OutsideAStepTooTheRunEndsWithStatusOneNotAnAbort) {
  EXPECT_EXIT(
      {
        WorldConfig c;
        World w(c);
        dGeomSetPosition(dCreatePlane(nullptr, 0, 0, 1, 0), 1, 2, 3);
      },
      testing::ExitedWithCode(1), "ODE (error|internal check failed) \\([0-9]+\\) outside a world step .*geom must be placeable");
}

}  // namespace
}  // namespace sbot
