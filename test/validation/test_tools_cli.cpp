// The headless tools' options (sbot_validate, switching_experiment, two_sbots; sbot_sim/tools/cli_args.h):
// a missing value, or a value that is not a number in range, is refused with exit status 2 and a
// message that names the option and what was found (atoi/atof would turn "abc" into a silent 0 runs
// or trials); and the machine they name beside their figures (sbot_sim/tools/machine.h).
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../common/run_process.h"
#include "sbot_sim/tools/machine.h"

namespace {

using Outcome = sbot_test::ProcessOutcome;

Outcome run(const std::string& tool, const std::string& args) {
  return sbot_test::runProcess(std::string(SWARMBOT3D_BIN_DIR) + "/" + tool + " " + args);
}

void expectRefused(const std::string& tool, const std::string& args, const std::string& message) {
  const Outcome o = run(tool, args);
  EXPECT_EQ(o.status, 2) << tool << " " << args << ": " << o.output;
  EXPECT_NE(o.output.find(message), std::string::npos) << tool << " " << args << ": " << o.output;
}

TEST(ToolsCli, NonNumbersAndOutOfRangeValuesAreRefusedByName) {
  expectRefused("sbot_validate", "--out " + testing::TempDir() + "cli --trials abc", "--trials expects a number in [1, 1000], found 'abc'");
  expectRefused("sbot_validate", "--trial step detailed x", "--trial step detailed (step height, m) expects a number");
  // Each trial kind checks its parameter against its own unit and range.
  expectRefused("sbot_validate", "--trial gap medium -0.01", "--trial gap medium (gap width, m) expects a number in [0, 0.3], found '-0.01'");
  expectRefused("sbot_validate", "--trial uphill fast 2", "--trial uphill fast (ramp angle, rad) expects a number in [0, 1.5], found '2'");
  expectRefused("sbot_validate", "--trial bogus detailed 1", "found 'bogus'");
  expectRefused("sbot_validate", "--index -1 --trial gap fast 0.03", "--index expects a number in [0, 999], found '-1'");
  expectRefused("sbot_validate", "--track-mu slippery --trial step detailed 0.02", "--track-mu expects a number in [1e-06, 100], found 'slippery'");
  expectRefused("switching_experiment", "--runs 0", "--runs expects a number in [1, 1000], found '0'");
  expectRefused("switching_experiment", "--small-gap-max nan", "--small-gap-max expects a number");
  expectRefused("two_sbots", "--angles 10,x", "--angles expects a number in [0, 90], found 'x'");
  expectRefused("two_sbots", "--trials 2.5", "--trials expects a whole number, found '2.5'");
  expectRefused("two_sbots", "--track-mu -1", "--track-mu expects a number");
  expectRefused("two_sbots", "--seed-friction --track-mu 1", "--seed-friction and --track-mu choose the friction law two ways");
  expectRefused("two_sbots", "--level huge", "two_sbots: --level huge (or $SBOT_DESCRIPTION_DIR): unknown model level 'huge'");  // aborted
  expectRefused("sbot_validate", "--trial step huge 0.01", "sbot_validate: --trial step huge: unknown model level 'huge'");  // aborted
}

// sbot_bench (package sbot_sim) reads the same way, and runs no rows of 0 robots or 0 seconds.
TEST(ToolsCli, BenchRefusesWhatItCannotRun) {
  const auto refused = [](const std::string& args, const std::string& message) {
    const Outcome o = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " " + args);
    EXPECT_EQ(o.status, 2) << args << ": " << o.output;
    EXPECT_NE(o.output.find(message), std::string::npos) << args << ": " << o.output;
  };
  refused("--robots 1,0", "sbot_bench: --robots expects a number in [1, 10000], found '0'");
  refused("--seconds -1", "sbot_bench: --seconds expects a number in [0.001, 1e+06], found '-1'");
  refused("--chains x", "sbot_bench: --chains expects a number");
  refused("--level huge", "sbot_bench: --level: unknown model level 'huge'");
  refused("--seconds", "sbot_bench: --seconds needs a value");
  // A step of 1e-9 s sized per-robot buffers past the machine's memory; 0x10 read as 16.
  refused("--step 1e-9", "sbot_bench: --step expects a number in [0.0001, 0.5], found '1e-9'");
  refused("--seconds 0x10", "sbot_bench: --seconds expects a number in [0.001, 1e+06], found '0x10'");
  refused("--scenario /nonexistent/s.yaml", "sbot_bench: --scenario: /nonexistent/s.yaml: cannot open scenario file");
  refused("--scenario s.yaml --chains 2", "with --scenario the scenario sets its levels, step and links");
}

// --scenario: the row is the scenario's own world, robots and levels (not the arena's Simple s-bots),
// and --robots overrides its swarm.count (the listed robots stay).
TEST(ToolsCli, BenchRunsAScenarioFile) {
  const std::string file = testing::TempDir() + "bench_scenario.yaml";
  std::ofstream(file) << "world: {terrain: {type: plane, arena: {size: 2.0, height: 0.1}}}\n"
                         "robots:\n"
                         "  - {name: a, level: simple, pose: {x: 0, y: 0, yaw: 0}}\n"
                         "  - {name: b, level: basic, pose: {x: 0.4, y: 0, yaw: 0}}\n"
                         "swarm: {count: 4, level: simple, layout: grid, spacing: 0.3, center: [0, 0.5]}\n";
  const auto row = [](const std::string& output) {  // the line after the column header
    const std::size_t header = output.find("peak_MiB\n");
    return header == std::string::npos ? std::string() : output.substr(header + 9, output.find('\n', header + 9) - header - 9);
  };
  const Outcome own = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --scenario " + file + " --seconds 0.2");
  ASSERT_EQ(own.status, 0) << own.output;
  std::istringstream r(row(own.output));
  std::string level;
  int robots = 0;
  double sim_s = 0;
  r >> level >> robots >> sim_s;
  EXPECT_EQ(level, "mixed") << own.output;
  EXPECT_EQ(robots, 6) << own.output;  // two explicit, four of the swarm block
  EXPECT_NEAR(sim_s, 0.2, 0.011) << own.output;
  const Outcome fewer = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --scenario " + file + " --robots 1 --seconds 0.1");
  ASSERT_EQ(fewer.status, 0) << fewer.output;
  std::istringstream f(row(fewer.output));
  f >> level >> robots;
  EXPECT_EQ(robots, 3) << fewer.output;  // the two listed and one of the swarm block
}

