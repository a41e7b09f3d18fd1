// Command-line options of the headless tools (sbot_validate, switching_experiment, two_sbots, sbot_bench): an
// option missing its value, or a value that is not a finite number inside its range, is refused with
// a message that names the tool, the option and what was found (exit status 2), instead of
// atoi/atof's silent 0 or an empty string.
#pragma once

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot_tools {

/// Exit statuses, one rule for every tool (sbot_bench, sbot_validate, sbot_calibrate,
/// switching_experiment, two_sbots; simulator_node ends with 1 on a failure):
///   0  done;
///   2  bad input (an option, a file, a field) refused before any work: no result written, no row printed;
///   1  a failure during the work (a run that threw, an ODE error: sbot_sim/src/core/ode_errors.h);
///   3  a worker process crashed (killed by a signal), reported as a crash with the signal's name.
/// A tool with several failures exits with the most severe: 3 over 1.
constexpr int kExitDone = 0, kExitFailure = 1, kExitBadInput = 2, kExitCrash = 3;

/// The exit status a worker's waitpid `status` contributes (kExitDone, kExitFailure or kExitCrash);
/// a crash is reported as "TOOL: WHAT crashed: killed by signal N (NAME)".
inline int workerOutcome(const char* tool, const std::string& what, int status) {
  if (WIFSIGNALED(status)) {
    std::fprintf(stderr, "%s: %s crashed: killed by signal %d (%s)\n", tool, what.c_str(), WTERMSIG(status),
                 strsignal(WTERMSIG(status)));
    return kExitCrash;
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? kExitDone : kExitFailure;
}
/// The more severe of two exit statuses (kExitCrash over kExitFailure over kExitDone).
inline int worseExit(int a, int b) {
  auto rank = [](int s) { return s == kExitCrash ? 3 : s == kExitBadInput ? 2 : s == kExitFailure ? 1 : 0; };
  return rank(a) >= rank(b) ? a : b;
}

inline double numberArg(const char* tool, const std::string& option, const std::string& text, double min,
                        double max) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  // strtod also reads hexadecimal ("0x10" = 16), which no one means on a command line.
  const bool hex = text.find_first_of("xX") != std::string::npos;
  if (text.empty() || *end != '\0' || hex || !std::isfinite(v) || v < min || v > max) {
    std::fprintf(stderr, "%s: %s expects a number in [%g, %g], found '%s'\n", tool, option.c_str(), min, max,
                 text.c_str());
    std::exit(2);
  }
  return v;
}

/// A whole number in [min, max].
inline int countArg(const char* tool, const std::string& option, const std::string& text, int min, int max) {
  const double v = numberArg(tool, option, text, min, max);
  if (v != std::floor(v)) {
    std::fprintf(stderr, "%s: %s expects a whole number, found '%s'\n", tool, option.c_str(), text.c_str());
    std::exit(2);
  }
  return static_cast<int>(v);
}

/// The model description of `level` loads (an unknown level, or a $SBOT_DESCRIPTION_DIR without it,
/// would abort the tool at its first trial): else "TOOL: WHAT: why" and exit status 2.
inline void requireLevel(const char* tool, const std::string& what, const std::string& level) {
  try {
    sbot::loadLevel(level);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s: %s\n", tool, what.c_str(), e.what());
    std::exit(2);
  }
}

/// The tool's output directory `dir` (option `option`) is created with its parents and can be
/// written (sbot::makeOutputDirectory), checked before the work whose results it will hold: else
/// "TOOL: OPTION: why" and exit status 2.
inline void requireOutputDirectory(const char* tool, const std::string& option, const std::string& dir) {
  try {
    sbot::makeOutputDirectory(dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s: %s\n", tool, option.c_str(), e.what());
    std::exit(2);
  }
}

/// Walks one tool's argv: option() is the next argument, value()/number()/count() the one after it.
///   sbot_tools::ArgReader args("sbot_validate", argc, argv);
///   while (args.more()) { const std::string a = args.option(); if (a == "--trials") trials = args.count(1, 1000); ... }
class ArgReader {
 public:
  ArgReader(const char* tool, int argc, char** argv) : tool_(tool), argc_(argc), argv_(argv) {}
  bool more() const { return i_ + 1 < argc_; }
  const std::string& option() {
    option_ = argv_[++i_];
    return option_;
  }
  /// The current option's value; missing: exit 2 with "TOOL: OPTION needs a value" (or, for an
  /// option of several values, "TOOL: OPTION needs WHAT": "--trial needs LEVEL PARAM after KIND").
  std::string value(const std::string& what = "a value") {
    if (!more()) {
      std::fprintf(stderr, "%s: %s needs %s\n", tool_, option_.c_str(), what.c_str());
      std::exit(2);
    }
    return argv_[++i_];
  }
  /// The next argument, not consumed (more() must be true).
  std::string peek() const { return argv_[i_ + 1]; }
  double number(double min, double max) { return numberArg(tool_, option_, value(), min, max); }
  int count(int min, int max) { return countArg(tool_, option_, value(), min, max); }
  const char* tool() const { return tool_; }

 private:
  const char* tool_;
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string option_;
};

}  // namespace sbot_tools
