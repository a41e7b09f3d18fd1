#include "calibration/parallel.h"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <thread>

namespace sbot::calib {
namespace {

bool g_in_worker = false;
int g_size = 0;
std::atomic<long> g_counter{0};

void writeAll(int fd, const void* data, std::size_t len) {
  const char* p = static_cast<const char*>(data);
  while (len > 0) {
    const ssize_t k = ::write(fd, p, len);
    if (k < 0) {
      if (errno == EINTR) continue;
      _exit(3);
    }
    p += k;
    len -= static_cast<std::size_t>(k);
  }
}

// Frame: u32 index, u8 ok, u64 length, i64 counter delta, bytes.
constexpr std::size_t kHead = 21;
void writeFrame(int fd, std::uint32_t index, bool ok, const std::string& payload, long counted) {
  std::string head(kHead, '\0');
  std::memcpy(&head[0], &index, 4);
  head[4] = ok ? 1 : 0;
  const std::uint64_t len = payload.size();
  std::memcpy(&head[5], &len, 8);
  const std::int64_t c = counted;
  std::memcpy(&head[13], &c, 8);
  writeAll(fd, head.data(), head.size());
  writeAll(fd, payload.data(), payload.size());
}

}  // namespace

WorkerPool::WorkerPool(int processes) {
  procs_ = processes > 0 ? processes : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

bool WorkerPool::inWorker() { return g_in_worker; }
void WorkerPool::count(long units) { g_counter += units; }
long WorkerPool::counted() { return g_counter.load(); }

WorkerPool& WorkerPool::global() {
  static WorkerPool pool(g_size);
  return pool;
}

void WorkerPool::setGlobalSize(int processes) { g_size = processes; }

std::vector<std::string> WorkerPool::mapBytes(std::size_t n, const std::function<std::string(std::size_t)>& fn,
                                              const std::function<void(std::size_t)>& done) {
  std::vector<std::string> out(n);
  const int procs = static_cast<int>(std::min<std::size_t>(procs_, n));
  if (n == 0) return out;
  if (procs <= 1 || g_in_worker) {
    for (std::size_t i = 0; i < n; ++i) {
      out[i] = fn(i);
      if (done) done(i);
    }
    return out;
  }
  // Task queue: every index written up front into a pipe; workers read 4-byte indices (atomic
  // reads below PIPE_BUF) until EOF. Beyond the pipe's capacity, indices are dealt statically.
  const bool queue = n * 4 <= 60000;
  int task_pipe[2] = {-1, -1};
  if (queue) {
    if (::pipe(task_pipe) != 0) throw std::runtime_error("pipe() failed");
    for (std::uint32_t i = 0; i < n; ++i) writeAll(task_pipe[1], &i, 4);
  }
  std::fflush(stdout);
  std::fflush(stderr);
  std::vector<int> fds(procs, -1);
  std::vector<pid_t> pids(procs, -1);
  for (int p = 0; p < procs; ++p) {
    int rp[2];
    if (::pipe(rp) != 0) throw std::runtime_error("pipe() failed");
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error("fork() failed");
    if (pid == 0) {
      g_in_worker = true;
      ::close(rp[0]);
      for (int q = 0; q < p; ++q) ::close(fds[q]);
      if (queue) ::close(task_pipe[1]);
      auto runOne = [&](std::uint32_t i) {
        const long c0 = g_counter.load();
        try {
          std::string r = fn(i);
          writeFrame(rp[1], i, true, r, g_counter.load() - c0);
        } catch (const std::exception& e) {
          writeFrame(rp[1], i, false, e.what(), g_counter.load() - c0);
        } catch (...) {
          writeFrame(rp[1], i, false, "unknown error", g_counter.load() - c0);
        }
      };
      if (queue) {
        std::uint32_t i;
        for (;;) {
          const ssize_t k = ::read(task_pipe[0], &i, 4);
          if (k == 4) runOne(i);
          else if (k < 0 && errno == EINTR) continue;
          else break;
        }
      } else {
        for (std::size_t i = p; i < n; i += procs) runOne(static_cast<std::uint32_t>(i));
      }
      ::close(rp[1]);
      std::fflush(stderr);
      _exit(0);
    }
    ::close(rp[1]);
    fds[p] = rp[0];
    pids[p] = pid;
  }
  if (queue) {
    ::close(task_pipe[0]);
    ::close(task_pipe[1]);
  }
  // Collect frames from every worker until all pipes are closed.
  std::vector<std::string> buf(procs);
  std::vector<bool> open(procs, true);
  std::vector<bool> got(n, false);
  std::string first_error;
  int open_count = procs;
  std::vector<char> chunk(1 << 16);
  while (open_count > 0) {
    std::vector<pollfd> pfd;
    std::vector<int> which;
    for (int p = 0; p < procs; ++p)
      if (open[p]) {
        pfd.push_back({fds[p], POLLIN, 0});
        which.push_back(p);
      }
    if (::poll(pfd.data(), pfd.size(), -1) < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("poll() failed");
    }
    for (std::size_t k = 0; k < pfd.size(); ++k) {
      if (!(pfd[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const int p = which[k];
      const ssize_t r = ::read(fds[p], chunk.data(), chunk.size());
      if (r > 0) {
        buf[p].append(chunk.data(), static_cast<std::size_t>(r));
        // Parse complete frames.
        std::size_t pos = 0;
        while (buf[p].size() - pos >= kHead) {
          std::uint32_t idx;
          std::uint64_t len;
          std::int64_t counted;
          std::memcpy(&idx, &buf[p][pos], 4);
          const bool ok = buf[p][pos + 4] != 0;
          std::memcpy(&len, &buf[p][pos + 5], 8);
          std::memcpy(&counted, &buf[p][pos + 13], 8);
          if (buf[p].size() - pos - kHead < len) break;
          std::string payload = buf[p].substr(pos + kHead, len);
          pos += kHead + len;
          g_counter += counted;
          if (idx < n) {
            got[idx] = true;
            if (ok) out[idx] = std::move(payload);
            else if (first_error.empty()) first_error = payload;
            if (done) done(idx);
          }
        }
        buf[p].erase(0, pos);
      } else if (r == 0 || (r < 0 && errno != EINTR)) {
        ::close(fds[p]);
        open[p] = false;
        --open_count;
      }
    }
  }
  bool crashed = false;
  std::string signalled;  // the first worker killed by a signal, named
  for (int p = 0; p < procs; ++p) {
    int status = 0;
    ::waitpid(pids[p], &status, 0);
    crashed |= !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    if (WIFSIGNALED(status) && signalled.empty())
      signalled = "a worker process crashed: killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
                  strsignal(WTERMSIG(status)) + ")";
  }
  if (!signalled.empty()) throw WorkerCrashed(signalled);
  if (!first_error.empty()) throw std::runtime_error(first_error);
  for (std::size_t i = 0; i < n; ++i)
    if (!got[i]) throw std::runtime_error(std::string("a worker process died") + (crashed ? " (crash)" : ""));
  return out;
}

}  // namespace sbot::calib
