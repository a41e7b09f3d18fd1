#include "sbot_sim/core/effects/effects_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <string_view>

#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/yaml_checks.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/world_config.h"

namespace sbot {
namespace {

std::string at(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  if (m.line < 0) return "";
  return " (line " + std::to_string(m.line + 1) + ", column " + std::to_string(m.column + 1) + ")";
}

std::map<std::string, double> numberMap(const YAML::Node& n, const std::string& field, const std::string& src) {
  std::map<std::string, double> out;
  if (!n || n.IsNull()) return out;
  if (!n.IsMap()) throw ConfigError(src, field, "expected a mapping of name: number" + at(n));
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    double v;
    try {
      v = kv.second.as<double>();
    } catch (const YAML::Exception&) {
      const std::string text = kv.second.IsScalar() ? kv.second.as<std::string>() : "<not a scalar>";
      throw ConfigError(src, field + "." + k, "expected a number, found '" + text + "'" + at(kv.second));
    }
    if (!std::isfinite(v)) throw ConfigError(src, field + "." + k, "must be a finite number" + at(kv.second));
    out[k] = v;
  }
  return out;
}

}  // namespace

std::vector<EffectConfig> parseEffectsConfig(const std::string& yaml_text, const std::string& src) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(src, "", "not valid YAML (line " + std::to_string(e.mark.line + 1) + "): " + e.msg);
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty()) throw ConfigError(src, "", problem);
  std::vector<EffectConfig> out;
  if (!root || root.IsNull()) return out;  // an empty file = no effects
  if (!root.IsMap()) throw ConfigError(src, "", "expected a mapping with an 'effects' list");
  for (const auto& kv : root) {
    const std::string k = kv.first.as<std::string>();
    if (k != "format" && k != "effects" && k != "name" && k != "description")
      throw ConfigError(src, k, "unknown field (expected format, effects, name, description)" + at(kv.first));
  }
  if (root["format"] && root["format"].as<std::string>() != "sbot-effects/1")
    throw ConfigError(src, "format", "unsupported format '" + root["format"].as<std::string>() +
                                         "' (expected sbot-effects/1)");
  const YAML::Node list = root["effects"];
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) throw ConfigError(src, "effects", "expected a list" + at(list));
  const EffectRegistry& reg = EffectRegistry::instance();
  std::set<std::string> seen;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string field = "effects[" + std::to_string(i) + "]";
    const YAML::Node e = list[i];
    if (!e.IsMap()) throw ConfigError(src, field, "expected a mapping {name, params}" + at(e));
    for (const auto& kv : e) {
      const std::string k = kv.first.as<std::string>();
      if (k != "name" && k != "params" && k != "stderr" && k != "note" && k != "ci95")
        throw ConfigError(src, field + "." + k, "unknown field (expected name, params, stderr, ci95, note)" + at(kv.first));
    }
    if (!e["name"]) throw ConfigError(src, field + ".name", "missing effect name" + at(e));
    if (!e["name"].IsScalar()) throw ConfigError(src, field + ".name", "must be one effect's name" + at(e["name"]));
    EffectConfig c;
    c.name = e["name"].as<std::string>();
    c.params = numberMap(e["params"], field + ".params", src);
    c.stderr_ = numberMap(e["stderr"], field + ".stderr", src);
    for (const auto& [k, v] : c.stderr_) {  // an uncertainty of a value the file does not give
      if (c.params.count(k)) continue;
      std::string given;
      for (const auto& [p, x] : c.params) given += (given.empty() ? "" : ", ") + p;
      throw ConfigError(src, field + ".stderr." + k,
                        "a standard error for '" + k + "', which params does not give (params: " +
                            (given.empty() ? "none" : given) + ")");
    }
    if (e["note"]) c.note = e["note"].as<std::string>();
    if (!seen.insert(c.name).second) throw ConfigError(src, field + ".name", "effect '" + c.name + "' listed twice");
    reg.create(c.name, c.params, src, field);  // validates name, parameter names and bounds
    out.push_back(c);
  }
  return out;
}

