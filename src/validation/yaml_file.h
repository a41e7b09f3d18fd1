// Reading one of the validation suite's YAML files (mismatch reasons, reference tables) with the
// same two refusals: a file that cannot be read, and one that is not YAML (with the parser's line).
#pragma once

#include <sys/stat.h>

#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/yaml_checks.h"

namespace sbot {
namespace validation {

/// The parsed file; throws std::runtime_error("<what> <path>: cannot be read" / ": not YAML (...)").
inline YAML::Node loadYamlFile(const std::string& what, const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw std::runtime_error(what + " " + path + ": is a directory");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(what + " " + path + ": cannot be read");
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(what + " " + path + ": not YAML (" + e.msg + ", line " + std::to_string(e.mark.line + 1) + ")");
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty())
    throw std::runtime_error(what + " " + path + ": " + problem);
  return root;
}

}  // namespace validation
}  // namespace sbot
