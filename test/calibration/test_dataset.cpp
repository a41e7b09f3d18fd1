// Dataset format sbot-dataset/1: round trip, held commands, and bad datasets reported with file,
// line and column.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <fstream>

#include "calibration/dataset.h"
#include "calibration/replay.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot::calib {
namespace {

std::string tempDir(const std::string& name) {
  const std::string d = testing::TempDir() + "sbot_dataset_" + name;
  ::mkdir(d.c_str(), 0755);
  return d;
}

void write(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
}

const char* kYaml =
    "format: sbot-dataset/1\n"
    "name: test\n"
    "robot: simple\n"
    "world:\n"
    "  obstacles:\n"
    "    - {name: wall, center: [0.5, 0, 0.05], size: [0.02, 1, 0.1], yaw: 0, surface: white_paper}\n"
    "runs:\n"
    "  - {name: straight, file: straight.csv, kind: drive, initial_pose: {x: 0, y: 0, yaw: 0}}\n";

/// A dataset directory with kYaml (optionally edited) and one run file.
std::string makeDataset(const std::string& name, const std::string& csv, const std::string& yaml = kYaml) {
  const std::string d = tempDir(name);
  write(d + "/dataset.yaml", yaml);
  write(d + "/straight.csv", csv);
  return d;
}

DatasetError errorOf(const std::string& dir) {
  try {
    loadDataset(dir);
  } catch (const DatasetError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for " << dir;
  return DatasetError("", 0, 0, "", "");
}

TEST(Dataset, LoadsChannelsWithDifferentRatesAndHeldCommands) {
  const std::string d = makeDataset("ok",
                                    "t,cmd_left,cmd_right,x,y,yaw,speed_left\n"
                                    "0,20,20,0,0,0,\n"
                                    "0.05,,,0.001,0,0.01,20\n"
                                    "0.1,40,-40,,,,\n"
                                    "0.15,,,0.003,0.001,0.02,39\n");
  const Dataset ds = loadDataset(d);
  ASSERT_EQ(ds.runs.size(), 1u);
  const calib::Run& r = ds.runs[0];
  EXPECT_EQ(ds.robot, "simple");
  EXPECT_EQ(r.channels.at("x").v.size(), 3u);
  EXPECT_EQ(r.channels.at("speed_left").v.size(), 2u);
  EXPECT_DOUBLE_EQ(r.channels.at("speed_left").t[1], 0.15);
  EXPECT_EQ(r.commandAt(0.07), std::make_pair(20.0, 20.0));
  EXPECT_EQ(r.commandAt(0.12), std::make_pair(40.0, -40.0));
  EXPECT_EQ(r.commandAt(-1), std::make_pair(0.0, 0.0));
  ASSERT_EQ(ds.world.terrain.boxes.size(), 1u);
  EXPECT_EQ(ds.world.terrain.boxes[0].surface, "white_paper");
  EXPECT_EQ(r.group, "straight");
}

TEST(Dataset, WriteThenLoadRoundTrips) {
  Dataset ds;
  ds.name = "rt";
  ds.robot = "medium";
  calib::Run drive;
  drive.name = "arc_1";
  drive.kind = RunKind::Drive;
  drive.initial_pose = {0.1, -0.2, 0.3};
  drive.start_time = 42;
  drive.cmd_t = {0, 1.5};
  drive.cmd_left = {30, 0};
  drive.cmd_right = {50, 0};
  drive.channels["x"] = {{0.0, 1.0 / 30, 2.0 / 30}, {0.1, 0.11, 0.12}, {}};
  drive.channels["pitch"] = {{0.05, 0.15}, {0.01, -0.02}, {}};
  drive.t_end = 2;
  calib::Run place;
  place.name = "ir_wall";
  place.kind = RunKind::Place;
  place.placements = {{{0.3, 0, 0}, kNaN}, {{0.35, 0, 0.2}, 0.05}};
  place.channels["ir0"] = {{0, 1}, {1000, 50}, {}};
  ds.runs = {drive, place};
  ds.world.terrain.boxes.push_back({"w", Vec3(0.5, 0, 0.05), Vec3(0.02, 1, 0.1), 0.1, 0, "black_card"});
  const std::string d = tempDir("roundtrip");
  writeDataset(ds, d);
  const Dataset back = loadDataset(d);
  ASSERT_EQ(back.runs.size(), 2u);
  EXPECT_EQ(back.robot, "medium");
  EXPECT_DOUBLE_EQ(back.runs[0].start_time, 42);
  EXPECT_NEAR(back.runs[0].initial_pose.yaw, 0.3, 1e-9);
  EXPECT_EQ(back.runs[0].channels.at("x").v, drive.channels["x"].v);
  EXPECT_EQ(back.runs[0].channels.at("pitch").t.size(), 2u);
  EXPECT_EQ(back.runs[0].commandAt(2.0), std::make_pair(0.0, 0.0));
  EXPECT_EQ(back.runs[1].kind, RunKind::Place);
  ASSERT_EQ(back.runs[1].placements.size(), 2u);
  EXPECT_TRUE(std::isnan(back.runs[1].placements[0].z));
  EXPECT_DOUBLE_EQ(back.runs[1].placements[1].z, 0.05);
  EXPECT_EQ(back.runs[1].channels.at("ir0").v, (std::vector<double>{1000, 50}));
  EXPECT_EQ(back.world.terrain.boxes.at(0).surface, "black_card");
}

TEST(Dataset, MissingColumnNamesFileAndColumn) {
  const DatasetError e = errorOf(makeDataset("missing", "t,cmd_left,x\n0,1,0\n"));
  EXPECT_NE(e.file().find("straight.csv"), std::string::npos);
  EXPECT_EQ(e.columnName(), "cmd_right");
  EXPECT_EQ(e.line(), 1);
  EXPECT_NE(std::string(e.what()).find("straight.csv:1 (column 'cmd_right')"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("the header has t, cmd_left, x"), std::string::npos) << e.what();
}

TEST(Dataset, NonMonotonicTimeNamesLineAndColumn) {
  const DatasetError e = errorOf(makeDataset("time", "# comment\nx,t,cmd_left,cmd_right\n0,0,1,1\n0,0.2,,\n0,0.1,,\n"));
  EXPECT_EQ(e.line(), 5);
  EXPECT_EQ(e.column(), 2);
  EXPECT_EQ(e.columnName(), "t");
  EXPECT_NE(std::string(e.what()).find("straight.csv:5:2"), std::string::npos) << e.what();
}

TEST(Dataset, NaNAndGarbageCells) {
  DatasetError e = errorOf(makeDataset("nan", "t,cmd_left,cmd_right,x,yaw\n0,1,1,0,0\n0.1,,,0,nan\n"));
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.column(), 5);
  EXPECT_EQ(e.columnName(), "yaw");
  EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos);
  e = errorOf(makeDataset("garbage", "t,cmd_left,cmd_right,x\n0,1,1,0\n0.1,,,1.2.3\n"));
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.columnName(), "x");
  e = errorOf(makeDataset("cells", "t,cmd_left,cmd_right,x\n0,1,1\n"));
  EXPECT_EQ(e.line(), 2);
  e = errorOf(makeDataset("halfcmd", "t,cmd_left,cmd_right,x\n0,1,,0\n"));
  EXPECT_EQ(e.columnName(), "cmd_right");
  e = errorOf(makeDataset("unknowncol", "t,cmd_left,cmd_right,xx\n0,1,1,0\n"));
  EXPECT_EQ(e.columnName(), "xx");
  EXPECT_EQ(e.column(), 4);
  e = errorOf(makeDataset("range", "t,cmd_left,cmd_right,x\n0,200,1,0\n"));
  EXPECT_EQ(e.columnName(), "cmd_left");
  // Not to be read as 20 and as 20.5: a NUL byte inside a cell, and a command between API units,
  // which setSpeed cannot have been given.
  e = errorOf(makeDataset("nul", std::string("t,cmd_left,cmd_right,x\n0,20\0,1,0\n", 33)));
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("straight.csv:2: not a text CSV file: byte 5 of the line is 0x00"), std::string::npos)
      << e.what();
  // A binary file is refused as not text (not as an unknown column named by its raw bytes).
  std::string binary = "\x1f\x8b\x08";  // a gzip header
  for (int i = 0; i < 200; ++i) binary += static_cast<char>((i * 37) % 256);
  e = errorOf(makeDataset("binary", binary));
  EXPECT_EQ(e.line(), 1);
  EXPECT_EQ(e.columnName(), "");
  EXPECT_NE(std::string(e.what()).find("byte 1 of the line is 0x1f"), std::string::npos) << e.what();
  // A long unknown column name is shown cut to 40 characters (the error keeps it whole).
  e = errorOf(makeDataset("longname", "t,cmd_left,cmd_right," + std::string(100, 'q') + "\n0,1,1,0\n"));
  EXPECT_EQ(e.columnName(), std::string(100, 'q'));
  EXPECT_NE(std::string(e.what()).find("(column '" + std::string(40, 'q') + "...')"), std::string::npos) << e.what();
  // Tabs, CR LF ends and Latin-1 bytes in a user column are text.
  EXPECT_NO_THROW(loadDataset(makeDataset("text", "t,cmd_left,cmd_right,x,_note\r\n0,\t1,1,0,caf\xe9\r\n")));
  e = errorOf(makeDataset("halfunit", "t,cmd_left,cmd_right,x\n0,20.5,1,0\n"));
  EXPECT_EQ(e.columnName(), "cmd_left");
  EXPECT_NE(std::string(e.what()).find("command 20.5 is not a whole number of API units"), std::string::npos) << e.what();
}

