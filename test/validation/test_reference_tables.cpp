// The validation report's reference tables (src/validation/reference_tables.h): the shipped file
// holds the seed's chapter 4 as sbot_validate tallies it, cells are named as the mismatch reasons
// name them, and a malformed file (another lab's measurements, say) is refused with the file, the
// entry and the problem before any trial runs.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "../common/temp_file.h"
#include "mismatch_reasons.h"
#include "reference_tables.h"

namespace v = sbot::validation;

namespace {

/// What sbot_validate checks a file against (its built-in sections and paragraphs, the levels).
const v::ReferenceVocabulary kVocabulary{{"facts", "4.1pair", "4.4", "compat", "fig4.4"},
                                         {"backward_step_statics"},
                                         {"fast", "simple", "basic", "medium", "detailed"},
                                         {{"4.1pair", "hardware"}}};

std::string shippedFile() { return std::string(SWARMBOT3D_SOURCE_DIR) + "/" + v::kReferenceTablesFile; }

std::string writeTemp(const std::string& text) { return sbot_test::writeTempFile("reference_tables", text); }

/// The message load() refuses `text` with ("" when it loads).
std::string refusal(const std::string& text) {
  const std::string path = writeTemp(text);
  try {
    v::ReferenceTables::load(path, kVocabulary);
  } catch (const std::runtime_error& e) {
    std::remove(path.c_str());
    return e.what();
  }
  std::remove(path.c_str());
  return "";
}

/// A valid one-table file; each refusal below changes one thing in it.
const std::string kLab =
    "groups:\n"
    "  - {name: lab, title: \"Lab cells\", required: true}\n"
    "report:\n"
    "  - table:\n"
    "      id: lab1\n"
    "      title: Gaps in our lab\n"
    "      group: lab\n"
    "      experiment: gap\n"
    "      level: medium\n"
    "      param: {header: gap, unit: mm, scale: 1000, decimals: 0}\n"
    "      references: [measured]\n"
    "      value: {header: \"base x [cm]\", scale: 100, decimals: 1}\n"
    "      cells:\n"
    "        - {param: 0.030, measured: pass}\n"
    "        - {param: 0.060, measured: \"stuck|fall inside\"}\n"
    "        - {param: 0.035, level: basic, measured: pass}\n";

std::string with(const std::string& from, const std::string& to) {
  std::string s = kLab;
  const auto at = s.find(from);
  if (at == std::string::npos) throw std::logic_error("kLab has no '" + from + "'");
  return s.replace(at, from.size(), to);
}

}  // namespace

