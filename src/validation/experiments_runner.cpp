// Running trials in worker processes (runParallel) and reading their outcomes (accepts, modal).
#include "experiments.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

namespace sbot {
namespace validation {

namespace {

// The workers of the round in progress and their result files, for the interrupt handler: a
// Ctrl-C or SIGTERM of sbot_validate must not leave workers running on, re-parented to init, nor
// result files in /tmp. Plain arrays: a signal handler may only touch what is async-signal-safe.
constexpr int kMaxWorkers = 256;
volatile sig_atomic_t g_worker_count = 0;
pid_t g_worker_pids[kMaxWorkers];
char g_worker_files[kMaxWorkers][32];

void stopWorkersAndExit(int sig) {
  for (int k = 0; k < g_worker_count; ++k) {
    if (g_worker_pids[k] > 0) kill(g_worker_pids[k], SIGKILL);
    unlink(g_worker_files[k]);
  }
  _exit(128 + sig);
}

/// One round: `jobs` spread over up to `processes` workers (worker k takes jobs k, k + P, ...).
/// Fills `out` with what the workers reported; returns the jobs a crashed worker did not report,
/// in the order it would have run them, one list per crashed worker.
std::vector<std::vector<int>> runRound(const std::vector<int>& jobs, int processes, const std::function<Outcome(int)>& fn,
                                       std::vector<Outcome>& out, std::vector<bool>& reported) {
  const int n = static_cast<int>(jobs.size());
  processes = std::max(1, std::min({processes, n, kMaxWorkers}));
  std::vector<std::string> files;
  std::vector<pid_t> pids;
  std::vector<int> slice;  // the worker index k of each started worker
  std::fflush(stdout);
  std::fflush(stderr);
  struct sigaction stop {}, old_int {}, old_term {};
  stop.sa_handler = stopWorkersAndExit;
  sigemptyset(&stop.sa_mask);
  sigaction(SIGINT, &stop, &old_int);
  sigaction(SIGTERM, &stop, &old_term);
  g_worker_count = 0;
  for (int k = 0; k < processes; ++k) {
    char tmpl[] = "/tmp/sbot_validate_XXXXXX";
    const int fd = mkstemp(tmpl);
    if (fd < 0) {  // its trials stay "error" in the report; say why
      std::fprintf(stderr, "sbot_validate: worker %d of %d not started: cannot create a result file in /tmp: %s\n", k + 1,
                   processes, std::strerror(errno));
      continue;
    }
    close(fd);
    const pid_t pid = fork();
    if (pid < 0) {
      std::fprintf(stderr, "sbot_validate: worker %d of %d not started: fork: %s\n", k + 1, processes, std::strerror(errno));
      std::remove(tmpl);
      continue;
    }
    if (pid == 0) {
      signal(SIGINT, SIG_DFL);
      signal(SIGTERM, SIG_DFL);
      std::ofstream f(tmpl);
      for (int i = k; i < n; i += processes) {
        const int job = jobs[i];
        Outcome o{"error"};
        try {
          o = fn(job);
        } catch (const std::exception& e) {
          std::fprintf(stderr, "sbot_validate: job %d: %s\n", job, e.what());
        }
        std::string label = o.label;
        std::replace(label.begin(), label.end(), '\t', ' ');
        f << job << '\t' << label << '\t' << o.value << '\t' << o.value2 << '\n';
        f.flush();
      }
      f.close();
      std::_Exit(0);
    }
    std::snprintf(g_worker_files[g_worker_count], sizeof(g_worker_files[0]), "%s", tmpl);
    g_worker_pids[g_worker_count] = pid;
    g_worker_count = g_worker_count + 1;
    files.push_back(tmpl);
    pids.push_back(pid);
    slice.push_back(k);
  }
  std::vector<bool> crashed(pids.size(), false);
  for (std::size_t w = 0; w < pids.size(); ++w) {
    int status = 0;
    waitpid(pids[w], &status, 0);
    if (WIFSIGNALED(status)) {
      crashed[w] = true;
      std::fprintf(stderr, "sbot_validate: a worker process died of signal %d (%s)\n", WTERMSIG(status),
                   strsignal(WTERMSIG(status)));
    }
  }
  for (const auto& name : files) {
    std::ifstream f(name);
    std::string line;
    while (std::getline(f, line)) {
      std::stringstream ss(line);
      std::string idx, label, v1, v2;
      std::getline(ss, idx, '\t');
      std::getline(ss, label, '\t');
      std::getline(ss, v1, '\t');
      std::getline(ss, v2, '\t');
      const int i = std::atoi(idx.c_str());
      if (i >= 0 && i < static_cast<int>(out.size())) {
        out[i] = Outcome{label, std::atof(v1.c_str()), std::atof(v2.c_str())};
        reported[i] = true;
      }
    }
    std::remove(name.c_str());
  }
  g_worker_count = 0;
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  std::vector<std::vector<int>> unfinished;
  for (std::size_t w = 0; w < pids.size(); ++w) {
    if (!crashed[w]) continue;
    std::vector<int> left;
    for (int i = slice[w]; i < n; i += processes)
      if (!reported[jobs[i]]) left.push_back(jobs[i]);
    unfinished.push_back(left);
  }
  return unfinished;
}

}  // namespace

std::vector<Outcome> runParallel(int n, int processes, const std::function<Outcome(int)>& fn) {
  std::vector<Outcome> out(n, Outcome{"error"});
  std::vector<bool> reported(n, false);
  std::vector<int> pending(n);
  for (int i = 0; i < n; ++i) pending[i] = i;
  // A worker that crashes (a signal, e.g. an ODE assertion) takes down the trial it was running:
  // that one stays "error"; the trials it had not reached run again in the next round, so that one
  // bad cell does not cost its neighbours their results.
  while (!pending.empty()) {
    const std::vector<std::vector<int>> unfinished = runRound(pending, processes, fn, out, reported);
    pending.clear();
    for (const std::vector<int>& left : unfinished) {
      if (left.empty()) continue;
      std::fprintf(stderr, "sbot_validate: job %d crashed its worker and is marked error; %zu unfinished job(s) run again\n",
                   left.front(), left.size() - 1);
      pending.insert(pending.end(), left.begin() + 1, left.end());
    }
    std::sort(pending.begin(), pending.end());
  }
  return out;
}

bool accepts(const std::string& expected, const std::string& ours) {
  std::stringstream ss(expected);
  for (std::string e; std::getline(ss, e, '|');) {
    if (e == ours) return true;
    if (e == "stuck" && ours == "fall inside") return true;
    if (e == "fall inside" && ours == "stuck") return true;
    if (e == "fail" && ours == "topple") return true;
  }
  return false;
}

std::vector<std::string> modalLabels(const std::vector<Outcome>& outcomes, int* count) {
  std::map<std::string, int> counts;
  int best_n = 0;
  for (const auto& o : outcomes) best_n = std::max(best_n, ++counts[o.label]);
  // A second pass in input order: a label joins when its running count reaches the modal count.
  std::map<std::string, int> running;
  std::vector<std::string> labels;
  for (const auto& o : outcomes)
    if (++running[o.label] == best_n) labels.push_back(o.label);
  if (count) *count = best_n;
  return labels;
}

std::string modal(const std::vector<Outcome>& outcomes, int* count) {
  const std::vector<std::string> labels = modalLabels(outcomes, count);
  return labels.empty() ? std::string() : labels.front();
}

}  // namespace validation
}  // namespace sbot
