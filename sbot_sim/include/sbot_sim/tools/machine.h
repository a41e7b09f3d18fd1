// The machine a benchmark figure was measured on, printed beside it by the headless tools
// (sbot_bench's header line, sbot_validate's Table 4.4). A real-time multiplier means little without
// it: the same build ran Table 4.4 40-50 % slower on one 2-core VM than on another
// (docs/benchmarks.md, the Table 4.4 rows of two machines).
#pragma once

#include <unistd.h>

#include <fstream>
#include <istream>
#include <sstream>
#include <string>

namespace sbot_tools {

/// "MODEL, N cores, BogoMIPS B" from the text of /proc/cpuinfo (x86: "model name" and "bogomips"
/// lines; a field missing is left out, and a processor that names no model is "unknown processor").
inline std::string describeProcessor(std::istream& cpuinfo, long cores) {
  auto trim = [](const std::string& t) {
    const std::size_t first = t.find_first_not_of(" \t\r");
    return first == std::string::npos ? std::string() : t.substr(first, t.find_last_not_of(" \t\r") - first + 1);
  };
  std::string model, bogomips, line;
  while (std::getline(cpuinfo, line)) {  // the first processor's lines name them all
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = trim(line.substr(0, colon));
    if (model.empty() && key == "model name") model = trim(line.substr(colon + 1));
    if (bogomips.empty() && (key == "bogomips" || key == "BogoMIPS")) bogomips = trim(line.substr(colon + 1));
  }
  std::ostringstream out;
  out << (model.empty() ? "unknown processor" : model);
  if (cores > 0) out << ", " << cores << (cores == 1 ? " core" : " cores");
  if (!bogomips.empty()) out << ", BogoMIPS " << bogomips;
  return out.str();
}

/// This machine, as describeProcessor reads it from /proc/cpuinfo and the online core count.
inline std::string describeThisMachine() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  return describeProcessor(cpuinfo, sysconf(_SC_NPROCESSORS_ONLN));
}

}  // namespace sbot_tools
