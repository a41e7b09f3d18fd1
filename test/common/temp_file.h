// A file with given contents under /tmp for a test (malformed configuration files and the like).
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

namespace sbot_test {

/// Writes `text` to a new file /tmp/<prefix>_XXXXXX and returns its path (the caller removes it).
inline std::string writeTempFile(const std::string& prefix, const std::string& text) {
  std::string path = "/tmp/" + prefix + "_XXXXXX";
  const int fd = mkstemp(&path[0]);
  if (fd < 0) throw std::runtime_error("mkstemp " + path);
  close(fd);
  std::ofstream(path) << text;
  return path;
}

}  // namespace sbot_test
