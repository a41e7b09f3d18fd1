// Files the core and the headless tools write: reports, plots, datasets, effects files, run logs.
// A directory that cannot be created or a write that does not reach the disk is an OutputError that
// names the path and the system's reason, so a tool never reports as written a file that is not
// there, and a tool that runs for minutes checks its output place before it starts, not after.
#pragma once

#include <fstream>
#include <stdexcept>
#include <string>

namespace sbot {

/// A file or directory the program cannot write. what(): "cannot ... 'PATH': reason".
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Creates `dir` and its missing parents (as mkdir -p) and checks that files can be created in it.
/// Throws OutputError naming the directory that could not be made, or that `dir` is not a directory.
void makeOutputDirectory(const std::string& dir);

/// Checks, before the work that produces it, that the file `path` can be written: its directory
/// exists (it is created if missing) and is writable, and `path` is not a directory. Creates no file.
void checkOutputFile(const std::string& path);

/// A file being written. The constructor opens (truncates) `path` and throws OutputError if it
/// cannot; commit() flushes and closes it and throws OutputError if any write failed (a full disk).
/// It is a std::ofstream, so writers stream into it as usual; call commit() when done, since a
/// destructor cannot report a failed write.
class OutputFile : public std::ofstream {
 public:
  explicit OutputFile(const std::string& path, std::ios::openmode mode = std::ios::out | std::ios::trunc);
  void commit();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Writes `text` to `path` (replacing it), checked as OutputFile.
void writeTextFile(const std::string& path, const std::string& text);

/// As writeTextFile, but through `path`.tmp renamed over `path`: a reader, or a process killed
/// during the write, sees the old file or the new one, never half of one (a report rewritten as a
/// long run goes on).
void writeTextFileAtomically(const std::string& path, const std::string& text);

}  // namespace sbot
