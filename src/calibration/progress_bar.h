// A progress bar on stderr for the calibration's long stages: "label [####......] done/total  s".
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace sbot::calib {

class ProgressBar {
 public:
  ProgressBar(bool on, std::string label, std::size_t total)
      : on_(on), label_(std::move(label)), total_(total), start_(std::chrono::steady_clock::now()) {
    draw();
  }
  void tick() {
    ++done_;
    draw();
  }
  void finish() {
    if (!on_) return;
    done_ = total_.load();
    draw();
    std::fprintf(stderr, "\n");
  }

 private:
  void draw() {
    if (!on_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t t = std::max<std::size_t>(1, total_), d = std::min<std::size_t>(done_, t);
    const int width = 30;
    const int fill = static_cast<int>(width * d / t);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fprintf(stderr, "\r%-28s [%s%s] %3zu/%zu  %5.1f s", label_.c_str(), std::string(fill, '#').c_str(),
                 std::string(width - fill, '.').c_str(), d, t, secs);
    std::fflush(stderr);
  }
  bool on_;
  std::string label_;
  std::atomic<std::size_t> total_, done_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
};

}  // namespace sbot::calib
