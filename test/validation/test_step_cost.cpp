// Table 4.4's "what limits it" (profileTrial, StepCost): the phases of a profiled step share its wall
// time, and the solver-alone ceiling the report prints beside each target is the level's step over
// the solver's time per step, so it can never be below the RTM measured with everything else on.
#include <gtest/gtest.h>

#include "experiments.h"

namespace v = sbot::validation;

namespace {

TEST(StepCost, SolverAloneRtmIsTheStepOverTheSolversTimePerStep) {
  v::StepCost c;
  c.step_s = 0.01;            // 10 ms
  c.wall_us_per_step = 20.0;  // 20 us per step in all ...
  c.solver = 0.5;             // ... half of it in the solver: 10 us
  EXPECT_DOUBLE_EQ(c.solverAloneRtm(), 1000.0);
  c.solver = 0;  // nothing measured: no ceiling, rather than a division by zero
  EXPECT_DOUBLE_EQ(c.solverAloneRtm(), 0.0);
}

TEST(StepCost, AProfiledSimpleStepIsSplitIntoPhasesBelowItsCeiling) {
  const v::StepCost c = v::profileTrial("simple", 2.0);
  EXPECT_DOUBLE_EQ(c.step_s, 0.01);  // the Simple level's recommended step (Table 4.4)
  EXPECT_EQ(c.bodies, 4);
  EXPECT_GT(c.contacts_per_step, 0.0);
  EXPECT_GT(c.solver, 0.0);
  const double phases = c.solver + c.collision + c.sensors + c.commands + c.feedback;
  EXPECT_LE(phases, 1.0 + 1e-9);  // fractions of one wall time
  EXPECT_GT(phases, 0.5);         // the loop around them is not where a step's time goes
  EXPECT_GT(c.rtm, 0.0);
  EXPECT_GE(c.solverAloneRtm(), c.rtm);  // the solver's share of a step is at most all of it
}

}  // namespace
