// Run a command line in a shell for a test and keep its exit status and output (stdout and stderr):
// the command-line tests of sbot_calibrate and of the headless tools.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace sbot_test {

struct ProcessOutcome {
  int status = -1;      ///< exit status; -1 if it did not exit normally
  std::string output;   ///< stdout and stderr
};

inline ProcessOutcome runProcess(const std::string& command_line) {
  ProcessOutcome o;
  FILE* p = popen((command_line + " 2>&1").c_str(), "r");
  if (!p) return o;
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = fread(buf.data(), 1, buf.size(), p)) > 0;) o.output.append(buf.data(), n);
  const int st = pclose(p);
  o.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return o;
}

}  // namespace sbot_test