// One exit status rule (sbot_sim/tools/cli_args.h): 2 for bad input refused before any row, 1 for a
// failure during the work, 3 for a worker that crashed, named as a crash with its signal.
TEST(ToolsCli, BenchExitStatusesFollowOneRule) {
  const std::string bench = SBOT_BENCH_BIN;
  // --robots 1 builds only the first robot; the second, at y = 1e20, is refused all the same, before the header.
  const std::string far = testing::TempDir() + "bench_far_robot.yaml";
  std::ofstream(far) << "robots:\n  - {name: a, level: simple}\n  - {name: b, level: simple, pose: {x: 0, y: 1e20}}\n";
  const Outcome o = sbot_test::runProcess(bench + " --scenario " + far + " --robots 1 --seconds 0.1");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("field 'robots[1].pose': position (0, 1e+20, 0) m is outside the simulated space"), std::string::npos)
      << o.output;
  EXPECT_EQ(o.output.find("peak_MiB"), std::string::npos) << "refused before any row: " << o.output;
  // Degenerate geometry: refused at load time, not by ODE aborting the run.
  const std::string thin = testing::TempDir() + "bench_thin_box.yaml";
  std::ofstream(thin) << "world: {terrain: {type: composite, boxes: [{center: [0.3, 0, 0.05], size: [1e-20, 0.6, 0.1]}]}}\n"
                         "robots: [{name: a, level: simple}]\n";
  const Outcome t = sbot_test::runProcess(bench + " --scenario " + thin + " --seconds 0.1");
  EXPECT_EQ(t.status, 2) << t.output;
  EXPECT_NE(t.output.find("field 'world.terrain.boxes[0].size': every edge must be in [0.0001"), std::string::npos) << t.output;
  // A worker killed by a signal: exit status 3 and the signal named, not 1 like a refusal.
  const Outcome k = sbot_test::runProcess(
      "sh -c '" + bench + " --robots 1 --seconds 100000 & P=$!; C=; for i in $(seq 200); do C=$(pgrep -P $P); "
      "[ -n \"$C\" ] && break; sleep 0.05; done; sleep 0.3; kill -9 $C; wait $P'");
  EXPECT_EQ(k.status, 3) << k.output;
  EXPECT_NE(k.output.find("sbot_bench: the run with 1 robots crashed: killed by signal 9 (Killed)"), std::string::npos) << k.output;
}

// A benchmark figure names the machine it was measured on: the first processor's model and BogoMIPS
// from /proc/cpuinfo, and the online cores (a field the file lacks is left out, not guessed).
TEST(ToolsCli, TheMachineIsNamedFromCpuinfo) {
  std::istringstream x86(
      "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 7B13 64-Core Processor\n"
      "cpu MHz\t\t: 2445.404\nbogomips\t: 4890.80\n\n"
      "processor\t: 1\nmodel name\t: another model\nbogomips\t: 1.00\n");
  EXPECT_EQ(sbot_tools::describeProcessor(x86, 2), "AMD EPYC 7B13 64-Core Processor, 2 cores, BogoMIPS 4890.80");
  std::istringstream arm("processor\t: 0\nBogoMIPS\t: 50.00\r\nFeatures\t: fp asimd\nCPU implementer\t: 0x41\n");
  EXPECT_EQ(sbot_tools::describeProcessor(arm, 1), "unknown processor, 1 core, BogoMIPS 50.00");
  std::istringstream none("");
  EXPECT_EQ(sbot_tools::describeProcessor(none, 0), "unknown processor");
  // sbot_bench prints it above its rows.
  const Outcome o = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --robots 1 --seconds 0.1");
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("sbot_bench: machine: " + sbot_tools::describeThisMachine() + "\n"), std::string::npos)
      << o.output;
}

// --idle: the robots stand, fall asleep in the untimed settling, and only --seconds are timed; a
// scenario that turns sleeping off keeps them in the solve.
TEST(ToolsCli, BenchIdleRowsTimeStandingRobots) {
  const Outcome asleep = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --idle --robots 3 --seconds 0.5");
  ASSERT_EQ(asleep.status, 0) << asleep.output;
  EXPECT_NE(asleep.output.find("flat arena, idle"), std::string::npos) << asleep.output;
  std::istringstream r(asleep.output.substr(asleep.output.find("peak_MiB\n") + 9));
  std::string level;
  int robots = 0;
  double sim_s = 0;
  r >> level >> robots >> sim_s;
  EXPECT_EQ(robots, 3) << asleep.output;
  EXPECT_NEAR(sim_s, 0.5, 0.011) << "the settling is not timed: " << asleep.output;
  EXPECT_NE(asleep.output.find("idle, 3 asleep at the end"), std::string::npos) << asleep.output;
  const std::string file = testing::TempDir() + "bench_awake.yaml";
  std::ofstream(file) << "world: {sleep_at_rest: false, terrain: {type: plane, arena: {size: 2.0, height: 0.1}}}\n"
                         "swarm: {count: 2, level: simple, layout: grid, spacing: 0.3}\n";
  const Outcome awake = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --idle --scenario " + file + " --seconds 0.2");
  ASSERT_EQ(awake.status, 0) << awake.output;
  EXPECT_NE(awake.output.find("idle, 0 asleep at the end"), std::string::npos) << awake.output;
}

