#include "sbot_sim/core/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "sbot_sim/core/errors.h"

namespace sbot {
namespace {

std::string limitText() { return std::to_string(kMaxInputFileBytes >> 20) + " MiB"; }

/// An open file descriptor checked as an input file (-1 and `problem` set when refused).
int openChecked(const std::string& path, const std::string& kind, std::string* problem) {
  // O_NONBLOCK: opening a FIFO without a writer would otherwise wait forever.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *problem = "cannot open " + kind + " (" + std::strerror(errno) + ")";
    return -1;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    *problem = "cannot read " + kind + " (" + std::strerror(errno) + ")";
  } else if (S_ISDIR(st.st_mode)) {
    *problem = std::string("is a folder, not ") + (std::string("aeiou").find(kind[0]) == std::string::npos ? "a " : "an ") + kind;
  } else if (!S_ISREG(st.st_mode)) {
    *problem = std::string("is not a regular file (") +
               (S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" :
                S_ISSOCK(st.st_mode) ? "a socket" : "a special file") +
               "); only regular files are read";
  } else if (static_cast<std::uintmax_t>(st.st_size) > kMaxInputFileBytes) {
    *problem = "is " + std::to_string(static_cast<std::uintmax_t>(st.st_size) >> 20) +
               " MiB, larger than the " + limitText() + " an input file may have";
  }
  if (!problem->empty()) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

std::string inputFileProblem(const std::string& path, const std::string& kind) {
  std::string problem;
  const int fd = openChecked(path, kind, &problem);
  if (fd >= 0) ::close(fd);
  return problem;
}

std::string readInputFile(const std::string& path, const std::string& kind) {
  std::string problem;
  const int fd = openChecked(path, kind, &problem);
  if (fd < 0) throw ConfigError(path, "", problem);
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      problem = "cannot read " + kind + " (" + std::strerror(errno) + ")";
      break;
    }
    if (n == 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > kMaxInputFileBytes) {
      problem = "grew past the " + limitText() + " an input file may have while it was read";
      break;
    }
  }
  ::close(fd);
  if (!problem.empty()) throw ConfigError(path, "", problem);
  return text;
}

}  // namespace sbot
