// Decisive cells of the two-connected-s-bot rows (seed Table 4.1, 4.1.3) on the Detailed level:
// the pair climbs fully at 29 deg but not at 32 and does not topple at 58 deg where a single s-bot topples; the
// pair passes a 32 mm step going backwards (the holder lifting itself with its gripper arm) where a
// single s-bot going backwards fails.
#include <gtest/gtest.h>

#include <cmath>

#include "two_sbots_trials.h"

namespace {

constexpr double kDeg = M_PI / 180;

TEST(TwoSbots, SlopeRows) {
  // The default set-up: Coulomb treels on Table 4.1's polystyrene (mu 2), creeping as everywhere.
  // Limit of full manoeuvrability 29 deg: climb efficiency 0.86 there, 0.84 at 32 deg (the tracks'
  // creep); limit of stable position 58-72 deg: upright at 58 deg, where a single s-bot topples.
  two_sbots::SlopeSetup single;
  single.pair = false;
  EXPECT_EQ(two_sbots::pairSlope("detailed", 29 * kDeg, 0).label, "full");
  EXPECT_EQ(two_sbots::pairSlope("detailed", 32 * kDeg, 0).label, "difficult");
  EXPECT_NE(two_sbots::pairSlope("detailed", 58 * kDeg, 0).label, "topple");
  EXPECT_EQ(two_sbots::pairSlope("detailed", 58 * kDeg, 0, single).label, "topple");
  // The seed's own friction set-up for this experiment (force limit 1.2 N per contact) stands at
  // 58 deg too.
  two_sbots::SlopeSetup seed_pair, seed_single;
  seed_pair.seed_friction = seed_single.seed_friction = true;
  seed_single.pair = false;
  EXPECT_NE(two_sbots::pairSlope("detailed", 58 * kDeg, 0, seed_pair).label, "topple");
  EXPECT_EQ(two_sbots::pairSlope("detailed", 58 * kDeg, 0, seed_single).label, "topple");
}

TEST(TwoSbots, StepPassing32mm) {
  for (int trial = 0; trial < 2; ++trial) {
    EXPECT_EQ(two_sbots::stepBackward("detailed", 0.032, trial, true, false).label, "pass") << trial;
    EXPECT_NE(two_sbots::stepBackward("detailed", 0.032, trial, false, false).label, "pass") << trial;
  }
}

}  // namespace