// --sensors: every robot's LEDs lit and its sensors and fake camera read at 10 Hz; robots on the
// arena's 0.3 m grid see each other's LEDs, a lone robot sees none.
TEST(ToolsCli, BenchSensorRowsReadLitSwarms) {
  const auto blobs = [](const std::string& output) {
    const std::size_t at = output.find("LEDs lit, ");
    return at == std::string::npos ? -1.0 : std::stod(output.substr(at + 10));
  };
  const Outcome four = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --sensors --profile --robots 4 --seconds 0.3");
  ASSERT_EQ(four.status, 0) << four.output;
  EXPECT_NE(four.output.find("random walk, sensors"), std::string::npos) << four.output;
  EXPECT_GT(blobs(four.output), 3.0) << "three neighbours, 8 LED groups each, half facing: " << four.output;
  EXPECT_NE(four.output.find("contacts/step, sensors "), std::string::npos) << "--profile gives their share: " << four.output;
  const Outcome one = sbot_test::runProcess(std::string(SBOT_BENCH_BIN) + " --sensors --robots 1 --seconds 0.3");
  ASSERT_EQ(one.status, 0) << one.output;
  EXPECT_EQ(blobs(one.output), 0.0) << one.output;
}

// The last option without its value (read as "", --level "" would fail later with an unrelated
// message).
TEST(ToolsCli, AnOptionWithoutItsValueIsRefusedByName) {
  expectRefused("sbot_validate", "--out", "sbot_validate: --out needs a value");
  expectRefused("sbot_validate", "--trial step detailed", "sbot_validate: --trial needs PARAM after KIND LEVEL");
  expectRefused("sbot_validate", "--trial", "sbot_validate: --trial needs KIND LEVEL PARAM");
  expectRefused("switching_experiment", "--runs 2 --scenario", "switching_experiment: --scenario needs a value");
  expectRefused("two_sbots", "--level", "two_sbots: --level needs a value");
}

// An unknown switching mode is refused before any mode's run starts, naming the tool (not found in
// the loop that starts them, after "detailed" had been started).
TEST(ToolsCli, AnUnknownModeIsRefusedBeforeAnyRun) {
  expectRefused("switching_experiment", "--runs 1 --out " + testing::TempDir() + "cli_modes --modes detailed,bogus",
                "switching_experiment: --modes: unknown mode 'bogus' (modes: switching, fast, simple, basic, medium, detailed)");
  expectRefused("switching_experiment", "--runs 1 --out " + testing::TempDir() + "cli_modes --modes ,",
                "switching_experiment: --modes: unknown mode '' (modes:");
}

// The solver and friction study knobs (docs/validation.md "Solver") are read from the environment by both
// tools; a value they cannot use stops them before any trial (an unparsable iteration count must not
// become 0 iterations through atoi).
TEST(ToolsCli, UnusableStudyKnobsAreRefusedByName) {
  // variable=value, and the message the tool must stop with (exit status 2)
  const std::pair<std::string, std::string> refused[] = {
      {"SBOT_VALIDATE_ITERATIONS=12x", "$SBOT_VALIDATE_ITERATIONS: expected a whole number in [1, 10000], found '12x'"},
      {"SBOT_VALIDATE_SOLVER=fast", "$SBOT_VALIDATE_SOLVER: expected 'quickstep' or 'exact', found 'fast'"},
      {"SBOT_VALIDATE_SOR=2.5", "$SBOT_VALIDATE_SOR: expected a number in [0.1, 1.99], found '2.5'"},
      {"SBOT_VALIDATE_CONTACT_CFM=-1", "$SBOT_VALIDATE_CONTACT_CFM: expected a number in [0, 1], found '-1'"},
      {"SBOT_VALIDATE_CONTACT_ERP=x", "$SBOT_VALIDATE_CONTACT_ERP: expected a number in [0.01, 1], found 'x'"},
      {"SBOT_VALIDATE_TRACK_MU=nan", "$SBOT_VALIDATE_TRACK_MU: expected a number in [0, 100], found 'nan'"},
      {"SBOT_VALIDATE_WELD=yes", "$SBOT_VALIDATE_WELD: expected 1 (weld idle turrets) or 0, found 'yes'"},
  };
  for (const std::string tool : {"sbot_validate", "two_sbots"}) {
    const std::string bin = std::string(SWARMBOT3D_BIN_DIR) + "/" + tool;
    for (const auto& [setting, message] : refused) {
      const Outcome o = sbot_test::runProcess("env " + setting + " " + bin + " --trial step detailed 0.010");
      EXPECT_EQ(o.status, 2) << setting << ": " << o.output;
      EXPECT_NE(o.output.find(tool + ": " + message), std::string::npos) << setting << ": " << o.output;
    }
  }
  // The friction knob is taken: on frictionless treels the 10 mm step that passes is not climbed.
  const Outcome slick = sbot_test::runProcess("env SBOT_VALIDATE_TRACK_MU=0 " + std::string(SWARMBOT3D_BIN_DIR) +
                                              "/sbot_validate --trial step detailed 0.010");
  EXPECT_EQ(slick.status, 0) << slick.output;
  EXPECT_NE(slick.output.find("step detailed 0.01: fail; base x at the end (step edge at 0) "), std::string::npos)
      << "the label, then what the trial measured, named: " << slick.output;
  // A usable value is taken: one trial at 60 iterations.
  const Outcome o = sbot_test::runProcess("env SBOT_VALIDATE_ITERATIONS=60 " + std::string(SWARMBOT3D_BIN_DIR) +
                                          "/sbot_validate --trial step detailed 0.010");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("step detailed 0.01: pass"), std::string::npos) << o.output;
}