TEST(Dataset, UnknownSurfaceNamesTheYamlLine) {
  std::string yaml = kYaml;
  yaml.replace(yaml.find("white_paper"), 11, "green_cheese");
  const DatasetError e = errorOf(makeDataset("surface", "t,cmd_left,cmd_right,x\n0,1,1,0\n", yaml));
  EXPECT_NE(e.file().find("dataset.yaml"), std::string::npos);
  EXPECT_EQ(e.line(), 6);
  EXPECT_GT(e.column(), 0);
  EXPECT_NE(std::string(e.what()).find("green_cheese"), std::string::npos);
  // ... unless the dataset declares it.
  const std::string d = makeDataset("surface_ok", "t,cmd_left,cmd_right,x\n0,1,1,0\n",
                                    "surfaces: [green_cheese]\n" + yaml);
  EXPECT_NO_THROW(loadDataset(d));
}

TEST(Dataset, WorldGravityAndStepAreKeptOrRefused) {
  // Written: used by the replays (and written back); absent: the level's own (Fast: 1/50 g).
  std::string yaml = kYaml;
  yaml.replace(yaml.find("world:\n"), 7, "world:\n  gravity: 1.62\n  step: 0.005\n");
  const Dataset moon = loadDataset(makeDataset("moon", "t,cmd_left,cmd_right,x\n0,1,1,0\n", yaml));
  EXPECT_TRUE(moon.world_sets_gravity);
  EXPECT_TRUE(moon.world_sets_step);
  EXPECT_DOUBLE_EQ(moon.world.gravity, 1.62);
  const WorldConfig replayed = replayWorldConfig(moon, loadLevel("simple"), ReplayOptions{});
  EXPECT_DOUBLE_EQ(replayed.gravity, 1.62) << "the replays use it";
  EXPECT_DOUBLE_EQ(replayed.step, 0.005);
  const std::string copy = tempDir("moon_copy");
  writeDataset(moon, copy);
  const Dataset again = loadDataset(copy);
  EXPECT_TRUE(again.world_sets_gravity);
  EXPECT_DOUBLE_EQ(again.world.gravity, 1.62);
  EXPECT_DOUBLE_EQ(again.world.step, 0.005);
  const Dataset plain = loadDataset(makeDataset("plain", "t,cmd_left,cmd_right,x\n0,1,1,0\n"));
  EXPECT_FALSE(plain.world_sets_gravity);
  EXPECT_FALSE(plain.world_sets_step);
  EXPECT_DOUBLE_EQ(replayWorldConfig(plain, loadLevel("fast"), ReplayOptions{}).gravity, loadLevel("fast").gravity)
      << "unwritten: the model level's";
  // The Fast level is scaled for 1/50 g: a dataset may not put it under 9.81.
  std::string fast = kYaml;
  fast.replace(fast.find("robot: simple"), 13, "robot: fast");
  fast.replace(fast.find("world:\n"), 7, "world:\n  gravity: 9.81\n");
  const DatasetError e = errorOf(makeDataset("fast_earth", "t,cmd_left,cmd_right,x\n0,1,1,0\n", fast));
  EXPECT_NE(std::string(e.what()).find("level fast is scaled for a gravity of 0.1962"), std::string::npos) << e.what();
}

