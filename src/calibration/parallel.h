// Parallel re-simulation in forked worker processes.
//
// Why processes and not threads: ODE's QuickStep shuffles constraints with ONE process-global
// random generator, which sbot::World::step() reseeds every step so a run is bit-identical whatever
// else happened in the process. Worlds stepping in parallel threads would share (and race on) that
// generator, so the same parameters would not give the same trajectory and finite-difference
// Jacobians would be noise. Forked workers each own a private copy of the generator (and of every
// other global), are fully deterministic, and need no locking. Results come back serialised
// through pipes (serialize.h). A map() called inside a worker runs inline.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "calibration/serialize.h"

namespace sbot::calib {

/// A worker process of WorkerPool::map ended by a signal (what() names it): a crash, not a refusal.
class WorkerCrashed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class WorkerPool {
 public:
  explicit WorkerPool(int processes = 0);  ///< 0 = number of cores
  int size() const { return procs_; }

  /// fn(0..n-1) in up to size() forked workers (dynamic load balancing); results in index order.
  /// Runs inline when size() == 1, n <= 1 or when called from inside a worker. A task that throws
  /// makes map() throw (with the task's message) after all workers have finished.
  /// `done(i)` (optional) is called in the calling process as each result arrives (progress bars).
  std::vector<std::string> mapBytes(std::size_t n, const std::function<std::string(std::size_t)>& fn,
                                    const std::function<void(std::size_t)>& done = nullptr);

  template <class R>
  std::vector<R> map(std::size_t n, const std::function<R(std::size_t)>& fn,
                     const std::function<void(std::size_t)>& done = nullptr) {
    const auto bytes = mapBytes(
        n,
        [&fn](std::size_t i) {
          Writer w;
          save(w, fn(i));
          return w.str();
        },
        done);
    std::vector<R> out(n);
    for (std::size_t i = 0; i < n; ++i) {
      Reader r(bytes[i]);
      load(r, out[i]);
    }
    return out;
  }

  /// True inside a forked worker.
  static bool inWorker();
  /// A work counter (e.g. run replays) that survives forking: increments made by a task in a worker
  /// are added to the caller's counter when its result arrives.
  static void count(long units = 1);
  static long counted();
  /// The process-wide pool (size = --jobs, default: all cores).
  static WorkerPool& global();
  static void setGlobalSize(int processes);

 private:
  int procs_;
};

}  // namespace sbot::calib
