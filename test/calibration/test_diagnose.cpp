// `diagnose` on synthetic data with known hidden effects (the reduced set of the statistical sweep;
// the full figures, 10 seeds per case, come from `sbot_calibrate sweep`, docs/calibration.md).
// Each case must hold in every seed here: the right effect accepted first with parameters within
// +-10 % (of their departure from null), held-out error halved and ending within 1.2x the noise
// floor; nothing accepted without a hidden effect; a floor tilt (not in the library) accepted as
// nothing, with the residual flagged; two hidden effects both found, both within +-10 %.
#include <gtest/gtest.h>

#include <algorithm>

#include "calibration/sweep.h"

namespace sbot::calib {
namespace {

class DiagnoseReduced : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    SweepOptions o;
    o.seeds = 2;
    o.first_seed = 101;
    o.gen.level = "simple";
    o.gen.duration = 5;
    for (const auto& c : standardCases("simple"))
      if (c.name == "speed_scale" || c.name == "latency" || c.name == "none" || c.name == "tilt2" ||
          c.name == "speed_scale+latency" || c.name == "ir_incidence")  // IR: Medium, place runs
        o.cases.push_back(c);
    results_ = new std::vector<CaseSummary>(runSweep(o, WorkerPool::global()));
    std::printf("%s\n", sweepMarkdown(*results_, o, 0).c_str());
  }
  static void TearDownTestSuite() { delete results_; }
  static const CaseSummary& result(const std::string& name) {
    for (const auto& c : *results_)
      if (c.c.name == name) return c;
    throw std::runtime_error("no case " + name);
  }
  static std::vector<CaseSummary>* results_;
};
std::vector<CaseSummary>* DiagnoseReduced::results_ = nullptr;

TEST_F(DiagnoseReduced, SingleHiddenEffectsAreFoundAndFitted) {
  for (const char* name : {"speed_scale", "latency", "ir_incidence"}) {
    const CaseSummary& c = result(name);
    EXPECT_EQ(c.right_first, 1.0) << name << ": accepted first";
    EXPECT_EQ(c.params_within, 1.0) << name << ": parameters within 10 %";
    EXPECT_EQ(c.rmse_halved, 1.0) << name << ": held-out error halved";
    EXPECT_EQ(c.at_floor, 1.0) << name << ": ends within 1.2x the noise floor";
    EXPECT_EQ(c.failing_halved, 1.0) << name << ": error halved on the channels where the model failed";
    EXPECT_EQ(c.failing_at_floor, 1.0) << name << ": ends within 1.2x their floor";
  }
}

TEST_F(DiagnoseReduced, NothingIsAcceptedWithoutAHiddenEffect) {
  EXPECT_EQ(result("none").none_accepted, 1.0);
}

TEST_F(DiagnoseReduced, AnEffectOutsideTheLibraryIsFlaggedNotExplained) {
  const CaseSummary& c = result("tilt2");
  EXPECT_EQ(c.none_accepted, 1.0) << "nothing accepted with strong evidence";
  EXPECT_EQ(c.flagged, 1.0) << "residual structure flagged";
}

TEST_F(DiagnoseReduced, TwoHiddenEffectsAreBothFound) {
  const CaseSummary& c = result("speed_scale+latency");
  EXPECT_EQ(c.both_found, 1.0);
  EXPECT_EQ(c.params_within, 1.0) << "both effects' parameters within 10 %";
}

}  // namespace
}  // namespace sbot::calib
