// Command-line lists shared by the sbot_calibrate subcommands: comma lists and hidden-effect specs.
#pragma once

#include <string>
#include <vector>

#include "sbot_sim/core/effects/effects_file.h"

namespace sbot::calib {

/// Split at `sep`, dropping empty items ("a,,b" -> {a, b}).
std::vector<std::string> splitList(const std::string& s, char sep);

/// "speed_scale:scale=1.05+latency:delay=0.08" or "speed_scale:1.05" (single-parameter shorthand).
/// Validated against the effects library (unknown effect or parameter, out of bounds: ConfigError
/// naming `source`).
std::vector<EffectConfig> parseEffectList(const std::string& spec, const std::string& source);

}  // namespace sbot::calib
