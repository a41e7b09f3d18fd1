// Effects files: which library effects are switched on, with which parameters. Written by
// `sbot_calibrate fit`, read by the calibration workbench, the simulator node and scenarios.
//
//   format: sbot-effects/1          # optional
//   effects:
//     - name: speed_scale           # a registered effect (effect_registry.h)
//       params: {scale: 1.04}       # missing parameters take their null value (effect off)
//       stderr: {scale: 0.002}      # optional, informational (standard errors from a fit)
//       note: "fitted on datasets/example"   # optional
//
// Every error is an sbot::ConfigError naming the file and the field (e.g. effects[1].params.scale).
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "sbot_sim/core/effects.h"

namespace sbot {

struct EffectConfig {
  std::string name;
  std::map<std::string, double> params;
  std::map<std::string, double> stderr_;  ///< optional standard errors (same keys as params)
  std::string note;
};

std::vector<EffectConfig> parseEffectsConfig(const std::string& yaml_text, const std::string& source);
std::vector<EffectConfig> loadEffectsConfig(const std::string& path);
/// Validate (names, parameters, bounds) and instantiate, in pipeline order (the registry's), not
/// in the order listed.
std::vector<EffectPtr> makeEffects(const std::vector<EffectConfig>& configs, const std::string& source = "<effects>");
/// A per-surface parameter (ir_reflectance) must name a surface of the library (knownSurfaces,
/// world_config.h) or of `world_surfaces` (a scenario's or dataset's obstacles): any other label
/// (a typo) would never act. ConfigError naming `source`, the field and the labels it may name.
void checkEffectSurfaces(const std::vector<EffectConfig>& configs, const std::string& source,
                         const std::set<std::string>& world_surfaces = {});
/// Read, validate (names, parameters, bounds, surfaces) and instantiate an effects file.
std::vector<EffectPtr> loadEffectsFile(const std::string& path, const std::set<std::string>& world_surfaces = {});

std::string effectsToYaml(const std::vector<EffectConfig>& configs, const std::string& header_comment = "");
void writeEffectsFile(const std::string& path, const std::vector<EffectConfig>& configs,
                      const std::string& header_comment = "");

}  // namespace sbot