TEST(Dataset, BadYaml) {
  std::string yaml = kYaml;
  yaml.replace(yaml.find("sbot-dataset/1"), 14, "sbot-dataset/7");
  EXPECT_EQ(errorOf(makeDataset("format", "t,cmd_left,cmd_right,x\n0,1,1,0\n", yaml)).line(), 1);
  yaml = kYaml;
  yaml.replace(yaml.find("straight.csv"), 12, "missing.csv");
  const DatasetError e = errorOf(makeDataset("file", "t,cmd_left,cmd_right,x\n0,1,1,0\n", yaml));
  EXPECT_EQ(e.line(), 8);
  EXPECT_NE(std::string(e.what()).find("missing.csv"), std::string::npos);
  yaml = kYaml;
  yaml.replace(yaml.find("kind: drive"), 11, "kind: dance");
  EXPECT_NE(std::string(errorOf(makeDataset("kind", "t,cmd_left,cmd_right,x\n0,1,1,0\n", yaml)).what()).find("dance"),
            std::string::npos);
  EXPECT_THROW(loadDataset("/nonexistent/dataset"), DatasetError);
}

// Input that would crash a replay, run it for hours or turn into wrong numbers: each is refused
// naming the file, line and column.
TEST(Dataset, ValuesNoReplayCanUseAreRefusedByPlace) {
  const std::string head = "t,cmd_left,cmd_right,x,ir0\n0,1,1,0,\n";
  struct Case {
    const char* name;
    std::string csv;
    int line;
    const char* column;
    const char* says;
  };
  const Case cases[] = {
      // a tracker stamp before the first command (a bag whose clocks differ): was a heap overwrite
      {"negative_t", "t,cmd_left,cmd_right,x\n-20,,,0\n0,1,1,0\n", 2, "x", "before the replay's start at t = 0"},
      {"epoch_t", "t,cmd_left,cmd_right,x\n1700000000,1,1,0\n1700000001,,,0\n", 3, "t", "are the times in seconds?"},
      {"gap", head + "0.1,,,0,\n100,,,0,\n", 4, "t", "a gap of 99.9 s"},
      {"hex", head + "0.1,,,0x10,\n", 3, "x", "not a number: '0x10'"},
      {"ir_range", head + "0.1,,,0,99999\n", 3, "ir0", "outside the range of ir0 [0, 8191]"},
      {"position_range", head + "0.1,,,1e300,\n", 3, "x", "outside the range of x"},
      {"no_sample", "t,cmd_left,cmd_right,x\n0,1,1,\n1,2,2,\n", 1, "", "no measured value in any row"},
      // a pull of 1e12 N was replayed (nRMS 3.7e7)
      {"force", "t,cmd_left,cmd_right,x,force_x\n0,1,1,0,1e12\n", 2, "force_x", "outside [-100, 100] N"},
  };
  for (const Case& c : cases) {
    const DatasetError e = errorOf(makeDataset(c.name, c.csv));
    EXPECT_EQ(e.line(), c.line) << c.name << ": " << e.what();
    EXPECT_EQ(e.columnName(), c.column) << c.name << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find(c.says), std::string::npos) << c.name << ": " << e.what();
  }
  // A run file that is a folder read as an empty stream ("empty file").
  std::string yaml = kYaml;
  yaml.replace(yaml.find("straight.csv"), 12, ".");
  const DatasetError folder = errorOf(makeDataset("folder", "t,cmd_left,cmd_right,x\n0,1,1,0\n", yaml));
  EXPECT_NE(std::string(folder.what()).find("is a folder, not a file"), std::string::npos) << folder.what();
  // A byte-order mark (spreadsheet export) is not part of the first column's name.
  EXPECT_NO_THROW(loadDataset(makeDataset("bom", "\xEF\xBB\xBFt,cmd_left,cmd_right,x\n0,1,1,0\n")));
}

