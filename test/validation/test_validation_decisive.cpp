// The decisive cells of the seed's hardware validation (Tables 4.1-4.3) on the Detailed model, one
// trial each, run in 2 processes (~12 s). The full suite with 12 trials per cell is `sbot_validate`.
//
// Cells the current model does not match yet have a recorded reason in
// config/validation/mismatch_reasons.yaml (the report prints it under the cell): for them the test
// prints the outcome but does not fail, so that the suite guards every matched cell against
// regressions. When such a cell starts to match, the test says so: remove its reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "experiments.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot_description.h"
#include "mismatch_reasons.h"

namespace v = sbot::validation;

namespace {

struct Cell {
  std::string what;
  std::string expect;
  std::function<v::Outcome()> run;
};

/// The cells the validation report explains as not matching (the same file sbot_validate reads).
v::MismatchReasons knownMismatches() {
  return v::MismatchReasons::load(std::string(SWARMBOT3D_SOURCE_DIR) + "/" + v::kMismatchReasonsFile);
}

/// Tables 4.2 and 4.3's apparatus (reference_tables.yaml: track_mu: lab_floor).
const v::Drive kLabFloor{v::kSlowUnits, v::kLabFloorTrackMu};

}  // namespace

TEST(ValidationDecisive, HardwareCells) {
  const std::vector<Cell> cells{
      // Tables 4.2 and 4.3 run on the lab floor (reference_tables.yaml: track_mu: lab_floor).
      {"4.2 45 mm", "pass", [] { return v::gapTrial("detailed", 0.045, 0, kLabFloor); }},
      {"4.2 55 mm", "fall inside", [] { return v::gapTrial("detailed", 0.055, 0, kLabFloor); }},  // hardware: "failing to overcome it"
      {"4.3 15 mm forward", "pass", [] { return v::stepTrial("detailed", 0.015, false, 0, kLabFloor); }},
      {"4.3 23 mm forward", "pass", [] { return v::stepTrial("detailed", 0.023, false, 0, kLabFloor); }},
      {"4.3 24 mm forward", "fail", [] { return v::stepTrial("detailed", 0.024, false, 0, kLabFloor); }},
      {"4.3 15 mm backward", "pass", [] { return v::stepTrial("detailed", 0.015, true, 0, kLabFloor); }},
      {"4.3 16 mm backward", "fail", [] { return v::stepTrial("detailed", 0.016, true, 0, kLabFloor); }},
      // The two cells the Detailed turret's COM is calibrated on (sbot_parameters.yaml): 12/12 each.
      {"4.1 20 deg rear uphill", "difficult",
       [] { return v::slopeHoldClimbTrial("detailed", 20 * M_PI / 180, true, 0); }},
      {"4.3 10 mm backward", "pass", [] { return v::stepTrial("detailed", 0.010, true, 0, kLabFloor); }},
      {"4.1 30 deg rear uphill", "topple b/w",
       [] { return v::slopeHoldClimbTrial("detailed", 30 * M_PI / 180, true, 0); }},
  };
  const v::MismatchReasons known_mismatches = knownMismatches();
  const auto res = v::runParallel(static_cast<int>(cells.size()), 2, [&](int i) { return cells[i].run(); });
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const bool ok = v::accepts(cells[i].expect, res[i].label);
    const bool known = known_mismatches.explains(cells[i].what);
    std::printf("[decisive] %-24s seed %-11s ours %-11s %s\n", cells[i].what.c_str(), cells[i].expect.c_str(),
                res[i].label.c_str(),
                ok ? (known ? "MATCH (now matches: remove its reason)" : "match") : (known ? "known mismatch" : "MISMATCH"));
    EXPECT_NE(res[i].label, "error") << cells[i].what;
    if (!known) {
      EXPECT_TRUE(ok) << cells[i].what << ": seed " << cells[i].expect << ", ours " << res[i].label << " (value "
                      << res[i].value << ", " << res[i].value2 << ")";
    }
  }
}

TEST(ValidationCompatibility, EveryLevelsConnectedPairStandsAtItsScaledDistance) {
  // Seed 2.1.3: two s-bots connected by the front gripper are the same distance apart at every
  // level (0.147 m centre to centre; the half-size Fast pair half of it), standing and after
  // reversing together (the link holds).
  const std::vector<std::string>& levels = sbot::modelLevels();
  const auto r = v::runParallel(static_cast<int>(levels.size()), 2, [&](int i) { return v::connectedPairTrial(levels[i]); });
  for (std::size_t i = 0; i < levels.size(); ++i) {
    ASSERT_NE(r[i].label, "error") << levels[i];
    const double scale = v::lengthScale(levels[i]);
    EXPECT_NEAR(r[i].value / scale, 0.147, 0.003) << levels[i] << " standing";
    EXPECT_NEAR(r[i].value2 / scale, 0.147, 0.003) << levels[i] << " after reversing";
  }
}

