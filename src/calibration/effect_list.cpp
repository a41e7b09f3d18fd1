#include "calibration/effect_list.h"

#include <sstream>

#include "sbot_sim/core/effects/effect_registry.h"

namespace sbot::calib {

std::vector<std::string> splitList(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, sep);)
    if (!x.empty()) out.push_back(x);
  return out;
}

std::vector<EffectConfig> parseEffectList(const std::string& spec, const std::string& source) {
  std::vector<EffectConfig> out;
  for (const auto& item : splitList(spec, ';')) {
    for (const auto& e : splitList(item, '+')) {
      const auto colon = e.find(':');
      EffectConfig c;
      c.name = e.substr(0, colon);
      const EffectInfo& info = EffectRegistry::instance().info(c.name);
      if (colon != std::string::npos) {
        for (const auto& kv : splitList(e.substr(colon + 1), ',')) {
          const auto eq = kv.find('=');
          if (eq == std::string::npos) c.params[info.params.front().name] = std::stod(kv);
          else c.params[kv.substr(0, eq)] = std::stod(kv.substr(eq + 1));
        }
      }
      out.push_back(c);
    }
  }
  makeEffects(out, source);  // validate
  return out;
}

}  // namespace sbot::calib
