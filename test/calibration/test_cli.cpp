// The sbot_calibrate command line: options a subcommand does not take are refused with a message that
// names them (ignored, a misspelt --effects would let `compare --effect F` compare the nominal
// model), and so are bad values of the ones it does take.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../common/run_process.h"

namespace {

using Outcome = sbot_test::ProcessOutcome;

Outcome run(const std::string& args) { return sbot_test::runProcess(std::string(SBOT_CALIBRATE_BIN) + " " + args); }

const std::string kExample = std::string(SWARMBOT3D_SOURCE_DIR) + "/datasets/example";
/// One place run of 4 samples (IR only, one white_paper wall): fits and diagnoses in well under a second.
const std::string kIrPoints = std::string(SWARMBOT3D_SOURCE_DIR) + "/datasets/seed_ir_response";

/// An empty folder TempDir()/name/ (returned with the slash).
std::string freshDir(const std::string& name) {
  const std::string dir = testing::TempDir() + name + "/";
  std::system(("rm -rf '" + dir + "' && mkdir -p '" + dir + "'").c_str());
  return dir;
}

void writeFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Cli, AnOptionTheSubcommandDoesNotTakeIsRefusedByName) {
  const Outcome o = run("compare " + kExample + " --effect fitted.yaml --no-plots --out " + testing::TempDir() + "cli_typo");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("unknown option --effect for 'compare'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("--effects"), std::string::npos) << "lists what it takes: " << o.output;
  const Outcome d = run("diagnose " + kExample + " --treshold 5");
  EXPECT_EQ(d.status, 2) << d.output;
  EXPECT_NE(d.output.find("unknown option --treshold for 'diagnose'"), std::string::npos) << d.output;
  // Last on the line, a misspelt option is named as such (not as one that "needs a value").
  const Outcome last = run("compare " + kExample + " --no-plot");
  EXPECT_EQ(last.status, 2) << last.output;
  EXPECT_NE(last.output.find("unknown option --no-plot for 'compare'"), std::string::npos) << last.output;
}

TEST(Cli, ABadSolverIsRefusedByName) {
  const Outcome o = run("compare " + kExample + " --solver fast --no-plots --out " + testing::TempDir() + "cli_solver");
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("--solver expects quickstep or exact, got 'fast'"), std::string::npos) << o.output;
}

// An output place that cannot be written is refused before the work (a fit or a diagnosis runs for
// minutes): compare and fit must not compute, then print "report: DIR/report.md" or lose the fitted
// effects file, with exit status 0.
TEST(Cli, AnOutputPlaceThatCannotBeWrittenIsRefusedBeforeTheWork) {
  const std::string dir = testing::TempDir() + "cli_out/";
  std::system(("rm -rf " + dir + " && mkdir -p " + dir + " && touch " + dir + "plain").c_str());
  auto refused = [](const Outcome& o, const std::string& message) {
    EXPECT_EQ(o.status, 2) << o.output;
    EXPECT_NE(o.output.find("sbot_calibrate: " + message), std::string::npos) << o.output;
    EXPECT_EQ(o.output.find("nRMS"), std::string::npos) << "nothing was computed: " << o.output;
  };
  refused(run("compare " + kExample + " --no-plots --out /proc/sbot_no_such_place"),
          "--out: cannot create directory '/proc/sbot_no_such_place': No such file or directory");
  refused(run("fit " + kExample + " --effect speed_scale --out " + dir + "plain/fitted.yaml"),
          "--out: cannot create directory '" + dir + "plain': '" + dir + "plain' exists and is not a directory");
  refused(run("diagnose " + kExample + " --write-effects " + dir), "--write-effects: cannot write '" + dir + "': it is a directory");
  refused(run("generate --out " + dir + "plain"), "--out: cannot create directory '" + dir + "plain'");
}