TEST(ValidationCompatibility, EveryLevelReachesTheDetailedModelsSteadySpeedWithinThreePercent) {
  // Seed 2.1.3, the first half of compatibility: at the same setSpeed on flat ground every level
  // reaches the same steady speed within 3 % (the report's compatibility table: the Detailed model
  // is the reference), and that speed is the API's 50 x 0.28 cm/s (Table 2.2's speed unit).
  const std::vector<std::string>& levels = sbot::modelLevels();
  const auto r = v::runParallel(static_cast<int>(levels.size()), 2, [&](int i) { return v::steadySpeedTrial(levels[i], 50); });
  const auto detailed = std::find(levels.begin(), levels.end(), "detailed");
  ASSERT_NE(detailed, levels.end());
  const double reference = r[detailed - levels.begin()].value;
  EXPECT_NEAR(reference, 0.14, 0.03 * 0.14) << "Detailed at setSpeed(50, 50)";
  for (std::size_t i = 0; i < levels.size(); ++i) {
    ASSERT_NE(r[i].label, "error") << levels[i];
    EXPECT_NEAR(r[i].value, reference, 0.03 * reference) << levels[i] << " against the Detailed model's " << reference << " m/s";
  }
}

TEST(ValidationFacts, DetailedTipsOverItsFrontNearTheStaticLimit) {
  // The centre of mass 1.5 cm ahead of the centre wheels and 4.6 cm above the ground (the turret's
  // calibrated COM), the front axle 4 cm ahead: facing downhill the robot tips at
  // atan(0.025 / 0.046) = 28.5 deg. Quickstep's compliance at the level's 40 iterations lowers it
  // to ~26 deg (200 iterations: 29.5). Facing uphill the offset holds it until the treels slide
  // (tan 45 deg = mu 1.0).
  const auto r = v::runParallel(2, 2, [](int i) { return v::tippingAngle("detailed", i == 0); });
  EXPECT_EQ(r[0].label, "tipped");
  EXPECT_GT(r[0].value, 22.0) << "rear uphill: the hardware climbs 20 deg";
  EXPECT_LT(r[0].value, 30.0) << "rear uphill: the hardware topples at 30 deg";
  EXPECT_LT(r[1].value2, 48.0) << "front uphill: slides";
  EXPECT_GT(r[1].value2, 38.0) << "front uphill: slides near atan(mu)";
  EXPECT_LT(r[1].value2, r[1].value) << "front uphill: slides before it tips";
}

TEST(ValidationModal, ATieListsEveryLabelInTheOrderItReachedTheCount) {
  // The report prints a tie as one and tallies it as a match only if the seed accepts every tied
  // label (sbot_validate's modalCell): which label reaches the count first is only trial order.
  auto outcomes = [](std::vector<std::string> labels) {
    std::vector<v::Outcome> o;
    for (auto& l : labels) o.push_back(v::Outcome{l});
    return o;
  };
  const auto tie = outcomes({"slide back", "topple", "topple", "slide back", "stuck"});
  EXPECT_EQ(v::modalLabels(tie), (std::vector<std::string>{"topple", "slide back"}));
  int count = 0;
  EXPECT_EQ(v::modal(tie, &count), "topple");
  EXPECT_EQ(count, 2);
  const auto clear = outcomes({"stuck", "topple", "topple", "pass"});
  EXPECT_EQ(v::modalLabels(clear), (std::vector<std::string>{"topple"}));
  EXPECT_TRUE(v::modalLabels({}).empty());
}

TEST(ValidationFast, CrossesHalvedGapsItsFrontCasterDropsInto) {
  // Table 4.5's Fast row (the half-size robot crosses each gap halved): its 1 cm front caster drops
  // into any halved gap from 4.5 cm. It crosses up to 5.7 cm (seed: up to 6.0) only because its
  // body drive acts as a wheel drive does on the chassis (Robot::applyBodyDrive: the motors'
  // reaction torque, and the tracks' speed held relative to the pitching chassis); without either
  // it was stuck from 4.5 cm. At 6.5 cm it is stuck, as the seed's.
  EXPECT_EQ(v::gapTrial("fast", 0.045, 0).label, "pass");
  EXPECT_EQ(v::gapTrial("fast", 0.057, 0).label, "pass");
  EXPECT_EQ(v::gapTrial("fast", 0.065, 0).label, "stuck");
}

TEST(ValidationDownhill, DetailedManagesAGentleRampAndTopplesForwardOnSteeperOnes) {
  // 4.2.4: all models manage downhill slopes up to about 0.5 rad; steeper ones topple them forward.
  // The Detailed model tips over its front statically at ~26-28.5 deg (the test above): it manages
  // 0.3 rad (17 deg) and topples at 0.8 rad (46 deg). At 0.5 rad (28.6 deg) it pitches 84 deg onto
  // its held gripper and slides down on it, which the trial counts as the topple it is (tilted
  // > 45 deg off the ramp's normal; counting only > 100 deg off vertical, this would be a "pass").
  const std::vector<double> angles{0.3, 0.5, 0.8};
  const auto r = v::runParallel(3, 2, [&](int i) { return v::downhillTrial("detailed", angles[i], 0); });
  EXPECT_EQ(r[0].label, "pass") << "0.3 rad";
  EXPECT_EQ(r[1].label, "topple") << "0.5 rad";
  EXPECT_EQ(r[2].label, "topple") << "0.8 rad";
}

