// A worker process of WorkerPool that dies by a signal is reported as a crash naming the signal
// (WorkerCrashed; sbot_calibrate exits 3), not as a task's refusal (exit 1 or 2).
#include <gtest/gtest.h>

#include <signal.h>

#include <string>

#include "calibration/parallel.h"

namespace sbot::calib {
namespace {

TEST(WorkerCrash, AWorkerKilledByASignalIsReportedAsACrashNamingIt) {
  WorkerPool pool(2);
  try {
    pool.mapBytes(4, [](std::size_t i) -> std::string {
      if (i == 2) ::raise(SIGSEGV);
      return "ok";
    });
    ADD_FAILURE() << "a crashed worker went unreported";
  } catch (const WorkerCrashed& e) {
    EXPECT_NE(std::string(e.what()).find("a worker process crashed: killed by signal 11 (Segmentation fault)"),
              std::string::npos) << e.what();
  }
  // A task that throws is a failure, not a crash.
  try {
    pool.mapBytes(4, [](std::size_t i) -> std::string {
      if (i == 1) throw std::runtime_error("task 1 refused");
      return "ok";
    });
    ADD_FAILURE() << "a throwing task went unreported";
  } catch (const WorkerCrashed& e) {
    ADD_FAILURE() << "reported as a crash: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("task 1 refused"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sbot::calib