// The weld knob is a switch: 0 is the default (set to 0 it does not weld), 1 welds. Medium on the
// 0.7 rad ramp is a trial the weld changes (docs/model.md, "Yaw drift under quickstep").
TEST(ToolsCli, TheWeldKnobZeroIsTheDefaultAndOneWelds) {
  const std::string trial = std::string(SWARMBOT3D_BIN_DIR) + "/sbot_validate --trial uphill medium 0.7";
  const Outcome unset = sbot_test::runProcess("env -u SBOT_VALIDATE_WELD " + trial);
  const Outcome zero = sbot_test::runProcess("env SBOT_VALIDATE_WELD=0 " + trial);
  const Outcome one = sbot_test::runProcess("env SBOT_VALIDATE_WELD=1 " + trial);
  ASSERT_EQ(unset.status, 0) << unset.output;
  EXPECT_EQ(zero.output, unset.output);
  EXPECT_NE(one.output, unset.output) << "welding idle turrets changes nothing in this trial any more: pick another";
}

// --index picks the cell's trial, i.e. its start perturbation: trial 1 starts elsewhere than trial 0
// (the printed end position differs), and naming trial 0 is the default.
TEST(ToolsCli, IndexRunsAnotherTrialOfTheCell) {
  const std::string tool = std::string(SWARMBOT3D_BIN_DIR) + "/sbot_validate ";
  const Outcome first = sbot_test::runProcess(tool + "--trial gap fast 0.03");
  const Outcome zero = sbot_test::runProcess(tool + "--index 0 --trial gap fast 0.03");
  const Outcome second = sbot_test::runProcess(tool + "--index 1 --trial gap fast 0.03");
  ASSERT_EQ(first.status, 0) << first.output;
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_EQ(zero.output, first.output);
  EXPECT_NE(second.output, first.output);
}

// Inputs that must not give a report anyway: a misspelt --only section (an empty report, status 0)
// and an unreadable height map (288 failed runs shown as "0.00 +- 0.00" in Figure 4.4).
TEST(ToolsCli, UnknownSectionsAndUnreadableHeightMapsAreRefusedBeforeAnyRun) {
  const std::string out = "--out " + testing::TempDir() + "cli_refused ";
  expectRefused("sbot_validate", out + "--only fig44", "--only: unknown section 'fig44' (in config/validation/reference_tables.yaml: facts, 4.1,");
  expectRefused("sbot_validate", out + "--only fig4.4 --heightmap /nonexistent/map.png",
                "--heightmap (or $SBOT_HEIGHTMAP): /nonexistent/map.png: field 'terrain.heightmap_image': cannot open image (No such file or directory)");
  // A report whose mismatches could not be explained is not written either.
  expectRefused("sbot_validate", out + "--only 4.2 --reasons /nonexistent/reasons.yaml",
                "sbot_validate: --reasons: mismatch reasons /nonexistent/reasons.yaml: cannot open mismatch reasons file");
}

