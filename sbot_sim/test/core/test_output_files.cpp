// Output files (output_files.h): a place that cannot be written is refused with its path and the
// system's reason, and a write that does not reach the disk is reported, not taken as done.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <functional>
#include <fstream>
#include <sstream>
#include <string>

#include "sbot_sim/core/output_files.h"

namespace sbot::test {
namespace {

/// A fresh directory under /tmp, removed with its contents at the end of the test.
class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/sbot_output_files_XXXXXX";
    path_ = ::mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf '" + path_ + "'").c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const OutputError& e) {
    return e.what();
  }
  return "(no OutputError)";
}

bool isDirectory(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

TEST(OutputFiles, MakesMissingParentsAndAcceptsAnExistingDirectory) {
  TempDir t;
  const std::string dir = t.path() + "/a/b/c";
  makeOutputDirectory(dir);
  EXPECT_TRUE(isDirectory(dir));
  makeOutputDirectory(dir);  // again: already there
  makeOutputDirectory(t.path() + "/a//b/");
  EXPECT_TRUE(isDirectory(t.path() + "/a/b"));
}

TEST(OutputFiles, ADirectoryUnderAFileIsRefusedWithItsPath) {
  TempDir t;
  const std::string file = t.path() + "/plain";
  std::ofstream(file) << "x";
  const std::string under = messageOf([&] { makeOutputDirectory(file + "/report"); });
  EXPECT_NE(under.find("cannot create directory '" + file + "/report'"), std::string::npos) << under;
  EXPECT_NE(under.find("'" + file + "' exists and is not a directory"), std::string::npos) << under;
  const std::string itself = messageOf([&] { makeOutputDirectory(file); });
  EXPECT_NE(itself.find("'" + file + "' exists and is not a directory"), std::string::npos) << itself;
  EXPECT_NE(messageOf([] { makeOutputDirectory(""); }).find("empty"), std::string::npos);
}

TEST(OutputFiles, APlaceTheSystemRefusesNamesTheSystemsReason) {
  // /proc takes no new directories, also for root (permission bits would not stop root).
  const std::string m = messageOf([] { makeOutputDirectory("/proc/sbot_no_such_place/report"); });
  EXPECT_NE(m.find("cannot create directory '/proc/sbot_no_such_place'"), std::string::npos) << m;
  EXPECT_NE(m.find("(for '/proc/sbot_no_such_place/report')"), std::string::npos) << m;
}

TEST(OutputFiles, CheckOutputFileCreatesItsDirectoryButNoFile) {
  TempDir t;
  const std::string path = t.path() + "/new/effects.yaml";
  checkOutputFile(path);
  EXPECT_TRUE(isDirectory(t.path() + "/new"));
  EXPECT_NE(::access(path.c_str(), F_OK), 0) << "checkOutputFile created the file";
  const std::string dir = messageOf([&] { checkOutputFile(t.path()); });
  EXPECT_NE(dir.find("it is a directory"), std::string::npos) << dir;
  const std::string bad = messageOf([] { checkOutputFile("/proc/sbot_no_such_place/x.yaml"); });
  EXPECT_NE(bad.find("/proc/sbot_no_such_place"), std::string::npos) << bad;
}

TEST(OutputFiles, WritesAndReplacesAFile) {
  TempDir t;
  const std::string path = t.path() + "/report.md";
  writeTextFile(path, "first\n");
  writeTextFile(path, "second\n");
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), "second\n");
}

TEST(OutputFiles, AnAtomicWriteReplacesTheFileAndLeavesNoTemporary) {
  TempDir t;
  const std::string path = t.path() + "/report.partial.md";
  writeTextFileAtomically(path, "one section\n");
  writeTextFileAtomically(path, "two sections\n");
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), "two sections\n");
  EXPECT_NE(::access((path + ".tmp").c_str(), F_OK), 0) << "the temporary file was left behind";
  // Where the temporary cannot be made, the error names it, and the old file is kept.
  const std::string m = messageOf([&] { writeTextFileAtomically(t.path() + "/missing_dir/report.md", "x"); });
  EXPECT_NE(m.find("missing_dir/report.md.tmp"), std::string::npos) << m;
}

TEST(OutputFiles, AFileThatCannotBeOpenedIsRefusedAtOnce) {
  TempDir t;
  const std::string m = messageOf([&] { OutputFile f(t.path() + "/missing_dir/report.md"); });
  EXPECT_NE(m.find("cannot write '" + t.path() + "/missing_dir/report.md': No such file or directory"),
            std::string::npos)
      << m;
}

TEST(OutputFiles, AWriteThatDoesNotReachTheDiskIsReportedAtCommit) {
  // /dev/full opens, then fails every write with ENOSPC: a full disk.
  OutputFile f("/dev/full");
  f << "a report that would be lost\n";
  const std::string m = messageOf([&] { f.commit(); });
  EXPECT_NE(m.find("cannot write '/dev/full': No space left on device"), std::string::npos) << m;
  EXPECT_NE(messageOf([] { writeTextFile("/dev/full", "x"); }).find("/dev/full"), std::string::npos);
}

}  // namespace
}  // namespace sbot::test