TEST(ValidationLabels, ARobotThatRearsOverAtTheRampsFootHasToppled) {
  // Table 4.6: a Medium at 0.9 and 1.0 rad gets its front up the face with its rear spheres wedged
  // in the ramp's foot, rears onto its tail (86-90 deg) and falls on its side. A rule counting a
  // robot on the floor as toppled only from 100 deg off vertical would label these trials "slide
  // back", the seed's label.
  const std::vector<std::pair<double, int>> trials{{1.0, 0}, {0.9, 1}};
  const auto res = v::runParallel(static_cast<int>(trials.size()), 2,
                                  [&](int i) { return v::uphillTrial("medium", trials[i].first, trials[i].second); });
  for (std::size_t i = 0; i < trials.size(); ++i)
    EXPECT_EQ(res[i].label, "topple") << trials[i].first << " rad, trial " << trials[i].second;
}

TEST(StepStatics, ColinearAxlesPitchByTheStepOverTheAxleSpacing) {
  v::SideView s;
  s.centre_radius = s.front_radius = 0.02;
  s.front_axle_x = 0.04;
  EXPECT_NEAR(v::pitchOnStep(s, 0.0), 0.0, 1e-12);
  EXPECT_NEAR(v::pitchOnStep(s, 0.01), std::asin(0.25), 1e-12);
  // A larger centre wheel on the same axle line stands the robot nose down by its extra radius.
  s.centre_radius = 0.022;
  EXPECT_NEAR(v::pitchOnStep(s, 0.01), std::asin(0.3), 1e-12);
}

TEST(StepStatics, TheCentreOfMassAheadOfTheCornerTipsTheRobot) {
  v::SideView s;
  s.centre_radius = s.front_radius = 0.02;
  s.front_axle_x = 0.04;
  // Centre of mass on the centre axle: the corner (at most r behind the front axle) stays ahead of it.
  EXPECT_DOUBLE_EQ(v::cornerTipHeight(s), 0.02);
  // h = 10 mm: pitch asin(1/4), front axle 0.04 cos p ahead, corner sqrt(r^2 - (r - h)^2) = 17.3 mm behind it.
  const double p = std::asin(0.25), corner = 0.04 * std::cos(p) - std::sqrt(0.02 * 0.02 - 0.01 * 0.01);
  s.com_z = 0.025;
  s.com_x = (corner - s.com_z * std::sin(p)) / std::cos(p);  // exactly above the corner at 10 mm
  EXPECT_NEAR(v::cornerMargin(s, 0.01), 0.0, 1e-12);
  EXPECT_NEAR(v::cornerTipHeight(s), 0.01, 1e-6);
  EXPECT_NEAR(v::comXForCornerTip(s, 0.01), s.com_x, 1e-12);
  EXPECT_NEAR(v::comZForCornerTip(s, 0.01), s.com_z, 1e-12);
  s.com_x -= 0.002;  // further back: it takes a higher step to tip it
  EXPECT_GT(v::cornerTipHeight(s), 0.011);
  // Lower: likewise (pitched nose down, a lower centre of mass swings less far forward).
  v::SideView low = s;
  low.com_z = 0.015;
  EXPECT_GT(v::cornerTipHeight(low), v::cornerTipHeight(s));
  EXPECT_LT(v::comZForCornerTip(s, 0.015), s.com_z);
  // Facing downhill it tips when the COM passes over the front wheel's contact: atan((x_f - x) / (z + r)).
  EXPECT_NEAR(v::frontTipSlope(s), std::atan2(0.04 - s.com_x, 0.045), 1e-12);
}

TEST(StepStatics, PredictsWhereTheDetailedModelTopplesReversingOntoAStep) {
  // The statics are only worth quoting in the report if the simulated robot follows them: it passes
  // 1 mm below the static limit and topples 3 mm above it (measured: static 10.2 mm, trials pass at
  // 11 and topple from 12; with the turret COM moved back 1 and 2 cm, static 13.2 / 16.3 mm against
  // trial limits of 14 / 16 mm).
  const double tip = v::cornerTipHeight(v::sideView("detailed"));
  ASSERT_GT(tip, 0.004);
  const auto r = v::runParallel(2, 2, [&](int i) { return v::stepTrial("detailed", tip + (i == 0 ? -0.001 : 0.003), true, 0); });
  EXPECT_EQ(r[0].label, "pass") << "reversing onto " << (tip - 0.001) * 1000 << " mm";
  EXPECT_EQ(r[1].label, "topple") << "reversing onto " << (tip + 0.003) * 1000 << " mm";
}

TEST(StepStatics, RefusesALevelWithoutFrontWheels) {
  // Simple drives on two centre wheels and casters: there is no front wheel to meet the step's face.
  try {
    v::sideView("simple");
    FAIL() << "expected a ConfigError";
  } catch (const sbot::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("front wheel"), std::string::npos) << e.what();
  }
}