// Reference tables other than the seed's (--tables): another lab's cells run, their mismatches are
// tallied in their own group and decide the exit status when the group is required; a malformed
// file is refused before any run, and --only names the file's own entries.
TEST(ToolsCli, AnotherReferenceTableRunsAndDecidesTheExitStatus) {
  const std::string dir = testing::TempDir() + "cli_tables/";
  std::system(("mkdir -p " + dir).c_str());
  auto tables = [&](const std::string& name, bool required, const std::string& wide_gap) {
    std::ofstream(dir + name) << "groups:\n  - {name: lab, title: \"Lab cells\", required: " << (required ? "true" : "false")
                              << "}\nreport:\n  - table:\n      id: lab1\n      title: Half-size gaps\n      group: lab\n"
                                 "      experiment: gap\n      level: fast\n      param: {unit: mm, scale: 1000, decimals: 0}\n"
                                 "      references: [measured]\n      cells:\n        - {param: 0.030, measured: pass}\n"
                                 "        - {param: 0.065, measured: \""
                              << wide_gap << "\"}\n";
    return dir + name;
  };
  const std::string tool = std::string(SWARMBOT3D_BIN_DIR) + "/sbot_validate --trials 1 --jobs 1 --out " + dir;
  // The Fast robot crosses a 3 cm gap and is stuck in 6.5 cm (the seed's Table 4.5, halved terrain).
  Outcome o = sbot_test::runProcess(tool + "ok --tables " + tables("ok.yaml", true, "stuck|fall inside"));
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("| 65 mm | stuck or fall inside | stuck (stuck 1/1) | match |"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("- Lab cells matched: 2/2"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("Table 4.5"), std::string::npos) << "only the file's tables run: " << o.output;
  // A reference the model does not meet: a mismatch, not explained yet, and exit status 1.
  o = sbot_test::runProcess(tool + "bad --tables " + tables("bad.yaml", true, "pass"));
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find("| 65 mm | pass | stuck (stuck 1/1) | **mismatch** |"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("*lab1 65 mm*: **not explained yet**"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("- Lab cells matched: 1/2"), std::string::npos) << o.output;
  // The same mismatch in a group that is not required is reported but does not fail the run.
  o = sbot_test::runProcess(tool + "optional --tables " + tables("optional.yaml", false, "pass"));
  EXPECT_EQ(o.status, 0) << o.output;
  // Refused before any run: a label the experiment never yields, and an entry the file does not have.
  expectRefused("sbot_validate", "--out " + dir + "x --tables " + tables("typo.yaml", true, "stuk"),
                "sbot_validate: --tables: reference tables " + dir + "typo.yaml: table 'lab1', cell 1: reference 'measured' "
                "accepts 'stuk', which gap never yields");
  expectRefused("sbot_validate", "--out " + dir + "x --only 4.5 --tables " + dir + "ok.yaml",
                "--only: unknown section '4.5' (in " + dir + "ok.yaml: lab1)");
}

// Inputs to refuse or name: a 0 mm step would stop ODE with an assertion (and cost the worker's
// other cells), options only --trial reads would be ignored by a report, an empty --only would run
// the whole suite, the seed's reasons would "explain" cells of another tables file, and a reason
// whose key names no cell would silently never be shown.
TEST(ToolsCli, ProbedTablesAndOptionsAreRunOrRefusedAsTheySay) {
  const std::string dir = testing::TempDir() + "cli_probe/";
  std::system(("mkdir -p " + dir).c_str());
  const Outcome zero = run("sbot_validate", "--trial step detailed 0");
  EXPECT_EQ(zero.status, 0) << zero.output;
  EXPECT_NE(zero.output.find("step detailed 0: pass"), std::string::npos) << "a 0 mm step is the floor: " << zero.output;
  const Outcome flat = run("sbot_validate", "--trial downhill detailed 0");
  EXPECT_EQ(flat.status, 0) << flat.output;
  const std::string out = "--out " + dir + "x ";
  expectRefused("sbot_validate", out + "--speed 30", "--speed goes with --trial (before it)");
  expectRefused("sbot_validate", out + "--index 5", "--index goes with --trial (before it)");
  expectRefused("sbot_validate", out + "--only \"\"", "--only expects a list of sections and table ids, found ''");
  expectRefused("sbot_validate", out + "--tables " + dir, "--tables: reference tables " + dir + ": is a folder, not a reference tables file");
  // A table of one's own, named like a seed cell, mismatching: the seed's reason is not shown for it.
  std::ofstream(dir + "mine.yaml") << "groups:\n  - {name: mine, title: Mine}\n"
                                      "report:\n  - table:\n      id: \"4.6\"\n      title: Mine\n      group: mine\n      experiment: uphill\n"
                                      "      param: {unit: rad, scale: 1, decimals: 2}\n      references: [measured]\n"
                                      "      cells:\n        - {param: 0.04, level: simple, measured: stuck}\n"
                                      "        - {param: 0.02, level: fast, measured: climb}\n";
  const Outcome mine = run("sbot_validate", "--trials 1 --jobs 1 " + out + "--tables " + dir + "mine.yaml");
  EXPECT_NE(mine.output.find("| 0.04 rad | simple | stuck | climb"), std::string::npos) << mine.output;
  EXPECT_NE(mine.output.find("*4.6 0.04 rad simple*: **not explained yet**"), std::string::npos) << mine.output;
  // With a reasons file that names a cell the tables do not have: a warning naming it.
  std::ofstream(dir + "reasons.yaml") << "\"4.6 0.04 rad simple\": why\n\"4.6 0.4 rad simple\": a typo\n";
  const Outcome typo = run("sbot_validate", "--trials 1 --jobs 1 " + out + "--tables " + dir + "mine.yaml --reasons " + dir +
                                                 "reasons.yaml");
  EXPECT_NE(typo.output.find("warning: " + dir + "reasons.yaml: the reason for '4.6 0.4 rad simple' names no cell"),
            std::string::npos)
      << typo.output;
  EXPECT_NE(typo.output.find("*4.6 0.04 rad simple*: why"), std::string::npos) << typo.output;
}

// A table's cells can drive at another speed than the seed's 2.8 cm/s (speed_units): the Medium is
// stuck in a 4.5 cm gap at 2.8 cm/s and crosses it on its momentum at 16.8 cm/s (the seed's reason for
// driving slowly, 4.2.3); the report then shows each cell's speed, and the variants that tell the two
// rows apart (also without a variant_header).
TEST(ToolsCli, ATableCellDrivesAtItsOwnSpeed) {
  const std::string dir = testing::TempDir() + "cli_speed/";
  std::system(("mkdir -p " + dir).c_str());
  std::ofstream(dir + "speed.yaml") << "groups:\n  - {name: lab, title: \"Lab cells\", required: true}\nreport:\n  - table:\n"
                                       "      id: fast_gap\n      title: Gap at two speeds\n      group: lab\n"
                                       "      experiment: gap\n      level: medium\n      param: {unit: cm, scale: 100, decimals: 1}\n"
                                       "      references: [measured]\n      cells:\n"
                                       "        - {param: 0.045, variant: slow, measured: stuck}\n"
                                       "        - {param: 0.045, variant: fast, speed_units: 60, measured: pass}\n";
  const Outcome o = sbot_test::runProcess(std::string(SWARMBOT3D_BIN_DIR) + "/sbot_validate --trials 1 --jobs 1 --out " + dir +
                                          "report --tables " + dir + "speed.yaml");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("| 4.5 cm | slow | 2.80 | stuck | stuck (stuck 1/1) | match |"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("| 4.5 cm | fast | 16.80 | pass | pass (pass 1/1) | match |"), std::string::npos) << o.output;
}

// A model description that cannot be read ($SBOT_DESCRIPTION_DIR, the sweep tool's variants): two_sbots
// and sbot_validate --trial aborted on an uncaught exception, and a report was written anyway with every
// model fact "error" and every static tipping angle "> 90 deg" (a failed run read as a number), status 0.
TEST(ToolsCli, AnUnreadableModelDescriptionIsRefusedBeforeAnyRun) {
  const std::string env = "env SBOT_DESCRIPTION_DIR=/nonexistent/descriptions " + std::string(SWARMBOT3D_BIN_DIR) + "/";
  const std::string missing = "/nonexistent/descriptions/urdf/";
  Outcome o = sbot_test::runProcess(env + "two_sbots --trials 1 --angles 10 --steps 0.032");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("two_sbots: --level detailed (or $SBOT_DESCRIPTION_DIR): " + missing + "detailed.urdf"),
            std::string::npos) << o.output;
  o = sbot_test::runProcess(env + "sbot_validate --out " + testing::TempDir() + "cli_no_description --only facts");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("sbot_validate: model description of level 'fast' (or $SBOT_DESCRIPTION_DIR): " + missing),
            std::string::npos) << o.output;
  o = sbot_test::runProcess(env + "sbot_validate --trial step detailed 0.010");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("sbot_validate: --trial step detailed: " + missing + "detailed.urdf"), std::string::npos)
      << o.output;
}

