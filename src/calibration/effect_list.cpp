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
      if (!info.params.empty() && (colon == std::string::npos || colon + 1 == e.size())) {
        // Its defaults would be taken silently: for most effects the nominal model, nothing hidden.
        std::string params;
        for (const auto& p : info.params) params += (params.empty() ? "" : ", ") + p.name;
        throw std::invalid_argument(source + " '" + e + "': give the values (e.g. " + c.name + ":" +
                                    info.params.front().name + "=...; parameters: " + params + ")");
      }
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
  checkEffectSurfaces(out, source);
  return out;
}

std::vector<EffectConfig> loadCheckedEffects(const std::string& path, const std::set<std::string>& surfaces) {
  std::vector<EffectConfig> configs = loadEffectsConfig(path);
  checkEffectSurfaces(configs, path, surfaces);
  return configs;
}

}  // namespace sbot::calib
