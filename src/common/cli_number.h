// Command-line numbers for the headless tools (sbot_validate, switching_experiment, two_sbots): a
// value that is not a finite number inside its range is refused with a message that names the
// option and what was found (exit status 2), instead of atoi/atof's silent 0.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace sbot_tools {

inline double numberArg(const char* tool, const std::string& option, const std::string& text, double min,
                        double max) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v) || v < min || v > max) {
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

}  // namespace sbot_tools
