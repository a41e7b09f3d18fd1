// Errors the core raises for bad input. Every message names the offending file and field so a user
// can fix a scenario, URDF, sidecar or dataset without reading source code.
#pragma once

#include <stdexcept>
#include <string>

namespace sbot {

/// Malformed or inconsistent configuration (scenario YAML, URDF, sidecar, effects file).
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(file + ": " + (field.empty() ? "" : "field '" + field + "': ") + what),
        file_(file), field_(field) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_, field_;
};

/// "a, b, c": the names a message lists as what was expected (any range of strings, in its order).
template <class Names>
std::string nameList(const Names& names, const std::string& separator = ", ") {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : separator) + n;
  return list;
}

/// A request that names something that does not exist (unknown robot, link, level).
class UnknownName : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace sbot