TEST(ReferenceTables, TheShippedFileHoldsTheSeedsTablesAsTallied) {
  const v::ReferenceTables t = v::ReferenceTables::load(shippedFile(), kVocabulary);
  std::map<std::string, int> cells;  // per group
  std::map<std::string, const v::ReferenceTable*> by_id;
  for (const v::ReportEntry& e : t.report)
    if (e.section.empty()) {
      by_id[e.table.id] = &e.table;
      cells[e.table.group] += static_cast<int>(e.table.cells.size());
    }
  // 20 hardware cells: 16 here, plus the 4 two-robot rows of the built-in 4.1pair section.
  EXPECT_EQ(cells["hardware"], 16);
  EXPECT_EQ(cells["4.5"], 28);
  EXPECT_EQ(cells["4.6"], 28);
  ASSERT_TRUE(t.findGroup("hardware"));
  EXPECT_TRUE(t.findGroup("hardware")->required);
  EXPECT_FALSE(t.findGroup("4.5")->required);
  // Spot checks against the seed's text (Tables 4.2, 4.3, 4.5, 4.6).
  ASSERT_TRUE(by_id.count("4.3") && by_id.count("4.5") && by_id.count("4.6") && by_id.count("4.2"));
  const v::ReferenceTable& steps = *by_id["4.3"];
  EXPECT_EQ(steps.key(steps.cells[2]), "4.3 15 mm backward");
  EXPECT_EQ(steps.cells[2].experiment, "stepb");
  EXPECT_EQ(steps.cells[2].references[0].accepts, "pass");
  EXPECT_EQ(steps.cells[9].experiment, "step");
  EXPECT_EQ(steps.cells[9].references[0].accepts, "fail");  // 24 mm forward
  const v::ReferenceTable& gaps = *by_id["4.5"];
  EXPECT_EQ(gaps.key(gaps.cells[5]), "4.5 4.0 cm simple");
  EXPECT_EQ(gaps.cells[9].references[0].accepts, "pass|stuck");  // 4.5 cm simple: pass 70 % / stuck 30 %
  EXPECT_EQ(gaps.cells[9].references[0].text, "pass 70% / stuck 30%");
  const v::ReferenceTable& ramps = *by_id["4.6"];
  EXPECT_EQ(ramps.key(ramps.cells[22]), "4.6 0.90 rad medium");
  EXPECT_EQ(ramps.cells[22].references[0].accepts, "slide back");
  EXPECT_EQ(by_id["4.2"]->cells[2].references[0].accepts, "fall inside");
  // The hardware's gap and step apparatus is the lab floor; the seed simulator's tables keep 1.0.
  for (const char* id : {"4.2", "4.3"})
    for (const v::ReferenceCell& c : by_id[id]->cells) EXPECT_EQ(c.track_mu, v::kLabFloorTrackMu) << id;
  for (const char* id : {"4.1", "4.5", "4.6"})
    for (const v::ReferenceCell& c : by_id[id]->cells) EXPECT_EQ(c.track_mu, 0.0) << id;
}

TEST(ReferenceTables, EveryMismatchReasonNamesACellTheReportRuns) {
  // A typo in either file would hide a reason from its cell (the report would call the cell
  // unexplained and the entry unused), so every reason's key must be a cell of the shipped tables
  // or one of the built-in 4.1pair section's rows or Figure 4.4's reading.
  std::set<std::string> keys{"4.1 pair limit of full manoeuvrability", "4.1 pair limit of stable position",
                             "4.1.3 32 mm single s-bot", "4.1.3 32 mm two connected",
                             "fig4.4 fast", "fig4.4 simple", "fig4.4 medium"};  // Figure 4.4's reading
  for (const v::ReportEntry& e : v::ReferenceTables::load(shippedFile(), kVocabulary).report)
    for (const v::ReferenceCell& c : e.table.cells) keys.insert(e.table.key(c));
  const YAML::Node reasons = YAML::LoadFile(std::string(SWARMBOT3D_SOURCE_DIR) + "/" + v::kMismatchReasonsFile);
  ASSERT_TRUE(reasons.IsMap());
  EXPECT_GT(reasons.size(), 0u);
  for (const auto& entry : reasons) EXPECT_TRUE(keys.count(entry.first.as<std::string>())) << entry.first.as<std::string>();
}

TEST(ReferenceTables, AnotherLabsTableLoadsWithItsOwnNamesAndDefaults) {
  const std::string path = writeTemp(kLab);
  const v::ReferenceTables t = v::ReferenceTables::load(path, kVocabulary, "lab.yaml");
  std::remove(path.c_str());
  EXPECT_EQ(t.source, "lab.yaml");
  ASSERT_EQ(t.report.size(), 1u);
  const v::ReferenceTable& table = t.report[0].table;
  ASSERT_EQ(table.cells.size(), 3u);
  EXPECT_EQ(table.cells[0].experiment, "gap");
  EXPECT_EQ(table.cells[0].level, "medium");   // the table's default
  EXPECT_EQ(table.cells[2].level, "basic");    // the cell's own
  EXPECT_TRUE(table.severalLevels());
  EXPECT_EQ(table.key(table.cells[0]), "lab1 30 mm medium");
  EXPECT_EQ(table.cells[1].references[0].text, "stuck or fall inside") << "a '|' would split the Markdown table";
  EXPECT_EQ(table.cells[0].speed_units, v::kSlowUnits) << "the seed's 2.8 cm/s unless the table says otherwise";
  EXPECT_EQ(table.cells[0].track_mu, 0.0) << "the experiment's own floor unless the table says otherwise";
  EXPECT_FALSE(table.otherSpeeds());
  EXPECT_EQ(table.value.header, "base x [cm]");
  EXPECT_EQ(table.value.text(0.0123), "1.2") << "x scale, decimals, no unit";
  EXPECT_EQ(table.param.text(0.035), "35 mm");
}

