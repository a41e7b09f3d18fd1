// Command-line lists shared by the sbot_calibrate subcommands: comma lists, effect names and
// hidden-effect specs, and the checks the workbench adds to an effects file.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "sbot_sim/core/effects/effects_file.h"

namespace sbot::calib {

/// Split at `sep`, dropping empty items ("a,,b" -> {a, b}).
std::vector<std::string> splitList(const std::string& s, char sep);

/// Throws std::invalid_argument "OPTION: unknown effect 'x' (known: ...)" unless `name` is in the
/// effects library.
void requireEffect(const std::string& name, const std::string& option);

/// "speed_scale:scale=1.05+latency:delay=0.08" or "speed_scale:1.05" (single-parameter shorthand).
/// Validated against the effects library (unknown effect or parameter, a value that is not a number,
/// out of bounds, an unknown surface: errors naming `source`).
std::vector<EffectConfig> parseEffectList(const std::string& spec, const std::string& source);

/// loadEffectsConfig(path) and checkEffectSurfaces (effects_file.h) with the dataset's `surfaces`.
std::vector<EffectConfig> loadCheckedEffects(const std::string& path, const std::set<std::string>& surfaces = {});

}  // namespace sbot::calib
