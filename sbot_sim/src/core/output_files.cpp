#include "sbot_sim/core/output_files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cerrno>
#include <cstring>

namespace sbot {
namespace {

std::string reason(int err) { return std::strerror(err); }

bool isDirectory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

/// The directory part of a file path ("." for a bare name).
std::string parentOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

void makeOutputDirectory(const std::string& dir) {
  if (dir.empty()) throw OutputError("cannot use '' as an output directory: the name is empty");
  std::string cur = dir[0] == '/' ? "/" : "";
  std::size_t start = 0;
  while (start <= dir.size()) {
    const std::size_t end = std::min(dir.find('/', start), dir.size());
    const std::string part = dir.substr(start, end - start);
    start = end + 1;
    if (part.empty()) continue;
    cur += part;
    if (::mkdir(cur.c_str(), 0755) != 0 && errno != EEXIST)
      throw OutputError("cannot create directory '" + cur + "'" + (cur == dir ? "" : " (for '" + dir + "')") + ": " +
                        reason(errno));
    if (!isDirectory(cur))
      throw OutputError("cannot create directory '" + dir + "': '" + cur + "' exists and is not a directory");
    cur += "/";
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw OutputError("cannot write in directory '" + dir + "': " + reason(errno));
}

void checkOutputFile(const std::string& path) {
  if (path.empty()) throw OutputError("cannot write to '': the file name is empty");
  if (isDirectory(path)) throw OutputError("cannot write '" + path + "': it is a directory");
  makeOutputDirectory(parentOf(path));
  if (::access(path.c_str(), F_OK) == 0 && ::access(path.c_str(), W_OK) != 0)
    throw OutputError("cannot write '" + path + "': " + reason(errno));
}

OutputFile::OutputFile(const std::string& path, std::ios::openmode mode) : std::ofstream(), path_(path) {
  errno = 0;
  open(path, mode);
  if (!is_open())
    throw OutputError("cannot write '" + path + "': " + (errno ? reason(errno) : std::string("cannot open it")));
}

void OutputFile::commit() {
  errno = 0;
  flush();
  const bool written = !fail();
  const int err = errno;
  close();
  if (!written || fail())
    throw OutputError("cannot write '" + path_ + "': " + (err ? reason(err) : std::string("the write failed")));
}

void writeTextFile(const std::string& path, const std::string& text) {
  OutputFile f(path);
  f << text;
  f.commit();
}

void writeTextFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  writeTextFile(tmp, text);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw OutputError("cannot write '" + path + "': renaming '" + tmp + "' over it: " + reason(err));
  }
}

}  // namespace sbot
