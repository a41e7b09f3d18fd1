// Checks on parsed YAML that yaml-cpp does not make itself.
#pragma once

#include <set>
#include <string>

#include <yaml-cpp/yaml.h>

namespace sbot {

/// What yaml-cpp accepts but no configuration file may hold, or "" if nothing:
/// - a key repeated within one mapping, as "key 'k' appears twice in one mapping (lines L1 and L2)":
///   yaml-cpp keeps both copies and answers node["k"] with the first, so the value written last is
///   silently lost (a second `report:` in a tables file dropped a whole table);
/// - an alias inside the value it names (`a: &x [*x]`), which made every walk of the tree recurse
///   until the stack overflowed;
/// - aliases nested to multiply the document past a million values ("billion laughs"), which made
///   a walk run for hours.
/// - a key that is a list or a mapping (`? [a]: 1`), which every loader reads as a name and which
///   then escaped as yaml-cpp's "bad conversion".
std::string yamlStructureProblem(const YAML::Node& node);

/// The first key of mapping `node` that is not in `allowed` (its name: Scalar(), its place: Mark()),
/// or an undefined node (false) when every key is (or `node` is no mapping): a typo or a leftover, which a loader
/// must not ignore. unknownFieldMessage words it.
YAML::Node unknownKey(const YAML::Node& node, const std::set<std::string>& allowed);
/// "unknown field (expected one of: a, b, c)".
std::string unknownFieldMessage(const std::set<std::string>& allowed);

}  // namespace sbot
