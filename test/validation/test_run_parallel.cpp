// runParallel (experiments.h), the worker processes every validation table runs its trials in: each
// outcome lands at its job's index, a job that throws is that job's "error" alone, and a worker that
// dies (a signal, which it cannot report itself) costs only the job it was running, which is reported
// on stderr, where the report's "error" cells can be traced back to it.
#include <gtest/gtest.h>

#include <csignal>
#include <stdexcept>
#include <string>

#include "experiments.h"

namespace v = sbot::validation;

namespace {

TEST(RunParallel, EveryOutcomeLandsAtItsJobsIndex) {
  const auto r = v::runParallel(7, 3, [](int i) { return v::Outcome{"job" + std::to_string(i), 0.5 * i, -1.0 * i}; });
  ASSERT_EQ(r.size(), 7u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(r[i].label, "job" + std::to_string(i));
    EXPECT_DOUBLE_EQ(r[i].value, 0.5 * i);
    EXPECT_DOUBLE_EQ(r[i].value2, -1.0 * i);
  }
}

TEST(RunParallel, AJobThatThrowsIsThatJobsErrorAlone) {
  testing::internal::CaptureStderr();
  const auto r = v::runParallel(4, 2, [](int i) {
    if (i == 1) throw std::runtime_error("bad cell");
    return v::Outcome{"ok"};
  });
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(r[0].label, "ok");
  EXPECT_EQ(r[1].label, "error");
  EXPECT_EQ(r[2].label, "ok");
  EXPECT_EQ(r[3].label, "ok");
  EXPECT_NE(err.find("sbot_validate: job 1: bad cell"), std::string::npos) << err;
}

TEST(RunParallel, AWorkerThatDiesCostsOnlyTheJobItWasRunning) {
  testing::internal::CaptureStderr();
  // Two workers: jobs 0, 2, 4 and 1, 3, 5. The first dies in job 2 (as an ODE assertion aborts); job
  // 4, which it had not reached, runs again in a fresh worker (it is not "error").
  const auto r = v::runParallel(6, 2, [](int i) {
    if (i == 2) std::raise(SIGKILL);
    return v::Outcome{"ok", static_cast<double>(i)};
  });
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(r[0].label, "ok") << "finished before the worker died";
  EXPECT_EQ(r[2].label, "error");
  EXPECT_EQ(r[4].label, "ok") << "not reached by the worker that died: run again";
  EXPECT_DOUBLE_EQ(r[4].value, 4.0);
  for (int i : {1, 3, 5}) EXPECT_EQ(r[i].label, "ok") << i;
  EXPECT_NE(err.find("sbot_validate: a worker process died of signal 9 (Killed)"), std::string::npos) << err;
  EXPECT_NE(err.find("sbot_validate: job 2 crashed its worker and is marked error; 1 unfinished job(s) run again"),
            std::string::npos)
      << err;
}

// Every job crashes: each is an error once, and the rounds end.
TEST(RunParallel, JobsThatAllCrashEndAsErrors) {
  testing::internal::CaptureStderr();
  const auto r = v::runParallel(5, 2, [](int) -> v::Outcome { std::raise(SIGKILL); return {}; });
  testing::internal::GetCapturedStderr();
  for (const auto& o : r) EXPECT_EQ(o.label, "error");
}

}  // namespace
