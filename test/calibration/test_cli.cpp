// The sbot_calibrate command line: options a subcommand does not take are refused with a message that
// names them (a misspelt --effects used to be ignored, so `compare --effect F` compared the nominal
// model), and so are bad values of the ones it does take.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "../common/run_process.h"

namespace {

using Outcome = sbot_test::ProcessOutcome;

Outcome run(const std::string& args) { return sbot_test::runProcess(std::string(SBOT_CALIBRATE_BIN) + " " + args); }

const std::string kExample = std::string(SWARMBOT3D_SOURCE_DIR) + "/datasets/example";

TEST(Cli, AnOptionTheSubcommandDoesNotTakeIsRefusedByName) {
  const Outcome o = run("compare " + kExample + " --effect fitted.yaml --no-plots --out " + testing::TempDir() + "cli_typo");
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find("unknown option --effect for 'compare'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("--effects"), std::string::npos) << "lists what it takes: " << o.output;
  const Outcome d = run("diagnose " + kExample + " --treshold 5");
  EXPECT_EQ(d.status, 1) << d.output;
  EXPECT_NE(d.output.find("unknown option --treshold for 'diagnose'"), std::string::npos) << d.output;
  // Last on the line, a misspelt option is named as such (it used to "need a value").
  const Outcome last = run("compare " + kExample + " --no-plot");
  EXPECT_EQ(last.status, 1) << last.output;
  EXPECT_NE(last.output.find("unknown option --no-plot for 'compare'"), std::string::npos) << last.output;
}

TEST(Cli, ABadSolverIsRefusedByName) {
  const Outcome o = run("compare " + kExample + " --solver fast --no-plots --out " + testing::TempDir() + "cli_solver");
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find("--solver expects quickstep or exact, got 'fast'"), std::string::npos) << o.output;
}

// An output place that cannot be written is refused before the work (a fit or a diagnosis runs for
// minutes): compare and fit used to compute, then print "report: DIR/report.md" or lose the fitted
// effects file, with exit status 0.
TEST(Cli, AnOutputPlaceThatCannotBeWrittenIsRefusedBeforeTheWork) {
  const std::string dir = testing::TempDir() + "cli_out/";
  std::system(("rm -rf " + dir + " && mkdir -p " + dir + " && touch " + dir + "plain").c_str());
  auto refused = [](const Outcome& o, const std::string& message) {
    EXPECT_EQ(o.status, 1) << o.output;
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

// The plot script is started without a shell: an output folder with a quote in its name used to
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

TEST(Cli, TheOptionsItTakesAreAccepted) {
  const Outcome o = run("effects --jobs 1 --quiet");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("speed_scale"), std::string::npos) << o.output;
}

}  // namespace