// An output place that cannot be written (output_files.h): sbot_validate made its directory without
// looking at the result, ran every trial and then said "wrote DIR/report.md" with no file there.
// Now it is refused before the first trial, with the directory and the system's reason; a missing
// parent is created.
TEST(ToolsCli, AnOutputPlaceThatCannotBeWrittenIsRefusedBeforeAnyRun) {
  const std::string dir = testing::TempDir() + "cli_out/";
  std::system(("rm -rf " + dir + " && mkdir -p " + dir + " && touch " + dir + "plain").c_str());
  Outcome o = run("sbot_validate", "--out /proc/sbot_no_such_place/report --only 4.2 --trials 1 --jobs 1");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("sbot_validate: --out: cannot create directory '/proc/sbot_no_such_place' (for "
                          "'/proc/sbot_no_such_place/report'): No such file or directory"),
            std::string::npos)
      << o.output;
  EXPECT_EQ(o.output.find("Table 4.2"), std::string::npos) << "no trial runs: " << o.output;
  expectRefused("sbot_validate", "--out " + dir + "plain/report --only 4.2",
                "--out: cannot create directory '" + dir + "plain/report': '" + dir + "plain' exists and is not a directory");
  expectRefused("switching_experiment", "--runs 1 --out " + dir + "plain",
                "switching_experiment: --out: cannot create directory '" + dir + "plain'");
  o = run("sbot_validate", "--out " + dir + "new/nested --only 4.2 --trials 1 --jobs 1");
  EXPECT_EQ(o.status, 1) << "the 55 mm cell is a known mismatch: " << o.output;
  EXPECT_NE(o.output.find("wrote " + dir + "new/nested/report.md"), std::string::npos) << o.output;
  std::ifstream report(dir + "new/nested/report.md");
  std::string first;
  std::getline(report, first);
  EXPECT_EQ(first, "# swarmbot3d validation report");
}

