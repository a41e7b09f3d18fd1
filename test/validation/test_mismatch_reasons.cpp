// The validation report's mismatch reasons (src/validation/mismatch_reasons.h): a mismatch is
// printed with its recorded reason or flagged as unexplained, a recorded cell that matches is
// flagged as stale, and a malformed file is refused with its name and the problem.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "../common/temp_file.h"
#include "mismatch_reasons.h"

namespace v = sbot::validation;

namespace {

std::string writeTemp(const std::string& text) { return sbot_test::writeTempFile("mismatch_reasons", text); }

/// The message load() refuses `text` with ("" when it loads).
std::string refusal(const std::string& text) {
  const std::string path = writeTemp(text);
  try {
    v::MismatchReasons::load(path);
  } catch (const std::runtime_error& e) {
    std::remove(path.c_str());
    return e.what();
  }
  std::remove(path.c_str());
  return "";
}

}  // namespace

TEST(MismatchReasons, MismatchesGetTheirReasonOrAreFlaggedAsUnexplained) {
  const std::string path = writeTemp("\"4.3 10 mm backward\": the band is missing\n\"4.2 55 mm\": the gripper props it\n");
  v::MismatchReasons r = v::MismatchReasons::load(path, "reasons.yaml");
  std::remove(path.c_str());
  EXPECT_EQ(r.record("4.3 10 mm backward", false), "**mismatch**");
  EXPECT_EQ(r.record("4.3 10 mm forward", true), "match");
  EXPECT_EQ(r.record("4.3 24 mm forward", false), "**mismatch**");
  const std::string md = r.explainPending();
  EXPECT_NE(md.find("`reasons.yaml`"), std::string::npos) << md;
  EXPECT_NE(md.find("*4.3 10 mm backward*: the band is missing"), std::string::npos) << md;
  EXPECT_NE(md.find("*4.3 24 mm forward*: **not explained yet**"), std::string::npos) << md;
  EXPECT_EQ(md.find("10 mm forward"), std::string::npos) << "a matching cell is not explained: " << md;
  EXPECT_EQ(r.explainPending(), "") << "each table's mismatches are explained once";
  // Cells that share a reason are listed together with it, once; so are the unexplained ones.
  const std::string shared = writeTemp("\"4.5 5.0 cm fast\": same\n\"4.5 5.7 cm fast\": same\n\"4.5 4.0 cm simple\": other\n");
  v::MismatchReasons g = v::MismatchReasons::load(shared);
  std::remove(shared.c_str());
  for (const char* key : {"4.5 5.0 cm fast", "4.5 4.0 cm simple", "4.5 5.7 cm fast", "4.5 6.0 cm fast", "4.5 6.5 cm fast"})
    g.record(key, false);
  const std::string grouped = g.explainPending();
  EXPECT_NE(grouped.find("- *4.5 5.0 cm fast*, *4.5 5.7 cm fast*: same\n"), std::string::npos) << grouped;
  EXPECT_NE(grouped.find("- *4.5 4.0 cm simple*: other\n"), std::string::npos) << grouped;
  EXPECT_NE(grouped.find("- *4.5 6.0 cm fast*, *4.5 6.5 cm fast*: **not explained yet**"), std::string::npos) << grouped;
  EXPECT_LT(grouped.find("5.0 cm fast"), grouped.find("4.0 cm simple")) << "groups keep the table's order";
  ASSERT_EQ(r.unexplained().size(), 1u);
  EXPECT_EQ(r.unexplained()[0], "4.3 24 mm forward");
  EXPECT_TRUE(r.stale().empty());
  // A recorded cell that now matches: its reason is stale.
  EXPECT_EQ(r.record("4.2 55 mm", true), "match");
  ASSERT_EQ(r.stale().size(), 1u);
  EXPECT_EQ(r.stale()[0], "4.2 55 mm");
  EXPECT_TRUE(r.explains("4.2 55 mm"));
  EXPECT_FALSE(r.explains("4.2 45 mm"));
}

TEST(MismatchReasons, WithoutAFileMismatchesAreFlaggedAndTheOptionIsNamed) {
  v::MismatchReasons r = v::MismatchReasons::none();
  EXPECT_FALSE(r.fromFile());
  EXPECT_EQ(r.record("L1 12.0 mm rev simple", false), "**mismatch**");
  const std::string md = r.explainPending();
  EXPECT_NE(md.find("(no reasons file; `--reasons FILE` records them)"), std::string::npos) << md;
  EXPECT_NE(md.find("*L1 12.0 mm rev simple*: **not explained yet**"), std::string::npos) << md;
  EXPECT_EQ(md.find("``"), std::string::npos) << "no empty file name: " << md;
}

TEST(MismatchReasons, MalformedFilesAreRefusedWithTheFileAndTheProblem) {
  EXPECT_NE(refusal("- a list\n- not a map\n").find("expected a map"), std::string::npos);
  EXPECT_NE(refusal("\"4.2 55 mm\": [1, 2]\n").find("the reason for '4.2 55 mm' is not a text"), std::string::npos);
  EXPECT_NE(refusal("\"4.2 55 mm\": \"\"\n").find("'4.2 55 mm'"), std::string::npos);
  EXPECT_NE(refusal("\"4.2 55 mm\": [unclosed\n").find("not YAML"), std::string::npos);
  EXPECT_EQ(refusal(""), "") << "an empty file explains nothing but is valid";
  try {
    v::MismatchReasons::load("/nonexistent/reasons.yaml");
    FAIL() << "an unreadable file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/reasons.yaml: cannot open mismatch reasons file (No such file or directory)"), std::string::npos) << e.what();
  }
}

// That every key of the shipped file names a cell the report runs: test_reference_tables.cpp.