TEST(ReferenceTables, ATablesFloorFrictionIsANumberOrTheLabFloorAndACellMaySetItsOwn) {
  std::string text = with("level: medium\n", "level: medium\n      track_mu: 0.6\n");
  text.replace(text.find("level: basic, "), 14, "level: basic, track_mu: lab_floor, ");
  const std::string path = writeTemp(text);
  const v::ReferenceTables t = v::ReferenceTables::load(path, kVocabulary, "lab.yaml");
  std::remove(path.c_str());
  const v::ReferenceTable& table = t.report[0].table;
  EXPECT_EQ(table.cells[0].track_mu, 0.6);
  EXPECT_EQ(table.cells[1].track_mu, 0.6);
  EXPECT_EQ(table.cells[2].track_mu, v::kLabFloorTrackMu);
}

TEST(ReferenceTables, MalformedFilesAreRefusedWithTheEntryAndTheProblem) {
  EXPECT_EQ(refusal(kLab), "");
  const std::pair<std::string, std::string> cases[] = {
      {with("experiment: gap", "experiment: gapp"), "cell 0: experiment 'gapp' is not one of gap, step, stepb"},
      {with("experiment: gap", "experiment: rough"), "experiment 'rough' is not one of"},  // a measurement, no labels
      {with("param: 0.060", "param: .nan"), "cell 1: field 'param' expects a finite number, found '.nan'"},
      {with("param: 0.060", "param: wide"), "cell 1: field 'param' expects a finite number, found 'wide'"},
      {with("param: 0.060", "param: 0.6"), "cell 1: param 0.6 is outside gap's range [0, 0.3] (gap width, m)"},
      {with("level: basic", "level: basik"), "cell 2: level 'basik' is not one of fast, simple, basic, medium, detailed"},
      {with("measured: pass}", "measured: pas}"), "accepts 'pas', which gap never yields (its labels: pass, fall inside"},
      {with("{param: 0.030, measured: pass}", "{param: 0.030}"), "cell 0: missing the reference 'measured'"},
      {with("{param: 0.030, measured: pass}", "{param: 0.030, mesured: pass, measured: pass}"), "unknown field 'mesured'"},
      {with("group: lab", "group: labs"), "table 'lab1': group 'labs' is not defined under groups"},
      {with("references: [measured]", "references: []"), "'references' must name at least one column"},
      {with("{param: 0.035, level: basic, measured: pass}", "{param: 0.030, measured: stuck}"),
        "two cells are both 'lab1 30 mm'"},
      {with("        - {param: 0.030, measured: pass}\n", "        - {param: 0.030, measured: {accepts: pass, text: \"a|b\"}}\n"),
        "holds a '|' or a line break, which would split the report's table"},
      // Values a report cannot use:
      {with("param: 0.060", "param: \"\""), "cell 1: field 'param' expects a finite number, found ''"},  // was a 0 m gap
      {with("measured: pass}", "measured: {accepts: \"\", text: pass}}"), "field 'accepts' is empty"},
      {with("measured: pass}", "measured: \"pass|\"}"), "every alternative between '|' must be a label"},
      {with("level: basic, ", "level: basic, variant: \"a|b\", "), "variant 'a|b' holds a '|' or a line break"},
      {with("id: lab1", "id: \"4.4\""), "'4.4' is the name of a built-in section"},  // it started the RTM runs
      {with("id: lab1", "id: \"lab,1\""), "an id may not hold a comma"},
      {with("references: [measured]", "references: [level]"), "the reference column 'level' has the name of a cell's field"},
      {with("      group: lab\n", ""), "group 'lab' is required, but no table or section counts its cells in it"},
      {with("{param: 0.035, level: basic, measured: pass}", "{param: 0.0301, measured: stuck}") + "",
        "the cells of param 0.030000 and 0.030100 are both shown as '30 mm'"},
      {with("level: basic, ", "level: basic, speed_units: 2.5, "), "cell 2: speed_units expects a whole number of setSpeed units in [1, 70]"},
      {with("level: medium\n", "level: medium\n      speed_units: 71\n"), "cell 0: speed_units expects a whole number"},
      {with("level: basic, ", "level: basic, track_mu: -0.5, "),
        "cell 2: field 'track_mu' expects a friction coefficient in [1e-6, 100] or lab_floor, found '-0.5'"},
      {with("level: medium\n", "level: medium\n      track_mu: lab floor\n"), "found 'lab floor'"},
      {with("decimals: 1}", "decimals: 9}"), "table 'lab1', value: decimals expects a whole number from 0 to 6, found '9'"},
      // -1 is how the loader marks "not given"; written in a file it must not be taken as that.
      {with("decimals: 1}", "decimals: -1}"), "table 'lab1', value: decimals expects a whole number from 0 to 6, found '-1'"},
      {with("references: [measured]", "references: [measured, measured]"), "'references' names the column 'measured' twice"},
      {with("required: true", "required: maybe"), "field 'required' expects true or false, found 'maybe'"},
      {with("report:\n", "report:\n  - section: rtm\n"), "section 'rtm' is not a built-in section"},
      {with("report:\n", "report:\n  - section: 4.1pair\n"), "tallies its cells in group 'hardware', which 'groups' does not define"},
      {with("report:\n", "report:\n  - {colour: red}\n"), "expected 'section: NAME' or 'table: {...}'"},
      {with("      title: Gaps in our lab\n", ""), "missing field 'title'"},
      {with("report:\n", "report:\n  - table: {id: lab1, title: x, references: [a], experiment: gap, level: fast, "
                          "cells: [{param: 0.03, a: pass}]}\n"),
        "'lab1' appears twice in the report"},
      // A slope cell in a gap table would read "25000 mm", a gap "0.03 deg".
      {with("{param: 0.035, level: basic, measured: pass}", "{param: 25, experiment: slope, measured: full}"),
        "cell 2: slope's parameter is a slope in deg, which the table's param format shows as x1000 mm"},
      {with("unit: mm, scale: 1000", "unit: deg, scale: 1"), "gap's parameter is a gap width in m, which the table's param format shows as x1 deg"},
      {with("unit: mm, scale: 1000", "unit: mm, scale: 100"), "shows as x100 mm"},
      {with("param: 0.060", "param: [0.060]"), "cell 1: field 'param' must be a number, found a list"},
      {"groups: []\n", "'report' must be a non-empty list"},
      {"report: [unclosed\n", "not YAML"},
      {"- just\n- a list\n", "expected a map with 'groups' and 'report'"},
  };
  for (const auto& c : cases) {
    const std::string why = refusal(c.first);
    EXPECT_NE(why.find(c.second), std::string::npos) << "expected '" << c.second << "', got '" << why << "'";
    EXPECT_NE(why.find("reference tables /tmp/reference_tables_"), std::string::npos) << "names the file: " << why;
  }
  try {
    v::ReferenceTables::load("/nonexistent/tables.yaml", kVocabulary);
    FAIL() << "an unreadable file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/tables.yaml: cannot open reference tables file (No such file or directory)"), std::string::npos) << e.what();
  }
}