// sbot_validate started in the background (argument words, no shell), its output in `log`.
pid_t startValidate(const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> words{std::string(SWARMBOT3D_BIN_DIR) + "/sbot_validate"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(&w[0]);
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  const int err = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return err == 0 ? pid : -1;
}

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Polls (every 20 ms, up to `seconds`) until `ready` holds; false if it never did.
template <class F>
bool waitFor(F ready, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return ready();
}

/// A tables file of two tables: a quick one (two Fast gaps) and Detailed gaps of 30 mm and up, one per mm.
std::string twoTables(const std::string& dir, int detailed_cells) {
  std::ostringstream t;
  t << "groups:\n  - {name: lab, title: Lab cells}\nreport:\n"
       "  - table:\n      id: quick\n      title: Quick gaps\n      group: lab\n      experiment: gap\n      level: fast\n"
       "      param: {unit: mm, scale: 1000, decimals: 0}\n      references: [measured]\n      cells:\n"
       "        - {param: 0.030, measured: pass}\n"
       "  - table:\n      id: slow\n      title: Slow gaps\n      group: lab\n      experiment: gap\n      level: detailed\n"
       "      param: {unit: mm, scale: 1000, decimals: 0}\n      references: [measured]\n      cells:\n";
  for (int k = 0; k < detailed_cells; ++k) t << "        - {param: " << 0.030 + 0.001 * k << ", measured: pass}\n";
  std::ofstream(dir + "tables.yaml") << t.str();
  return dir + "tables.yaml";
}

// A run stopped part-way (Ctrl-C, a killed job) keeps every finished section: the report so far is kept as report.partial.md, section by section, and
// the finished run replaces it by report.md.
TEST(ToolsCli, AStoppedRunKeepsTheSectionsItFinished) {
  const std::string dir = testing::TempDir() + "cli_stopped/";
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  const std::string tables = twoTables(dir, 40);
  const pid_t pid = startValidate({"--trials", "1", "--jobs", "1", "--out", dir + "report", "--tables", tables}, dir + "log");
  ASSERT_GT(pid, 0);
  const std::string partial = dir + "report/report.partial.md";
  const bool quick_done = waitFor([&] { return fileText(partial).find("## Quick gaps") != std::string::npos; }, 60);
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(quick_done) << fileText(dir + "log");
  const std::string text = fileText(partial);
  EXPECT_NE(text.find("| 30 mm | pass | pass (pass 1/1) | match |"), std::string::npos) << text;
  EXPECT_NE(text.find("The sections above are complete; not reached: slow."), std::string::npos) << text;
  EXPECT_EQ(text.find("## Slow gaps"), std::string::npos) << "stopped during the second table: " << text;
  EXPECT_NE(access((dir + "report/report.md").c_str(), F_OK), 0) << "no report.md from a run that did not finish";
  // A finished run leaves its report and no partial one.
  const Outcome done = run("sbot_validate", "--trials 1 --jobs 1 --out " + dir + "report --tables " + twoTables(dir, 1));
  EXPECT_EQ(done.status, 0) << done.output;
  EXPECT_NE(access((dir + "report/report.md").c_str(), F_OK), -1);
  EXPECT_NE(access(partial.c_str(), F_OK), 0) << "the partial report of the stopped run was left";
}

// A worker process that dies (an ODE assertion, the OOM killer) costs the trial it was running, not
// the run: the report marks that cell "error", lists it in the summary, and the exit status is 3 (not
// 1, as if the model had failed the cell).
TEST(ToolsCli, AKilledWorkerCostsOnlyItsTrialAndTheRunEndsWithStatus3) {
  const std::string dir = testing::TempDir() + "cli_killed_worker/";
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  const std::string tables = twoTables(dir, 4);
  const pid_t pid = startValidate({"--trials", "1", "--jobs", "1", "--out", dir + "report", "--only", "slow", "--tables", tables},
                                  dir + "log");
  ASSERT_GT(pid, 0);
  // The Detailed table's worker: the first child of the run (the quick table is not run).
  pid_t worker = -1;
  waitFor([&] {
    FILE* p = popen(("pgrep -P " + std::to_string(pid)).c_str(), "r");
    if (p && std::fscanf(p, "%d", &worker) != 1) worker = -1;
    if (p) pclose(p);
    return worker > 0;
  }, 60);
  ASSERT_GT(worker, 0) << fileText(dir + "log");
  kill(worker, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string log = fileText(dir + "log");
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 3) << log;
  EXPECT_NE(log.find("a worker process died of signal 9"), std::string::npos) << log;
  // Which cell was lost depends on when the kill landed (usually the first): one, and only one.
  EXPECT_NE(log.find("1 cell(s) had trials that could not run: slow 3"), std::string::npos) << log;
  int ran = 0;
  for (std::size_t at = 0; (at = log.find("| pass | pass (pass 1/1) | match |", at)) != std::string::npos; ++at) ++ran;
  EXPECT_EQ(ran, 3) << "the other cells ran: " << log;
  const std::string report = fileText(dir + "report/report.md");
  EXPECT_NE(report.find("- Cells with trials that could not run (\"error\"; the cause is on stderr): slow 3"), std::string::npos)
      << report;
  EXPECT_NE(report.find("| error (error 1/1) | **error** (could not run) |"), std::string::npos) << report;
  EXPECT_EQ(report.find("not explained yet"), std::string::npos) << "a cell that did not run is no model mismatch: " << report;
}

// --scenario FILE --trial ...: the trial's world and start as a scenario file for the node (to watch
// a cell in rviz), with the commands to do so; a kind a scenario cannot hold is refused by name.
TEST(ToolsCli, ATrialIsWrittenAsAScenarioToWatch) {
  const std::string file = testing::TempDir() + "cli_trial_scenario.yaml";
  std::remove(file.c_str());
  Outcome o = run("sbot_validate", "--scenario " + file + " --index 2 --speed 20 --trial stepb detailed 0.015");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("roslaunch swarmbot3d swarm.launch scenario:=" + file + " robots:=1 level:=detailed"),
            std::string::npos)
      << o.output;
  EXPECT_NE(o.output.find("/sbot_0/cmd_speed sbot_msgs/TrackSpeed '{left: -20, right: -20}'"), std::string::npos)
      << "reversing at --speed: " << o.output;
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("- {name: step, center: [0.5, 0, 0.0075], size: [1, 1, 0.015]"), std::string::npos) << text;
  EXPECT_EQ(text.find("track: 0.475"), std::string::npos) << "the experiment's own floor unless asked: " << text;
  // --track-mu lab_floor: the floor Tables 4.2 / 4.3 run on, in the scenario's materials.
  o = run("sbot_validate", "--scenario " + file + " --track-mu lab_floor --trial stepb detailed 0.015");
  EXPECT_EQ(o.status, 0) << o.output;
  std::ifstream in2(file);
  text.assign((std::istreambuf_iterator<char>(in2)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("track: 0.475"), std::string::npos) << text;
  EXPECT_NE(text.find("- {name: sbot_0, level: detailed, pose: {x: -0.07"), std::string::npos) << text;
  expectRefused("sbot_validate", "--scenario " + file + " --trial slope detailed 20",
                "--scenario: a slope trial cannot be written as a scenario");
  expectRefused("sbot_validate", "--scenario /proc/sbot_no_such_place/t.yaml --trial gap detailed 0.03",
                "--scenario: cannot write '/proc/sbot_no_such_place/t.yaml'");
}

// Figure 4.4 end to end (--quick: 4 runs a point): the table of distances, the plot, and the
// seed's reading checked per level, every mismatch of it with its recorded reason.
TEST(ToolsCli, FigureFourFourHasItsTablePlotAndTheSeedsReading) {
  const std::string dir = testing::TempDir() + "cli_fig44/";
  const Outcome o = run("sbot_validate", "--only fig4.4 --quick --out " + dir);
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("| level | HR 1 | HR 2 | HR 4 | HR 8 | HR 16 | HR 32 |"), std::string::npos) << o.output;
  std::ifstream png(dir + "fig4_4.png", std::ios::binary);
  char magic[4] = {};
  png.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG") << "the plot";
  EXPECT_NE(o.output.find("| level | holds its course up to | the seed says | match |"), std::string::npos) << o.output;
  for (const std::string level : {"fast", "simple", "medium"}) {
    const auto row = o.output.find("\n| " + level + " | HR ", o.output.find("holds its course up to"));
    ASSERT_NE(row, std::string::npos) << level << ": " << o.output;
    const std::string line = o.output.substr(row + 1, o.output.find('\n', row + 1) - row - 1);
    const bool mismatch = line.find("**mismatch**") != std::string::npos;
    EXPECT_TRUE(mismatch || line.find("| match") != std::string::npos) << line;
    if (mismatch) {
      EXPECT_NE(o.output.find("- *fig4.4 " + level + "*: "), std::string::npos) << "its reason: " << o.output;
    }
  }
  EXPECT_EQ(o.output.find("not explained yet"), std::string::npos) << o.output;
}

