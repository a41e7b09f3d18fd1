// The decisive cells of the seed's hardware validation (Tables 4.1-4.3) on the Detailed model, one
// trial each, run in 2 processes (~10 s). The full suite with 12 trials per cell is `sbot_validate`.
//
// Cells the current model does not match yet (see src/validation/README.md, "Why cells do not
// match") are listed in kKnownMismatch: for them the test prints the outcome but does not fail, so
// that the suite guards every matched cell against regressions. When a known cell starts to match,
// the test says so: remove it from the list.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "experiments.h"

namespace v = sbot::validation;

namespace {

struct Cell {
  std::string what;
  std::string expect;
  std::function<v::Outcome()> run;
};

// Our Detailed model climbs ~26 mm forward, crosses 55 mm gaps (the held front gripper props it on
// the far edge), and tips forward onto its gripper when it reverses up any step from 10 mm: see
// the README.
const std::set<std::string> kKnownMismatch{"gap 55 mm (Table 4.2)", "step 24 mm forward (Table 4.3)",
                                           "step 15 mm backward (Table 4.3)"};

}  // namespace

TEST(ValidationDecisive, HardwareCells) {
  const std::vector<Cell> cells{
      {"gap 45 mm (Table 4.2)", "pass", [] { return v::gapTrial("detailed", 0.045, 0); }},
      {"gap 55 mm (Table 4.2)", "stuck", [] { return v::gapTrial("detailed", 0.055, 0); }},
      {"step 15 mm forward (Table 4.3)", "pass", [] { return v::stepTrial("detailed", 0.015, false, 0); }},
      {"step 23 mm forward (Table 4.3)", "pass", [] { return v::stepTrial("detailed", 0.023, false, 0); }},
      {"step 24 mm forward (Table 4.3)", "fail", [] { return v::stepTrial("detailed", 0.024, false, 0); }},
      {"step 15 mm backward (Table 4.3)", "pass", [] { return v::stepTrial("detailed", 0.015, true, 0); }},
      {"step 16 mm backward (Table 4.3)", "fail", [] { return v::stepTrial("detailed", 0.016, true, 0); }},
      {"slope 30 deg, rear uphill (Table 4.1)", "topple b/w",
       [] { return v::slopeHoldClimbTrial("detailed", 30 * M_PI / 180, true, 0); }},
  };
  const auto res = v::runParallel(static_cast<int>(cells.size()), 2, [&](int i) { return cells[i].run(); });
  for (std::size_t i = 0; i < cells.size(); ++i) {
    std::string got = res[i].label;
    if (cells[i].expect == "fail" && got == "topple") got = "fail";  // toppling off a step fails it
    const bool known = kKnownMismatch.count(cells[i].what) != 0;
    std::printf("[decisive] %-40s seed %-11s ours %-11s %s\n", cells[i].what.c_str(), cells[i].expect.c_str(),
                res[i].label.c_str(),
                got == cells[i].expect ? (known ? "MATCH (now matches: remove from kKnownMismatch)" : "match")
                                       : (known ? "known mismatch" : "MISMATCH"));
    EXPECT_NE(res[i].label, "error") << cells[i].what;
    if (!known) {
      EXPECT_EQ(got, cells[i].expect) << cells[i].what << " (value " << res[i].value << ", " << res[i].value2 << ")";
    }
  }
}

TEST(ValidationFacts, DetailedTipsOverItsFrontNearTheStaticLimit) {
  // The centre of mass 1.9 cm ahead of the centre wheels and 4.9 cm above the ground, the front
  // axle 4 cm ahead: facing downhill the robot tips at atan(0.021 / 0.049) = 23 deg. Quickstep's
  // compliance at the level's 40 iterations lowers it to ~20 deg (200 iterations: 23.5). Facing
  // uphill the offset holds it until the treels slide (tan 45 deg = mu 1.0).
  const auto r = v::runParallel(2, 2, [](int i) { return v::tippingAngle("detailed", i == 0); });
  EXPECT_EQ(r[0].label, "tipped");
  EXPECT_GT(r[0].value, 17.0);
  EXPECT_LT(r[0].value, 24.5);
  EXPECT_LT(r[1].value2, 48.0) << "front uphill: slides";
  EXPECT_GT(r[1].value2, 38.0) << "front uphill: slides near atan(mu)";
  EXPECT_LT(r[1].value2, r[1].value) << "front uphill: slides before it tips";
}
