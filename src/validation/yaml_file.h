// Reading one of the validation suite's YAML files (mismatch reasons, reference tables) with the
// same two refusals: a file that cannot be read, and one that is not YAML (with the parser's line).
#pragma once

#include <sys/stat.h>

#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/yaml_checks.h"

namespace sbot {
namespace validation {

/// The parsed file; throws std::runtime_error("<what> <path>: <why>"): not a readable regular file of at most
/// sbot/core/input_file.h's size limit ("cannot open <what> file (...)", "is a folder, ..."), or not YAML.
inline YAML::Node loadYamlFile(const std::string& what, const std::string& path) {
  const std::string problem = inputFileProblem(path, what + " file");  // a folder, /dev/zero, a FIFO, too large
  if (!problem.empty()) throw std::runtime_error(what + " " + path + ": " + problem);
  YAML::Node root;
  try {
    root = YAML::Load(readInputFile(path, what + " file"));
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(what + " " + path + ": not YAML (" + e.msg + ", line " + std::to_string(e.mark.line + 1) + ")");
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty())
    throw std::runtime_error(what + " " + path + ": " + problem);
  return root;
}

}  // namespace validation
}  // namespace sbot
