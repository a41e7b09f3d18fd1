// sbot_validate's report: its options, the helpers every section uses (numbers, tallies, the
// reasons for mismatches), and the sections (validate_sections.cpp) that sbot_validate.cpp's main
// runs in the tables file's order.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "experiments.h"
#include "mismatch_reasons.h"
#include "reference_tables.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot_validate_tool {

using sbot::validation::Outcome;
namespace v = sbot::validation;

struct Options {
  std::string out = "validation_report";
  bool quick = false;
  int trials = 12;
  int rough_runs = 12;
  int jobs = 2;
  std::set<std::string> only;
  std::string heightmap;
  std::string reasons;  ///< YAML: why cells do not match (default: config/validation/mismatch_reasons.yaml)
  std::string tables;   ///< YAML: the reference tables (default: config/validation/reference_tables.yaml)
};

inline const std::vector<std::string> kLevels{"fast", "simple", "medium", "detailed"};
/// Table 4.4: the seed's real-time multiplier per level; the target is ten times it.
inline const std::map<std::string, double> kSeedRtm{{"fast", 950}, {"simple", 94}, {"medium", 31}, {"detailed", 3}};
inline double rtmTarget(const std::string& level) { return 10 * kSeedRtm.at(level); }
/// Every model level (the core's list): the model facts cover Basic too (the seed's tables do not).
inline const std::vector<std::string>& kAllLevels = sbot::modelLevels();
constexpr int kRtmRepeats = 5;  ///< Table 4.4: runs per RTM figure, the fastest reported
/// The built-in sections a tables file can place in its report (experiments that are not cells of
/// one trial kind), the paragraphs a table can have printed under it, and the group the two-robot
/// rows tally in.
inline const std::vector<std::string> kSections{"facts", "4.1pair", "4.4", "compat", "fig4.4"};
inline const std::vector<std::string> kParagraphs{"backward_step_statics"};
inline const char* const kHardwareGroup = "hardware";
/// The report so far, in --out beside report.md, while a run goes on or after it stopped part-way.
inline const char* const kPartialReportFile = "report.partial.md";

inline std::string fmt(double v, int prec = 2) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

/// A relative difference as "-0.3 %" (never "-0.0 %").
inline std::string percent(double relative) { return fmt(std::round(relative * 1000) / 10 + 0.0, 1) + " %"; }

/// A run that threw (runParallel's "error" outcome) has no numbers: its cells say "error", never 0.
inline bool failed(const Outcome& o) { return o.label == "error"; }
inline std::string number(const Outcome& o, double v, int prec) { return failed(o) ? "error" : fmt(v, prec); }

/// "pass 11/12" style summary of a cell's outcomes.
inline std::string summary(const std::vector<Outcome>& os) {
  std::map<std::string, int> c;
  for (const auto& o : os) ++c[o.label];
  std::vector<std::pair<int, std::string>> v;
  for (auto& [k, n] : c) v.push_back({-n, k});
  std::sort(v.begin(), v.end());
  std::string s;
  for (auto& [n, k] : v) s += (s.empty() ? "" : ", ") + k + " " + std::to_string(-n) + "/" + std::to_string(os.size());
  return s;
}

struct Tally {
  int match = 0, total = 0;
  std::string str() const { return std::to_string(match) + "/" + std::to_string(total); }
};

/// The report's reasons for the cells that do not match (mismatch_reasons.h).
extern v::MismatchReasons reasons;

/// Cells with a trial that could not run (an exception or a crashed worker, said on stderr): they
/// are not mismatches of the model, and the exit status says so.
extern std::vector<std::string> g_error_cells;

/// The cells the built-in section 4.1pair names (its rows are not cells of a tables file).
inline const char* const kPairFullKey = "4.1 pair limit of full manoeuvrability";
inline const char* const kPairStableKey = "4.1 pair limit of stable position";
inline const char* const kPairStepSingleKey = "4.1.3 32 mm single s-bot";
inline const char* const kPairStepTwoKey = "4.1.3 32 mm two connected";
/// The rows of Figure 4.4's reading (writeFig44Reading) that the seed's text speaks of.
inline std::string fig44Key(const std::string& level) { return "fig4.4 " + level; }
inline const char* const kFig44ReadLevels[] = {"fast", "simple", "medium"};

/// Tallies cell `key` and returns its match column; a mismatch is explained under its table.
inline std::string mark(const std::string& key, bool ok, Tally& t) {
  ++t.total;
  t.match += ok;
  return reasons.record(key, ok);
}

/// A cell whose modal label is "error" (its trials could not run) is counted as not matching but is
/// no model mismatch: marked so, it is listed in the summary (g_error_cells), not among the
/// mismatches to explain.
inline std::string markRun(const std::string& key, bool ok, bool ran, Tally& t) {
  if (ran) return mark(key, ok, t);
  ++t.total;
  return "**error** (could not run)";
}

/// A tallied cell's modal label as the report prints it, and whether the seed (or the hardware)
/// accepts it; every tallied table uses it. A tie (e.g. 6 / 6 of 12) is printed as one and matches
/// only if every tied label is accepted: which of them comes first is only the order of the trials.
struct ModalCell {
  std::string text;
  bool ok = false;
  bool ran = true;  ///< false when "error" (a trial that could not run) is a modal label
};
inline ModalCell modalCell(const std::string& expected, const std::vector<Outcome>& outcomes) {
  const std::vector<std::string> labels = v::modalLabels(outcomes);
  ModalCell cell;
  cell.ok = !labels.empty();
  for (std::size_t i = 0; i < labels.size(); ++i) {
    cell.text += (i ? " / " : "") + labels[i];
    cell.ok = cell.ok && v::accepts(expected, labels[i]);
    cell.ran = cell.ran && labels[i] != "error";
  }
  if (labels.size() > 1) cell.text = "tie: " + cell.text;
  return cell;
}

/// Table 4.4's runs: measured before the other sections, on a machine not yet busy with the
/// suite's two workers (after them this VM ran the same binary 10-15 % slower for a minute or
/// more); written in the section's place.
struct RtmRuns {
  std::map<std::string, std::array<v::Outcome, 2>> fastest;  ///< per level: [with sensors, physics only]
  std::map<std::string, double> slowest;  ///< per level, with sensors: how steady the machine was
  std::map<std::string, v::StepCost> profile;  ///< per level: the profiled run whose solver was fastest
  double load[3] = {0, 0, 0};             ///< load average before the runs
  std::string machine;                    ///< processor and cores (sbot_tools::describeThisMachine)
};
/// The default rough-terrain height map ($SBOT_HEIGHTMAP, else the package's).
std::string findHeightmap();
/// When the run started, and progress on stderr with the seconds since.
extern const std::chrono::steady_clock::time_point g_start;
void progress(const std::string& s);

// The built-in sections (kSections) and a reference table; Table 4.4's runs are measured first.
void writeFacts(std::ostream& md, const Options& o);
void writePairRows(std::ostream& md, const Options& o, Tally& hw);
RtmRuns measureRtm(const Options& o);
void writeRtm(std::ostream& md, const Options& o, const RtmRuns& runs);
void writeCompat(std::ostream& md, const Options& o);
void writeFig44(std::ostream& md, const Options& o);
void writeTable(std::ostream& md, const v::ReferenceTable& t, const Options& o, std::map<std::string, Tally>& tallies);

}  // namespace sbot_validate_tool
