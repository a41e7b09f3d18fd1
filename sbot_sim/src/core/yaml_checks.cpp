#include "sbot_sim/core/yaml_checks.h"

#include "sbot_sim/core/errors.h"

#include <map>
#include <vector>

namespace sbot {
namespace {

/// Nodes visited with aliases expanded. yaml-cpp shares an aliased node instead of copying it, so a
/// file of a few lines can stand for 10^11 nodes ("billion laughs"); no configuration comes near.
constexpr long kMaxExpandedNodes = 1000000;

struct Walk {
  std::vector<YAML::Node> ancestors;  // the path from the root: an alias to one of them is a cycle
  long visited = 0;
};

std::string problemIn(const YAML::Node& node, Walk& w) {
  if (++w.visited > kMaxExpandedNodes)
    return "more than " + std::to_string(kMaxExpandedNodes) +
           " values once its aliases (*name) are expanded: aliases nested to multiply a document are refused";
  for (const YAML::Node& a : w.ancestors)
    if (a.is(node))
      return "an alias refers to a value that contains it (anchor at line " + std::to_string(node.Mark().line + 1) +
             "): recursive YAML is refused";
  if (!node.IsSequence() && !node.IsMap()) return "";
  w.ancestors.push_back(node);
  std::string problem;
  if (node.IsSequence()) {
    for (const auto& item : node)
      if (problem = problemIn(item, w); !problem.empty()) break;
  } else {
    std::map<std::string, int> first_line;
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) {
        problem = "a key at line " + std::to_string(kv.first.Mark().line + 1) +
                  " is not a name (a list, a mapping or nothing: `? [a, b]: ...`); keys here are names";
        break;
      }
      const int line = kv.first.Mark().line + 1;
      const auto [it, fresh] = first_line.emplace(kv.first.Scalar(), line);
      if (!fresh) {
        problem = "key '" + kv.first.Scalar() + "' appears twice in one mapping (lines " + std::to_string(it->second) +
                  " and " + std::to_string(line) + ")";
        break;
      }
      if (problem = problemIn(kv.second, w); !problem.empty()) break;
    }
  }
  w.ancestors.pop_back();
  return problem;
}

}  // namespace

std::string yamlStructureProblem(const YAML::Node& node) {
  Walk w;
  return problemIn(node, w);
}

YAML::Node unknownKey(const YAML::Node& node, const std::set<std::string>& allowed) {
  if (node && node.IsMap())
    for (const auto& kv : node)
      if (!allowed.count(kv.first.as<std::string>())) return kv.first;
  return YAML::Node(YAML::NodeType::Undefined);  // false (a default Node is a defined null)
}

std::string unknownFieldMessage(const std::set<std::string>& allowed) {
  return "unknown field (expected one of: " + nameList(allowed) + ")";
}

}  // namespace sbot
