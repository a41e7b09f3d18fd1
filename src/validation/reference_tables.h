// The tables sbot_validate compares the model with, as data: which experiment runs in each cell, on
// which level and with which parameter, and what the reference (the hardware, the seed's simulator,
// your own measurements) observed there. The seed's chapter 4 is config/validation/reference_tables.yaml;
// `sbot_validate --tables FILE` runs any other file of the same form (docs/validation.md).
//
// A file lists the report's sections in order: a table, or one of the built-in sections whose
// experiments are not cells of one trial kind (the model facts, the two-robot rows, the RTM, the
// compatibility speeds, Figure 4.4). Tallies ("groups") count the matching cells of the tables
// that name them; the groups marked `required` decide sbot_validate's exit status.
#pragma once

#include <string>
#include <vector>

#include "experiments.h"

namespace sbot {
namespace validation {

/// The default file, relative to the root package (the swarmbot3d source directory).
constexpr const char* kReferenceTablesFile = "config/validation/reference_tables.yaml";

/// One reference value: what a cell accepts (labels separated by '|') and how the report shows it.
struct ReferenceValue {
  std::string accepts;  ///< compared column only: "pass", "pass|stuck"; empty for a shown-only column
  std::string text;     ///< as the report prints it ("pass 70% / stuck 30%")
};

struct ReferenceCell {
  std::string experiment;  ///< an ExperimentKind's name (experiments.h)
  std::string level;       ///< a model level
  double param = 0;        ///< the kind's parameter, in its unit (gap width m, slope deg, ramp rad)
  std::string variant;     ///< a row label beside the parameter ("backward"), may be empty
  int speed_units = kSlowUnits;  ///< the drive's setSpeed units (Drive; the seed's 2.8 cm/s)
  double track_mu = 0;           ///< the treels' mu on the terrain (Drive::track_mu; 0: the experiment's own)
  std::vector<ReferenceValue> references;  ///< one per ReferenceTable::references; [0] is compared
};

/// How a table shows a number: its column header, value x scale with `decimals`, then the unit.
struct NumberFormat {
  std::string header;
  std::string unit;   ///< after the number ("mm"); may be empty
  double scale = 1;   ///< a gap in m shown in mm: 1000
  int decimals = -1;  ///< -1 (not given): the value as written, up to 6 significant digits
  std::string text(double v) const;  ///< "15 mm"
};

struct ReferenceTable {
  std::string id;           ///< "4.3": names the table's cells ("4.3 15 mm backward") and --only
  std::string title;        ///< the report's heading
  std::string about;        ///< Markdown under the heading: the set-up and the labels' meaning
  std::string group;        ///< the tally its cells count in; empty: shown, not tallied
  NumberFormat param{"parameter"};  ///< how the cells' parameters are shown (and named)
  std::string variant_header;  ///< column of the cells' variants; empty: no such column
  std::vector<std::string> references;  ///< column headers; the first is the one compared
  std::string ours_header = "ours";
  std::string companion;        ///< optional experiment run on the same cells, shown, not tallied
  std::string companion_header;
  NumberFormat value;            ///< optional column (header set): the mean measured Outcome::value
  std::vector<std::string> after;  ///< built-in paragraphs printed under the table (by name)
  std::vector<ReferenceCell> cells;

  /// Whether the cells span more than one level (the report then has a level column).
  bool severalLevels() const;
  /// Whether a cell drives at other than the seed's 2.8 cm/s (the report then has a speed column).
  bool otherSpeeds() const;
  /// Whether the cells' variants, or their treels' mu, differ (the report then shows them).
  bool severalVariants() const;
  bool severalFloors() const;
  /// The parameter as shown ("15 mm").
  std::string paramText(const ReferenceCell& c) const;
  /// The cell's name in the report and in the mismatch reasons: "<id> <param> [<variant>] [<level>]"
  /// (the level only when the table spans several): "4.3 15 mm backward", "4.5 4.0 cm simple".
  std::string key(const ReferenceCell& c) const;
};

struct ReferenceGroup {
  std::string name;   ///< what tables give as `group`
  std::string title;  ///< the summary's line: "<title> matched: 17/20"
  bool required = false;  ///< every cell must match for exit status 0
};

/// One entry of the report: a built-in section (`section` set) or a table.
struct ReportEntry {
  std::string section;
  ReferenceTable table;
  std::string name() const { return section.empty() ? table.id : section; }
};

/// What the loader checks the file against: the built-in sections and paragraphs sbot_validate
/// can write, the levels that exist, and (for each built-in section that tallies cells) its group.
struct ReferenceVocabulary {
  std::vector<std::string> sections;
  std::vector<std::string> paragraphs;
  std::vector<std::string> levels;
  std::vector<std::pair<std::string, std::string>> section_groups;  ///< (section, group it tallies in)
};

struct ReferenceTables {
  std::string source;  ///< the file, as the report names it
  std::vector<ReferenceGroup> groups;
  std::vector<ReportEntry> report;

  /// Reads and checks a file. Throws std::runtime_error naming the file, the entry (the table's id,
  /// the cell's index) and the problem: not YAML, a missing or unknown field, an experiment that is
  /// not a labelled kind, a parameter that is not a number or out of the kind's range, a level or a
  /// section that does not exist, a reference label the experiment never yields, a group not
  /// defined, a duplicate table id or cell. `shown_as`: how the report names the file.
  static ReferenceTables load(const std::string& path, const ReferenceVocabulary& vocabulary,
                              const std::string& shown_as = "");

  const ReferenceGroup* findGroup(const std::string& name) const;
};

}  // namespace validation
}  // namespace sbot