// Milliseconds at a tracker's rate pass the row-gap and run-length limits (33 ms "gaps", a 2000 s
// "run"); the replay would then drive the robot for half an hour. Rows a second apart together with
// a robot that moved a thousandth of what its commands ask for give them away; either alone does not.
TEST(Dataset, MillisecondTimesAreRefusedAndSlowLoggersAreNot) {
  // 2 s at 30 Hz, setSpeed(20, 20) = 5.6 cm/s, the tracker noise-free: 11.2 cm.
  const auto run = [](double time_scale, double rate_hz, double speed) {
    std::string csv = "t,cmd_left,cmd_right,x,y\n";
    const int rows = static_cast<int>(2.0 * rate_hz);
    for (int i = 0; i <= rows; ++i) {
      const double t = i / rate_hz;
      csv += std::to_string(t * time_scale) + (i == 0 ? ",20,20," : ",,,") + std::to_string(speed * t) + ",0\n";
    }
    return csv;
  };
  const DatasetError e = errorOf(makeDataset("ms", run(1000, 30, 0.056)));
  EXPECT_EQ(e.line(), 62) << e.what();
  EXPECT_EQ(e.columnName(), "t") << e.what();
  EXPECT_NE(std::string(e.what()).find("are the times in milliseconds?"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("moved 0.112 m"), std::string::npos) << e.what();
  // The same run in seconds; a 1 Hz logger of a moving robot; a 30 Hz log of a robot pushing a wall.
  EXPECT_NO_THROW(loadDataset(makeDataset("s", run(1, 30, 0.056))));
  EXPECT_NO_THROW(loadDataset(makeDataset("slow_logger", run(1, 1, 0.056))));
  EXPECT_NO_THROW(loadDataset(makeDataset("wall", run(1, 30, 0.0))));
}

TEST(Dataset, RunNamesStartPosesAndSegmentsAreChecked) {
  const std::string csv = "t,cmd_left,cmd_right,x\n0,1,1,0\n";
  const auto withRun = [](const std::string& run) {
    std::string yaml = kYaml;
    const std::size_t at = yaml.find("  - {name: straight");
    return yaml.substr(0, at) + run;
  };
  // The name becomes a file name under the report's folder: no path may escape it.
  DatasetError e = errorOf(makeDataset(
      "name_path", csv, withRun("  - {name: ../../x, file: straight.csv, initial_pose: {x: 0, y: 0, yaw: 0}}\n")));
  EXPECT_NE(std::string(e.what()).find("must be a plain file name"), std::string::npos) << e.what();
  // Without a name, a run in a subfolder is named after its file alone.
  const std::string sub = makeDataset("subfolder", csv, withRun("  - {file: day1/straight.csv, initial_pose: {x: 0, y: 0, yaw: 0}}\n"));
  ::mkdir((sub + "/day1").c_str(), 0755);
  write(sub + "/day1/straight.csv", csv);
  EXPECT_EQ(loadDataset(sub).runs.at(0).name, "straight");
  // A start pose without its yaw is refused (not started at yaw 0).
  e = errorOf(makeDataset("pose", csv, withRun("  - {name: s, file: straight.csv, initial_pose: {x: 0, y: 0}}\n")));
  EXPECT_NE(std::string(e.what()).find("runs[0].initial_pose.yaw"), std::string::npos) << e.what();
  // A value of the wrong type names the file and line (was yaml-cpp's bare "bad conversion").
  e = errorOf(makeDataset("type", csv, withRun("  - {name: s, group: [a, b], file: straight.csv, initial_pose: {x: 0, y: 0, yaw: 0}}\n")));
  EXPECT_NE(e.file().find("dataset.yaml"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 8) << e.what();
  // Two runs naming one file (a copy-paste slip) replayed the first run's data from the second's
  // start pose; also when the second names it another way.
  e = errorOf(makeDataset("same_file", csv,
                          withRun("  - {name: a, file: straight.csv, initial_pose: {x: 0, y: 0, yaw: 0}}\n"
                                  "  - {name: b, file: ./straight.csv, initial_pose: {x: 1, y: 0, yaw: 0}}\n")));
  EXPECT_NE(std::string(e.what()).find("runs[1].file': './straight.csv' is already the file of run 'a'"), std::string::npos)
      << e.what();
  // Re-anchoring every 50 ms hid a 10 % speed error.
  e = errorOf(makeDataset("segment", csv, "align_segment: 0.05\n" + std::string(kYaml)));
  EXPECT_NE(std::string(e.what()).find("at least 1 s"), std::string::npos) << e.what();
  EXPECT_NO_THROW(loadDataset(makeDataset("segment_ok", csv, "align_segment: 0\n" + std::string(kYaml))));
  // A start the world cannot place is named here, with file and field, not by the first replay;
  // a start time of 1e300 s would drain the battery model at once.
  e = errorOf(makeDataset("far", csv, withRun("  - {name: s, file: straight.csv, initial_pose: {x: 1e9, y: 0, yaw: 0}}\n")));
  EXPECT_NE(std::string(e.what()).find("runs[0].initial_pose.x': value 1e+09 outside the range of x"), std::string::npos) << e.what();
  e = errorOf(makeDataset("spun", csv, withRun("  - {name: s, file: straight.csv, initial_pose: {x: 0, y: 0, yaw: 1e6}}\n")));
  EXPECT_NE(std::string(e.what()).find("runs[0].initial_pose.yaw"), std::string::npos) << e.what();
  e = errorOf(makeDataset("late", csv, withRun("  - {name: s, file: straight.csv, start_time: 1e300, "
                                                "initial_pose: {x: 0, y: 0, yaw: 0}}\n")));
  EXPECT_NE(std::string(e.what()).find("runs[0].start_time"), std::string::npos) << e.what();
}

// A robot measured inside a wall or below the floor is named, not replayed without a word (a
// drive start thrown out by the contacts, IR read from inside the wall).
TEST(Dataset, PlacesNoRobotCanHaveBeenMeasuredAtAreNamed) {
  const std::string drive_csv = "t,cmd_left,cmd_right,x\n0,1,1,0\n";
  const auto withRun = [](const std::string& run) {
    std::string yaml = kYaml;  // a wall 2 cm thick centred at x = 0.5 m, 1 m long, 10 cm high
    return yaml.substr(0, yaml.find("  - {name: straight")) + run;
  };
  const auto startAt = [&](double x) {
    return loadDataset(makeDataset("start_" + std::to_string(static_cast<int>(x * 1000)), drive_csv,
                                   withRun("  - {name: straight, file: straight.csv, initial_pose: {x: " + std::to_string(x) +
                                           ", y: 0, yaw: 0}}\n")));
  };
  EXPECT_EQ(impossiblePlacement(startAt(0.0), "simple"), "");
  EXPECT_EQ(impossiblePlacement(startAt(0.40), "simple"), "") << "a start beside the wall is a start";
  const std::string inside = impossiblePlacement(startAt(0.46), "simple");
  EXPECT_NE(inside.find("run 'straight', start pose (x 0.46 m"), std::string::npos) << inside;
  EXPECT_NE(inside.find("deep inside box 'wall'"), std::string::npos) << inside;

  // A start on a 20 deg ramp stands on it.
  const Dataset ramp = loadDataset(makeDataset(
      "ramp", drive_csv,
      "format: sbot-dataset/1\nname: ramp\nrobot: simple\nworld:\n  obstacles:\n"
      "    - {name: ramp, center: [0, 0, 0], size: [1, 1, 0.1], yaw: 0, pitch: 0.35, surface: white_paper}\n"
      "runs:\n  - {name: straight, file: straight.csv, kind: drive, initial_pose: {x: 0, y: 0, yaw: 0.5}}\n"));
  EXPECT_EQ(impossiblePlacement(ramp, "simple"), "");
  EXPECT_EQ(impossiblePlacement(ramp, "detailed"), "");

  const std::string d = makeDataset("placements", drive_csv,
                                    withRun("  - {name: held, file: held.csv, kind: place}\n"));
  write(d + "/held.csv", "x,y,yaw,z,ir0\n0.30,0,0,,100\n0.47,0,0,,100\n");
  const std::string into_wall = impossiblePlacement(loadDataset(d), "simple");
  EXPECT_NE(into_wall.find("run 'held', placement 2 (x 0.47 m"), std::string::npos) << into_wall;
  write(d + "/held.csv", "x,y,yaw,z,ir0\n0.30,0,0,0.2,100\n0.30,0,0,-0.05,100\n");
  const std::string below = impossiblePlacement(loadDataset(d), "simple");
  EXPECT_NE(below.find("placement 2 (x 0.3 m, y 0 m, yaw 0 rad, z -0.05 m)"), std::string::npos) << below;
  EXPECT_NE(below.find("deep inside the ground"), std::string::npos) << below;
  // The seed's IR points put a Medium's sensor 5 mm from the wall: a place, every one of them.
  EXPECT_EQ(impossiblePlacement(loadDataset(std::string(SWARMBOT3D_SOURCE_DIR) + "/datasets/seed_ir_response"), ""), "");
}

}  // namespace
}  // namespace sbot::calib