// With --only a required group's tally must not read "1/1" of its two cells, and a file whose
// tables name no group must not give exit status 0 without a word that nothing was compared.
TEST(ToolsCli, ATallySaysWhatOnlyLeftOutAndAnUntalliedReportSaysSo) {
  const std::string dir = testing::TempDir() + "cli_tally/";
  std::system(("mkdir -p " + dir).c_str());
  const auto table = [](const std::string& id, const std::string& group) {
    return "  - table:\n      id: " + id + "\n      title: " + id + "\n" + (group.empty() ? "" : "      group: " + group + "\n") +
           "      experiment: gap\n      level: fast\n      param: {unit: mm, scale: 1000, decimals: 0}\n"
           "      references: [measured]\n      cells:\n        - {param: 0.030, measured: pass}\n";
  };
  std::ofstream(dir + "two.yaml") << "groups:\n  - {name: lab, title: \"Lab cells\", required: true}\nreport:\n"
                                  << table("lab1", "lab") << table("lab2", "lab");
  const std::string tool = "--trials 1 --jobs 1 --out " + dir;
  Outcome o = run("sbot_validate", tool + "two --tables " + dir + "two.yaml --only lab1");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("- Lab cells matched: 1/1 (1 cells of this tally not run: --only)"), std::string::npos) << o.output;
  std::ofstream(dir + "none.yaml") << "groups: []\nreport:\n" << table("shown", "");
  o = run("sbot_validate", tool + "none --tables " + dir + "none.yaml");
  EXPECT_NE(o.output.find("- No cell is tallied"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("warning: no cell is tallied"), std::string::npos) << o.output;
}

// What follows --trial's three values is not ignored (report options too: --trials 3 with it would
// run one trial), an empty --scenario is refused rather than running the trial, a --scenario over a
// file of one's own does not replace it, and an unknown option is named, not just the usage.
TEST(ToolsCli, ATrialTakesOnlyItsOwnOptionsAndKeepsOtherFiles) {
  expectRefused("sbot_validate", "--trial step detailed 0.01 extra", "--trial KIND LEVEL PARAM comes last; found 'extra' after it");
  expectRefused("sbot_validate", "--trials 3 --trial step detailed 0.01", "--trials makes a report; --trial runs one trial");
  expectRefused("sbot_validate", "--scenario \"\" --trial gap detailed 0.03", "--scenario expects a file name, found ''");
  expectRefused("sbot_validate", "--bogus", "sbot_validate: unknown option '--bogus'");
  expectRefused("sbot_validate", "--tables a.yaml --tables b.yaml", "sbot_validate: --tables is given twice");
  const std::string mine = testing::TempDir() + "cli_my_scenario.yaml";
  std::ofstream(mine) << "name: mine\n";
  expectRefused("sbot_validate", "--scenario " + mine + " --trial gap detailed 0.03", "exists and was not written by sbot_validate");
  std::ifstream in(mine);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "name: mine") << "the user's file is kept";
}

TEST(ToolsCli, AValidTrialRuns) {
  const Outcome o = run("sbot_validate", "--trial step detailed 0.010");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("step detailed 0.01: pass"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("pitch"), std::string::npos) << "no trace unless asked";
}

// --trace prints the robot's state every 0.1 s (pose, attitude, wheel load, track speeds, turret
// angle, gripper tip height): here the Detailed model reversing into a 15 mm step
// tips nose down toward its gripper (the hardware passes; 10 mm passes with the calibrated turret
// COM); the trial stops as a topple once it is 45 deg off the vertical
// (not driving on, standing on its gripper at 70-77 deg, to count as a pass).
TEST(ToolsCli, TraceShowsTheRobotTippingOntoItsGripper) {
  const Outcome o = run("sbot_validate", "--trace --trial stepb detailed 0.015");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("stepb detailed 0.015: topple"), std::string::npos) << o.output;
  double max_pitch = 0;
  int lines = 0;
  for (std::size_t at = o.output.find("pitch"); at != std::string::npos; at = o.output.find("pitch", at + 1)) {
    max_pitch = std::max(max_pitch, std::atof(o.output.c_str() + at + 5));
    ++lines;
  }
  EXPECT_GT(lines, 20) << o.output;
  EXPECT_GT(max_pitch, 30.0) << o.output;
  // The encoders show the tracks reversing (left track speed < 0 on some line), and the turret's
  // angle is printed beside them.
  double min_track = 0;
  for (std::size_t at = o.output.find("tracks"); at != std::string::npos; at = o.output.find("tracks", at + 1))
    min_track = std::min(min_track, std::atof(o.output.c_str() + at + 6));
  EXPECT_LT(min_track, -0.02) << o.output;
  EXPECT_NE(o.output.find("turret"), std::string::npos) << o.output;
  expectRefused("sbot_validate", "--out " + testing::TempDir() + "cli --trace", "--trace goes with --trial");
}

}  // namespace