// The plot script is started without a shell: an output folder with a quote in its name must not
// end the quoting and run the rest as a command. --no-plots links no plot that is not drawn.
TEST(Cli, TheOutputFolderIsNotShellTextAndUndrawnPlotsAreNotLinked) {
  const std::string base = testing::TempDir() + "cli_quote/";
  std::system(("rm -rf '" + base + "' && mkdir -p '" + base + "'").c_str());
  const std::string out = base + "it's;touch " + base + "INJECTED;'";
  const Outcome o = run("compare " + kExample + " --jobs 1 --quiet --out \"" + out + "\"");
  EXPECT_EQ(o.status, 0) << o.output;
  struct stat st;
  EXPECT_NE(::stat((base + "INJECTED").c_str(), &st), 0) << "the folder name ran as a shell command";
  EXPECT_EQ(::stat((out + "/plots/parity.png").c_str(), &st), 0) << "plot_report.py got the folder as it is: " << o.output;
  const Outcome np = run("compare " + kExample + " --jobs 1 --quiet --no-plots --out \"" + out + "\"");
  EXPECT_EQ(np.status, 0) << np.output;
  std::ifstream md(out + "/report.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find(".png"), std::string::npos) << "links a plot --no-plots did not draw";
  EXPECT_NE(::stat((out + "/plots/parity.png").c_str(), &st), 0) << "the earlier run's plot is still there";
}

// fit --effect ir_reflectance must not run 0 iterations on no parameter and write `params: {}`: its
// parameters are per surface. They come from the dataset's obstacles (as in diagnose); without
// any, the refusal says how to name the surfaces.
TEST(Cli, APerSurfaceEffectIsFittedOnTheDatasetsSurfacesOrRefused) {
  const std::string dir = freshDir("cli_surfaces");
  const Outcome o = run("fit " + kIrPoints + " --effect ir_reflectance --quiet --out " + dir + "refl.yaml");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_TRUE(contains(o.output, "ir_reflectance.white_paper = ")) << o.output;
  EXPECT_TRUE(contains(readFile(dir + "refl.yaml"), "params: {white_paper: ")) << readFile(dir + "refl.yaml");

  std::system(("cp " + kIrPoints + "/ir2_head_on.csv " + dir).c_str());
  writeFile(dir + "dataset.yaml",
            "format: sbot-dataset/1\nname: no_walls\nrobot: medium\nworld: {terrain: {type: plane}}\n"
            "runs:\n  - {name: ir2_head_on, file: ir2_head_on.csv, kind: place}\n");
  const Outcome none = run("fit " + dir + " --effect ir_reflectance --quiet --out " + dir + "none.yaml");
  EXPECT_EQ(none.status, 2) << none.output;
  EXPECT_TRUE(contains(none.output, "--effect: ir_reflectance has one parameter per surface")) << none.output;
  EXPECT_TRUE(contains(none.output, "an --effects BASE file")) << "says how to give them: " << none.output;
  EXPECT_FALSE(exists(dir + "none.yaml"));
}

// A fit stopped by its iteration limit is not at a minimum, and the curvature there gave an interval
// that excluded the truth (accel_limit 2.103 +- 0.002 for 2.0). Its values are written with no
// interval and a note, and a warning says how to go on.
TEST(Cli, AFitStoppedByItsIterationLimitGivesNoInterval) {
  const std::string dir = freshDir("cli_iteration_limit");
  const Outcome cut = run("fit " + kIrPoints + " --effect ir_reflectance --quiet --max-iterations 1 --out " + dir + "cut.yaml");
  EXPECT_EQ(cut.status, 0) << cut.output;
  EXPECT_TRUE(contains(cut.output, "(no interval: not converged)")) << cut.output;
  EXPECT_TRUE(contains(cut.output, "warning: the fit stopped at its iteration limit (1) before converging")) << cut.output;
  const std::string file = readFile(dir + "cut.yaml");
  EXPECT_FALSE(contains(file, "stderr:")) << file;
  EXPECT_TRUE(contains(file, "not converged: sbot_calibrate fit on seed_ir_response stopped at its iteration limit (1)")) << file;
  // Given the iterations it needs, the same fit converges and states its interval.
  const Outcome done = run("fit " + kIrPoints + " --effect ir_reflectance --quiet --max-iterations 10 --out " + dir + "done.yaml");
  EXPECT_EQ(done.status, 0) << done.output;
  EXPECT_TRUE(contains(done.output, "(95 %)")) << done.output;
  EXPECT_TRUE(contains(readFile(dir + "done.yaml"), "stderr: {white_paper: ")) << readFile(dir + "done.yaml");
  const Outcome bad = run("fit " + kIrPoints + " --effect ir_reflectance --max-iterations 0 --out " + dir + "bad.yaml");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_TRUE(contains(bad.output, "--max-iterations")) << bad.output;
}

// The error a fit ends with is the error compare finds with the file it wrote: with 8 digits in the
// file the replay is chaotic enough that they move it (fit 2.3969, compare 2.4041).
TEST(Cli, WhatAFitReportsIsWhatCompareOfItsFileReports) {
  const std::string dir = freshDir("cli_fit_compare");
  const Outcome fit = run("fit " + kExample + " --effect latency --effect track_width --max-iterations 1 --quiet --out " +
                          dir + "cut.yaml");
  ASSERT_EQ(fit.status, 0) << fit.output;
  const std::string label = "normalised RMS: ";
  ASSERT_TRUE(contains(fit.output, label)) << fit.output;
  const std::string figures = fit.output.substr(fit.output.find(label) + label.size(), std::string("3.8873 -> 2.3969").size());
  const Outcome compare = run("compare " + kExample + " --effects " + dir + "cut.yaml --no-plots --quiet --out " + dir + "c");
  ASSERT_EQ(compare.status, 0) << compare.output;
  const std::string change = "error change (nRMS): ";
  ASSERT_TRUE(contains(compare.output, change)) << compare.output;
  EXPECT_EQ(compare.output.substr(compare.output.find(change) + change.size(), figures.size()), figures)
      << fit.output << "\n" << compare.output;
}

// An effect on channels the dataset does not measure is not "fitted" (exponent = 0 +- 1e+06)
// nor screened without a word.
TEST(Cli, AnEffectOnChannelsTheDatasetDoesNotMeasureIsRefusedOrNoted) {
  const std::string dir = freshDir("cli_channels");
  const Outcome fit = run("fit " + kExample + " --effect ir_incidence --quiet --out " + dir + "f.yaml");
  EXPECT_EQ(fit.status, 2) << fit.output;
  EXPECT_TRUE(contains(fit.output, "--effect: ir_incidence acts on ir, which dataset 'example' does not measure (it measures "))
      << fit.output;
  const Outcome named = run("diagnose " + kIrPoints + " --quiet --candidates ir_ambient,latency");
  EXPECT_EQ(named.status, 2) << named.output;
  EXPECT_TRUE(contains(named.output, "--candidates: latency acts on pose, speed, none of which dataset 'seed_ir_response' measures"))
      << named.output;
  const Outcome automatic = run("diagnose " + kIrPoints + " --quiet");
  EXPECT_EQ(automatic.status, 0) << automatic.output;
  EXPECT_TRUE(contains(automatic.output, "note: not screened, the dataset measures none of the channels they act on: "))
      << automatic.output;
  EXPECT_TRUE(contains(automatic.output, "light_angular, light_ambient (light)")) << automatic.output;
}

TEST(Cli, OptionValuesOutsideTheirRangeAndStrayArgumentsAreRefusedByName) {
  const std::string dir = freshDir("cli_values");
  auto refused = [](const std::string& args, const std::string& message) {
    const Outcome o = run(args);
    EXPECT_EQ(o.status, 2) << args << ": " << o.output;
    EXPECT_TRUE(contains(o.output, "sbot_calibrate: " + message)) << args << ": " << o.output;
  };
  for (const char* folds : {"0", "1", "-2", "2.5"})
    refused("diagnose " + kIrPoints + " --quiet --folds " + folds,
            "--folds expects a whole number of at least 2 (each fold's runs are scored by a fit on the others), got '" +
                std::string(folds) + "'");
  for (const char* t : {"nan", "inf"})
    refused("diagnose " + kIrPoints + " --quiet --threshold " + t, "--threshold expects a finite number, got '" + std::string(t) + "'");
  for (const char* jobs : {"0", "-1"})
    refused("effects --jobs " + std::string(jobs), "--jobs expects a whole number of at least 1 (worker processes), got '" + std::string(jobs) + "'");
  refused("compare " + kIrPoints + " " + kIrPoints + " --no-plots --out " + dir + "r",
          "unexpected argument '" + kIrPoints + "' ('compare' takes one DATASET)");
  refused("fit " + kIrPoints + " --effect ir_reflectance --effect ir_reflectance --out " + dir + "f.yaml",
          "--effect ir_reflectance is given twice");
  refused("fit " + kIrPoints + " --effect ir_reflectance --out " + dir + "a.yaml --out " + dir + "b.yaml",
          "--out is given 2 times");
  refused("fit " + kIrPoints + " --effect nonsuch --out " + dir + "f.yaml",
          "--effect: unknown effect 'nonsuch' (known: latency, dead_band, ");
  const Outcome unknown = run("calibrate " + kIrPoints);
  EXPECT_EQ(unknown.status, 2) << unknown.output;
  EXPECT_TRUE(contains(unknown.output, "sbot_calibrate: unknown command 'calibrate' (commands: compare, diagnose, ")) << unknown.output;
  EXPECT_TRUE(contains(unknown.output, "usage: ")) << unknown.output;
  // More folds than runs: the folds it uses are announced, not those asked for.
  const Outcome few = run("diagnose " + kIrPoints + " --quiet --folds 3");
  EXPECT_EQ(few.status, 0) << few.output;
  EXPECT_TRUE(contains(few.output, "level medium, 1 fold,")) << few.output;
  EXPECT_TRUE(contains(few.output, "note: --folds 3, but a fold holds out whole runs and the dataset has 1 run: 1 fold (scores in-sample)"))
      << few.output;
}

// sweep read its options with bare stoi/stod: "--seeds abc" stopped with the message "stoi", "--seeds
// 2.5" ran 2 seeds, "--duration nan" and an unknown --level or --solver reached the generator. They are
// checked as every other subcommand's, before any dataset is generated.
TEST(Cli, SweepOptionsAreCheckedByName) {
  auto refused = [](const std::string& args, const std::string& message) {
    const Outcome o = run("sweep --quiet " + args);
    EXPECT_EQ(o.status, 2) << args << ": " << o.output;
    EXPECT_TRUE(contains(o.output, "sbot_calibrate: " + message)) << args << ": " << o.output;
  };
  refused("--seeds abc", "--seeds expects a whole number from 1 to 10000 (synthetic datasets per case), got 'abc'");
  refused("--seeds 2.5", "--seeds expects a whole number from 1 to 10000 (synthetic datasets per case), got '2.5'");
  refused("--first-seed -1", "--first-seed expects a whole number from 0 to ");
  refused("--folds 1", "--folds expects a whole number of at least 2");
  refused("--threshold nan", "--threshold expects a finite number, got 'nan'");
  refused("--duration 1", "--duration expects 2 to 3600 s");
  refused("--solver fast", "--solver expects quickstep or exact, got 'fast'");
  refused("--level huge", "unknown model level 'huge'");
  refused("--cases none,nonsuch", "--cases: unknown sweep case 'nonsuch' (known: speed_scale, ");
  refused("--cases \"\"", "--cases expects a list of sweep case names, got ''");
  refused("--cases none --set latency:delay=0.2", "--set latency: no selected sweep case hides that effect");
  // And a sweep of one case and one short seed runs (a few seconds).
  const Outcome ok = run("sweep --quiet --cases none --seeds 1 --duration 3");
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(contains(ok.output, "Sweep: 1 seed per case, level simple")) << ok.output;
  EXPECT_TRUE(contains(ok.output, "- **none**: s1 {none} ")) << ok.output;
}

// diagnose --write-effects wrote nothing when nothing was accepted, so `compare --effects FILE`,
// the next step, failed on a missing file.
TEST(Cli, DiagnoseWritesTheNominalModelWhenNothingIsAccepted) {
  const std::string dir = freshDir("cli_none_accepted");
  const Outcome d = run("diagnose " + kIrPoints + " --quiet --write-effects " + dir + "effects.yaml");
  EXPECT_EQ(d.status, 0) << d.output;
  EXPECT_TRUE(contains(d.output, "no effect accepted: " + dir + "effects.yaml written with no effects (the nominal model)")) << d.output;
  EXPECT_TRUE(contains(readFile(dir + "effects.yaml"), "effects: []")) << readFile(dir + "effects.yaml");
  const Outcome c = run("compare " + kIrPoints + " --quiet --no-plots --effects " + dir + "effects.yaml --out " + dir + "report");
  EXPECT_EQ(c.status, 0) << c.output;
}

// generate overwrote a folder's dataset.yaml and left its other CSV files beside the new runs, and
// took families, durations, seeds and tilts it cannot make.
TEST(Cli, GenerateRefusesAFolderInUseAndValuesItCannotMake) {
  const std::string dir = freshDir("cli_generate");
  std::system(("mkdir -p " + dir + "lab && echo 't,x' > " + dir + "lab/measured.csv").c_str());
  const std::string quick = " --families straight --duration 2 --jobs 2 --quiet";
  const Outcome used = run("generate --out " + dir + "lab" + quick);
  EXPECT_EQ(used.status, 2) << used.output;
  EXPECT_TRUE(contains(used.output, "sbot_calibrate: --out " + dir + "lab is a folder that is not empty")) << used.output;
  EXPECT_TRUE(contains(used.output, "remove it or choose another folder")) << used.output;
  EXPECT_FALSE(exists(dir + "lab/dataset.yaml"));

  const std::string out = " --out " + dir + "new/data";
  auto refused = [&](const std::string& args, const std::string& message) {
    const Outcome o = run("generate" + out + " --jobs 2 --quiet " + args);
    EXPECT_EQ(o.status, 2) << args << ": " << o.output;
    EXPECT_TRUE(contains(o.output, "sbot_calibrate: " + message)) << args << ": " << o.output;
    EXPECT_FALSE(exists(dir + "new")) << args << ": a refused run created its output folder";
  };
  refused("--families straight,warp", "--families: unknown family 'warp' (known: straight, spin, arc, square, steps, place, approach)");
  for (const char* d : {"0", "0.001", "-3", "1.9"})
    refused(std::string("--families straight --duration ") + d, "--duration expects 2 to 3600 s");
  refused("--duration nan", "--duration expects a finite number, got 'nan'");
  refused("--hide speed_scale:scale=", "--hide 'speed_scale:scale=': speed_scale.scale expects a finite number, got ''");
  // Without values the effect's defaults were hidden: for latency, no delay at all.
  refused("--hide latency", "--hide 'latency': give the values (e.g. latency:delay=...; parameters: delay)");
  refused("--seed -5", "--seed expects a whole number from 0 to 9223372036854775807, got '-5'");
  refused("--seed 99999999999999999999", "--seed expects a whole number from 0 to 9223372036854775807");
  refused("--tilt 95", "--tilt expects a floor tilt from 0 to 30 deg");
  refused("--families place --level simple",
          "--families place needs a level with ray-traced IR (basic, medium, detailed); level 'simple'");
  refused("--level bogus", "unknown model level 'bogus'");
}

// fit and diagnose checked their output file only by access(2), which root passes in /proc: the
// work ran and its result was lost. A refused run also left the folders the check had created.
TEST(Cli, FitAndDiagnoseOutputsAreTriedBeforeTheWorkAndARefusedRunCreatesNoFolder) {
  const std::string dir = freshDir("cli_out_first");
  const Outcome fit = run("fit " + kIrPoints + " --effect ir_reflectance --quiet --out /proc/sbot_fitted.yaml");
  EXPECT_EQ(fit.status, 2) << fit.output;
  EXPECT_TRUE(contains(fit.output, "sbot_calibrate: --out: cannot write '/proc/sbot_fitted.yaml': ")) << fit.output;
  EXPECT_FALSE(contains(fit.output, "normalised RMS")) << "nothing was fitted: " << fit.output;
  const Outcome diag = run("diagnose " + kIrPoints + " --quiet --write-effects /proc/sbot_diagnosed.yaml");
  EXPECT_EQ(diag.status, 2) << diag.output;
  EXPECT_TRUE(contains(diag.output, "sbot_calibrate: --write-effects: cannot write '/proc/sbot_diagnosed.yaml': ")) << diag.output;
  EXPECT_FALSE(contains(diag.output, "VERDICT")) << "nothing was diagnosed: " << diag.output;

  const Outcome bad_base = run("fit " + kIrPoints + " --effect ir_reflectance --effects " + dir + "no_such.yaml --out " + dir +
                               "made/by/check/f.yaml");
  EXPECT_EQ(bad_base.status, 2) << bad_base.output;
  EXPECT_FALSE(exists(dir + "made")) << "the refused run created the folders of its --out";
  const Outcome bad_diag = run("diagnose " + kIrPoints + " --folds 0 --write-effects " + dir + "made/e.yaml");
  EXPECT_EQ(bad_diag.status, 2) << bad_diag.output;
  EXPECT_FALSE(exists(dir + "made")) << "the refused run created the folder of its --write-effects";
}

// `fit --out DATASET/dataset.yaml` must not replace the dataset with an effects file, nor
// `diagnose --write-effects` a run's CSV, nor `--no-align=false` turn alignment off.
TEST(Cli, TheDatasetsOwnFilesAreNotOverwrittenAndFlagsTakeNoValue) {
  const std::string dir = freshDir("cli_own_files");
  std::system(("cp -r " + kIrPoints + " " + dir + "ds").c_str());
  const std::string yaml = readFile(dir + "ds/dataset.yaml");
  const Outcome fit = run("fit " + dir + "ds --effect ir_reflectance --quiet --out " + dir + "ds/dataset.yaml");
  EXPECT_EQ(fit.status, 2) << fit.output;
  EXPECT_TRUE(contains(fit.output, "--out: '" + dir + "ds/dataset.yaml' is the dataset's own")) << fit.output;
  EXPECT_EQ(readFile(dir + "ds/dataset.yaml"), yaml) << "the dataset is kept";
  const Outcome diag = run("diagnose " + dir + "ds/ --quiet --write-effects " + dir + "ds/../ds/dataset.yaml");
  EXPECT_EQ(diag.status, 2) << diag.output;
  EXPECT_TRUE(contains(diag.output, "--write-effects: ")) << diag.output;
  EXPECT_EQ(readFile(dir + "ds/dataset.yaml"), yaml) << "the dataset is kept";
  const Outcome flag = run("compare " + dir + "ds --no-align=false --out " + dir + "report");
  EXPECT_EQ(flag.status, 2) << flag.output;
  EXPECT_TRUE(contains(flag.output, "--no-align is a flag and takes no value, found '--no-align=false'")) << flag.output;
}

// The effects library's loader took a stderr key that is no parameter and a surface no dataset can
// have: both would be dropped without a word.
TEST(Cli, AnEffectsFileWithAnUnknownSurfaceOrStderrKeyIsRefused) {
  const std::string dir = freshDir("cli_effects_file");
  writeFile(dir + "surface.yaml", "format: sbot-effects/1\neffects:\n  - name: ir_reflectance\n    params: {green_cheese: 0.5}\n");
  writeFile(dir + "stderr.yaml",
            "format: sbot-effects/1\neffects:\n  - name: latency\n    params: {delay: 0.1}\n    stderr: {dely: 0.01}\n");
  const Outcome surface = run("compare " + kIrPoints + " --quiet --no-plots --effects " + dir + "surface.yaml --out " + dir + "r1");
  EXPECT_EQ(surface.status, 2) << surface.output;
  EXPECT_TRUE(contains(surface.output, dir + "surface.yaml: field 'effects[0].params.green_cheese': ir_reflectance: unknown surface "
                                           "'green_cheese' (known: aluminium, black_card,"))
      << surface.output;
  const Outcome err = run("compare " + kIrPoints + " --quiet --no-plots --effects " + dir + "stderr.yaml --out " + dir + "r2");
  EXPECT_EQ(err.status, 2) << err.output;
  EXPECT_TRUE(contains(err.output, dir + "stderr.yaml: field 'effects[0].stderr.dely': a standard error for 'dely', which params does not give (params: delay)"))
      << err.output;
}

// A Fast robot (1/50 g) tips over in the generator's arcs, so even the true model cannot replay them
// from a start one sigma of the tracker noise away (evaluation.h, ReplaySensitivity): generate, fit and
// diagnose name them, fit leaves them out unless --keep-chaotic, and --skip-runs leaves out runs by name.
TEST(Cli, RunsTheModelCannotReplayAreNamedAndLeftOut) {
  // The command ends with `status` and prints every one of `parts`.
  auto expectRun = [](const std::string& args, int status, const std::vector<std::string>& parts) {
    const Outcome o = run(args);
    EXPECT_EQ(o.status, status) << args << ": " << o.output;
    for (const auto& p : parts) EXPECT_TRUE(contains(o.output, p)) << args << ": no '" << p << "' in " << o.output;
    return o.output;
  };
  const std::string dir = freshDir("cli_chaotic");
  expectRun("generate --out " + dir + "fast --level fast --seed 3 --families straight,arc --quiet", 0,
            {"note: the true model itself does not reproduce these runs", "arc_"});
  const std::string fit = "fit " + dir + "fast --effect speed_scale --quiet --max-iterations 2 --out " + dir;
  // straight_20/40/60 and the two arcs.
  const std::string skipped = expectRun(fit + "skipped.yaml", 0, {"leaving out ", "arc_right", "fit on "});
  EXPECT_FALSE(contains(skipped, "fit on 5 runs")) << skipped;
  // Its error figure is over the runs it fitted; the one compare will report, over all five, is
  // printed beside it and agrees with compare of the fitted file.
  const std::string all_runs = " on all 5 runs (what compare reports)";
  ASSERT_TRUE(contains(skipped, all_runs)) << skipped;
  const std::string before_all = skipped.substr(0, skipped.find(all_runs));
  const std::string fit_figures = before_all.substr(before_all.rfind("; ") + 2);  // "a -> b"
  const std::string compared = expectRun("compare " + dir + "fast --effects " + dir + "skipped.yaml --no-plots --quiet --out " +
                                             dir + "c_skipped", 0, {"error change (nRMS): "});
  const std::size_t at = compared.find("error change (nRMS): ") + std::string("error change (nRMS): ").size();
  EXPECT_EQ(compared.substr(at, fit_figures.size()), fit_figures) << skipped << "\n" << compared;
  expectRun(fit + "kept.yaml --keep-chaotic", 0,
            {"note: the start model does not reproduce these runs", "kept (--keep-chaotic)", "fit on 5 runs"});
  // straight_60 reads 1.0 from one side of its start, right at the bar: named with the arcs.
  const std::string named = expectRun(fit + "named.yaml --skip-runs arc_left,arc_right,straight_60", 0, {"fit on 2 runs"});
  EXPECT_FALSE(contains(named, "does not reproduce")) << named;
  // Only chaotic runs: nothing would be left, so they are kept, and that is said.
  expectRun(fit + "arcs.yaml --skip-runs straight_20,straight_40,straight_60", 0,
            {"kept (every run is: nothing would be left to fit)", "fit on 2 runs"});
  // diagnose's verdict says it is on the runs kept, and which were not looked at.
  expectRun("diagnose " + dir + "fast --candidates speed_scale,latency --quiet", 0,
            {" of 5 runs: ", "arc_left", "left out as not reproducible, and what only they show is not in this verdict"});
  const std::string kept = expectRun("diagnose " + dir + "fast --candidates speed_scale,latency --quiet --keep-chaotic", 0, {"VERDICT"});
  EXPECT_FALSE(contains(kept, "not in this verdict")) << kept;
  expectRun("compare " + dir + "fast --no-plots --quiet --skip-runs arc_left,spiral --out " + dir + "c", 2,
            {"has no run named spiral (its runs: "});
  expectRun(fit + "all.yaml --skip-runs arc_left,arc_right,straight_20,straight_40,straight_60", 2, {"leaves dataset"});
  EXPECT_FALSE(exists(dir + "all.yaml"));
  // sweep diagnoses each synthetic dataset without those runs, and says how many; --keep-chaotic keeps them.
  expectRun("sweep --quiet --level fast --cases none --seeds 1", 0, {"reproducibly left out", ") without "});
  const std::string all = expectRun("sweep --quiet --level fast --cases none --seeds 1 --keep-chaotic", 0, {"(--keep-chaotic)"});
  EXPECT_FALSE(contains(all, ") without ")) << all;
  expectRun("compare " + dir + "fast --no-plots --keep-chaotic --out " + dir + "c", 2,
            {"unknown option --keep-chaotic for 'compare'"});
}

TEST(Cli, TheOptionsItTakesAreAccepted) {
  const Outcome o = run("effects --jobs 1 --quiet");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("speed_scale"), std::string::npos) << o.output;
}

}  // namespace
