#include "calibration/effect_list.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "calibration/dataset.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/errors.h"

namespace sbot::calib {

std::vector<std::string> splitList(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, sep);)
    if (!x.empty()) out.push_back(x);
  return out;
}

void requireEffect(const std::string& name, const std::string& option) {
  const EffectRegistry& reg = EffectRegistry::instance();
  if (reg.has(name)) return;
  std::string known;
  for (const auto& n : reg.names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument(option + ": unknown effect '" + name + "' (known: " + known + ")");
}

std::vector<EffectConfig> parseEffectList(const std::string& spec, const std::string& source) {
  std::vector<EffectConfig> out;
  for (const auto& item : splitList(spec, ';')) {
    for (const auto& e : splitList(item, '+')) {
      const auto colon = e.find(':');
      EffectConfig c;
      c.name = e.substr(0, colon);
      requireEffect(c.name, source);
      const EffectInfo& info = EffectRegistry::instance().info(c.name);
      if (colon != std::string::npos) {
        for (const auto& kv : splitList(e.substr(colon + 1), ',')) {
          const auto eq = kv.find('=');
          const std::string param = eq == std::string::npos ? info.params.front().name : kv.substr(0, eq);
          const std::string text = eq == std::string::npos ? kv : kv.substr(eq + 1);
          char* end = nullptr;
          errno = 0;
          const double v = std::strtod(text.c_str(), &end);
          if (text.empty() || *end || errno == ERANGE || !std::isfinite(v))
            throw std::invalid_argument(source + " '" + e + "': " + c.name + "." + param + " expects a finite number, got '" +
                                        text + "'");
          c.params[param] = v;
        }
      }
      out.push_back(c);
    }
  }
  makeEffects(out, source);  // validate
  checkEffectConfigs(out, source);
  return out;
}

void checkEffectConfigs(const std::vector<EffectConfig>& configs, const std::string& source,
                        const std::set<std::string>& surfaces) {
  const EffectRegistry& reg = EffectRegistry::instance();
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const EffectConfig& c = configs[i];
    const EffectInfo& info = reg.info(c.name);
    const std::string field = "effects[" + std::to_string(i) + "]";
    if (info.open_params) {
      std::set<std::string> labels = knownSurfaces();
      labels.insert(surfaces.begin(), surfaces.end());
      for (const auto& [surface, v] : c.params) {
        if (labels.count(surface)) continue;
        std::string list;
        for (const auto& l : labels) list += (list.empty() ? "" : ", ") + l;
        throw ConfigError(source, field + ".params." + surface,
                          c.name + ": unknown surface '" + surface + "' (known: " + list +
                              "; a dataset declares others under 'surfaces:' and uses them on its obstacles)");
      }
    }
    // (A stderr for a value params does not give is refused by the core's loader.)
  }
}

std::vector<EffectConfig> loadCheckedEffects(const std::string& path, const std::set<std::string>& surfaces) {
  std::vector<EffectConfig> configs = loadEffectsConfig(path);
  checkEffectConfigs(configs, path, surfaces);
  return configs;
}

}  // namespace sbot::calib
