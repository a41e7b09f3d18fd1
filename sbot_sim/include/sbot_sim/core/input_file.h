// Reading an input file (scenario, effects file, URDF and sidecar, IR table, dataset YAML and CSV,
// reference tables, route and experiment files): one gate for every parser, so that what a user
// names as a file is either read whole or refused with its path.
#pragma once

#include <cstdint>
#include <string>

namespace sbot {

/// [bytes] The largest input file any parser reads (256 MiB). The shipped files are under 1 MiB; a
/// dataset CSV of a long recording stays far below it. Larger files are refused instead of being
/// read into memory (/dev/zero as a scenario grew the process by 3.2 GB in 9 s).
constexpr std::uintmax_t kMaxInputFileBytes = 256ull << 20;

/// Why `path` cannot be read as an input file, or "" when it can: it does not exist or cannot be
/// opened, it is not a regular file (a folder, a device such as /dev/zero, a FIFO, a socket), or it
/// is larger than kMaxInputFileBytes. Opening does not block (a FIFO without a writer). `kind`
/// names the file in the words ("cannot open scenario file (No such file or directory)").
std::string inputFileProblem(const std::string& path, const std::string& kind = "file");

/// The whole of `path`; throws ConfigError(path, "", inputFileProblem) when it cannot be read as
/// an input file (also when it grows past the limit while being read).
std::string readInputFile(const std::string& path, const std::string& kind = "file");

}  // namespace sbot