std::vector<EffectConfig> loadEffectsConfig(const std::string& path) {
  return parseEffectsConfig(readInputFile(path, "effects file"), path);
}

std::vector<EffectPtr> makeEffects(const std::vector<EffectConfig>& configs, const std::string& source) {
  std::vector<ParametricEffectPtr> out;
  const EffectRegistry& reg = EffectRegistry::instance();
  for (std::size_t i = 0; i < configs.size(); ++i)
    out.push_back(reg.create(configs[i].name, configs[i].params, source, "effects[" + std::to_string(i) + "]"));
  // Pipeline order, not listing order: effects do not commute (a motor asymmetry applied before or
  // after the turn slip of track_width differs by the width ratio), and a file is a set.
  std::stable_sort(out.begin(), out.end(), [&](const ParametricEffectPtr& a, const ParametricEffectPtr& b) {
    return reg.position(a->name()) < reg.position(b->name());
  });
  return {out.begin(), out.end()};
}

void checkEffectSurfaces(const std::vector<EffectConfig>& configs, const std::string& source,
                         const std::set<std::string>& world_surfaces) {
  const EffectRegistry& reg = EffectRegistry::instance();
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const EffectConfig& c = configs[i];
    if (!reg.info(c.name).open_params) continue;
    std::set<std::string> labels = knownSurfaces();
    labels.insert(world_surfaces.begin(), world_surfaces.end());
    for (const auto& entry : c.params) {
      if (labels.count(entry.first)) continue;
      throw ConfigError(source, "effects[" + std::to_string(i) + "].params." + entry.first,
                        c.name + ": unknown surface '" + entry.first + "' (known: " + nameList(labels) +
                            "; a dataset declares others under 'surfaces:', a scenario uses them on its boxes)");
    }
  }
}

std::vector<EffectPtr> loadEffectsFile(const std::string& path, const std::set<std::string>& world_surfaces) {
  const std::vector<EffectConfig> configs = loadEffectsConfig(path);
  checkEffectSurfaces(configs, path, world_surfaces);
  return makeEffects(configs, path);
}

std::string effectsToYaml(const std::vector<EffectConfig>& configs, const std::string& header) {
  std::ostringstream o;
  if (!header.empty()) {
    std::istringstream lines(header);
    for (std::string l; std::getline(lines, l);) o << "# " << l << "\n";
  }
  o << "format: sbot-effects/1\n";
  if (configs.empty()) {
    o << "effects: []\n";
    return o.str();
  }
  o << "effects:\n";
  // exact: the shortest text that reads back as the same double; otherwise 8 significant digits.
  auto map = [&o](const std::map<std::string, double>& m, bool exact) {
    o << std::setprecision(8) << "{";
    bool first = true;
    for (const auto& [k, v] : m) {
      o << (first ? "" : ", ") << k << ": ";
      if (exact) {
        char text[32];
        o << std::string_view(text, std::to_chars(text, text + sizeof text, v).ptr - text);
      } else {
        o << v;
      }
      first = false;
    }
    o << "}";
  };
  for (const auto& c : configs) {
    o << "  - name: " << c.name << "\n    params: ";
    // Every digit: a replay is chaotic enough that the 8 digits written before moved a fitted
    // Simple's error by 0.3 % (2.3969 in the fit, 2.4041 in compare of its file).
    map(c.params, true);
    o << "\n";
    if (!c.stderr_.empty()) {
      o << "    stderr: ";
      map(c.stderr_, false);
      o << "\n";
    }
    if (!c.note.empty()) o << "    note: " << YAML::Node(c.note) << "\n";
  }
  return o.str();
}

void writeEffectsFile(const std::string& path, const std::vector<EffectConfig>& configs, const std::string& header) {
  writeTextFile(path, effectsToYaml(configs, header));
}

}  // namespace sbot
