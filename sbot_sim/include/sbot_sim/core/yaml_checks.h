// Checks on parsed YAML that yaml-cpp does not make itself.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

namespace sbot {

/// The first key repeated within one mapping anywhere in `node`, as "key 'k' appears twice in one
/// mapping (lines L1 and L2)", or "" if there is none. yaml-cpp keeps both copies and answers
/// node["k"] with the first, so a repeated key silently loses the value written last (a second
/// `report:` in a tables file dropped a whole table).
std::string duplicateKeyProblem(const YAML::Node& node);

}  // namespace sbot
