#include "sbot_sim/core/yaml_checks.h"

#include <map>

namespace sbot {

std::string duplicateKeyProblem(const YAML::Node& node) {
  if (node.IsSequence()) {
    for (const auto& item : node)
      if (std::string p = duplicateKeyProblem(item); !p.empty()) return p;
  } else if (node.IsMap()) {
    std::map<std::string, int> first_line;
    for (const auto& kv : node) {
      if (kv.first.IsScalar()) {
        const int line = kv.first.Mark().line + 1;
        const auto [it, fresh] = first_line.emplace(kv.first.Scalar(), line);
        if (!fresh)
          return "key '" + kv.first.Scalar() + "' appears twice in one mapping (lines " + std::to_string(it->second) +
                 " and " + std::to_string(line) + ")";
      }
      if (std::string p = duplicateKeyProblem(kv.second); !p.empty()) return p;
    }
  }
  return "";
}

}  // namespace sbot
