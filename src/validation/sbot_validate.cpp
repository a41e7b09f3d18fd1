// sbot_validate: the validation experiments run headless on the core, written up as a Markdown report
// that puts every cell of a reference table beside ours (plus PNG plots). The tables are data:
// config/validation/reference_tables.yaml holds the seed's chapter 4 (which experiment, level and
// parameter each cell runs, and what the hardware or the seed's simulator observed); --tables FILE
// runs another file of the same form (reference_tables.h), e.g. your own measurements.
//
//   rosrun swarmbot3d sbot_validate [--out DIR] [--quick] [--trials N] [--jobs 2] [--only LIST]
//                                   [--tables YAML] [--reasons YAML] [--heightmap PNG]
//
// LIST: comma-separated table ids and built-in sections of the tables file (the seed's: facts, 4.1,
// 4.1pair, 4.2, 4.3, 4.4, compat, fig4.4, 4.5, 4.6, 4.2.4; default: all; an unknown name is refused,
// as is an unreadable --heightmap when fig4.4 is wanted, and a tables file with any error).
// --quick: 3 trials per cell and 4 runs per roughness (minutes instead of tens of minutes).
// Exit status: 0 when every cell of the file's required groups (the seed's: the hardware cells of
// Tables 4.1-4.3) matches, 1 otherwise, 2 on bad usage or when the report cannot be saved (--out is
// created with its parents and checked before any trial; a report that fails to save at the end is
// still printed on stdout), 3 when a cell had trials that could not run (an exception or a crashed
// worker; the report marks them "error" and lists the cells).
//
//   sbot_validate [--trace] [--index N] [--speed UNITS] [--track-mu MU|lab_floor] --trial KIND LEVEL PARAM    one trial, printed
//     (tuning aid); --trace prints the robot's state every 0.1 s (pose, attitude, wheel load, track
//     speeds, turret angle, gripper tip); --index N runs the cell's trial N (its start
//     perturbation, as in the report; default 0); --speed: setSpeed units (default 10, 2.8 cm/s);
//     --track-mu: the treels' mu on the terrain, e.g. lab_floor for Tables 4.2/4.3's cells (default:
//     the experiment's own, 1.0)
// KIND: gap, step, stepb, slope, slopeb, uphill, downhill, rough, rtm, speed (PARAM: m, m, m, deg,
// deg, rad, rad, HR in cm, simulated s, setSpeed units of the compatibility check; ranges in
// experimentKinds(), experiments.h).
//
//   sbot_validate --scenario FILE [--index N] [--speed UNITS] --trial KIND LEVEL PARAM
//     the trial is not run: its world and start are written to FILE as a scenario for the simulator
//     node, with the roslaunch and rostopic commands to watch it in rviz (gap, step, stepb, uphill,
//     downhill; a slope trial tilts gravity, which a scenario cannot).
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "experiments.h"
#include "mismatch_reasons.h"
#include "reference_tables.h"
#include "sbot_sim/tools/cli_args.h"
#include "sbot_sim/tools/machine.h"
#include "two_sbots_trials.h"
#include "validate_report.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/terrain.h"
#include "sbot_sim/core/world_config.h"

using namespace sbot_validate_tool;

namespace {

/// The first words of every scenario file --scenario writes: a file that does not start with them
/// is someone else's and is not overwritten.
constexpr const char* kTrialScenarioMark = "# Validation trial";

/// --scenario FILE --trial KIND LEVEL PARAM: the trial's world and start as a scenario file for the
/// simulator node, so that a cell can be watched in rviz (how, printed). Exit status as main's.
int writeTrialScenario(const std::string& file, const v::ExperimentKind& kind, const std::string& level, double param,
                       int index, const v::Drive& drive) {
  const std::string what = kind.name + " " + level + " " + fmt(param, 4);
  if (!kind.world) {
    std::string kinds;
    for (const v::ExperimentKind& k : v::experimentKinds())
      if (k.world) kinds += (kinds.empty() ? "" : ", ") + k.name;
    std::fprintf(stderr,
                 "sbot_validate: --scenario: a %s trial cannot be written as a scenario (a scenario's gravity points "
                 "straight down and its terrain is planes, boxes or a height field); these kinds can: %s\n",
                 kind.name.c_str(), kinds.c_str());
    return 2;
  }
  if (file.empty()) {
    std::fprintf(stderr, "sbot_validate: --scenario expects a file name, found ''\n");
    return 2;
  }
  {  // a scenario of the user's own (or any other file) under that name would be lost
    std::ifstream existing(file);
    std::string first;
    if (existing && std::getline(existing, first) && first.rfind(kTrialScenarioMark, 0) != 0) {
      std::fprintf(stderr,
                   "sbot_validate: --scenario: %s exists and was not written by sbot_validate --scenario (its first "
                   "line is not '%s ...'); not overwritten: remove it or choose another name\n",
                   file.c_str(), kTrialScenarioMark);
      return 2;
    }
  }
  const v::TrialWorld t = kind.world(level, param, index, drive);
  sbot::Scenario sc;
  sc.world = t.world;
  sc.robots.push_back({"sbot_0", level, t.start});
  sc.duration = 0;  // driven by hand: until stopped
  // The two commands that show it, written into the file's header and printed.
  const std::string launch_cmd = "roslaunch swarmbot3d swarm.launch scenario:=" + file + " robots:=1 level:=" + level +
                                 " controller:=false headless:=false real_time_factor:=1";
  const std::string drive_cmd = "rostopic pub -1 /sbot_0/cmd_speed sbot_msgs/TrackSpeed '{left: " +
                                std::to_string(t.units) + ", right: " + std::to_string(t.units) + "}'";
  const std::string header =
      std::string(kTrialScenarioMark) + " '" + what + "', trial " + std::to_string(index) + " of its cell (start perturbation included),\n"
      "# written by sbot_validate --scenario. To watch it:\n"
      "#   " + launch_cmd + "\n"
      "#   " + drive_cmd + "   # the trial's drive, after it stood " + fmt(t.settle, 1) + " s\n"
      "# The trial's own time limit: " + fmt(t.seconds, 1) + " s of driving.\n";
  try {
    sbot::writeTextFile(file, header + sbot::scenarioYaml(sc, "trial_" + kind.name + "_" + level,
                                                          "sbot_validate trial " + what + ", index " + std::to_string(index)));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sbot_validate: --scenario: %s\n", e.what());
    return 2;
  }
  std::printf("wrote %s: trial %s (index %d)\nwatch it:\n  %s\n  %s\n", file.c_str(), what.c_str(), index,
              launch_cmd.c_str(), drive_cmd.c_str());
  return 0;
}

/// What the command line asks for: a report (o) or one trial (trial, with its own options).
struct Command {
  Options o;
  bool trace = false;
  int index = 0;  // --index: which trial of a cell --trial runs (its start perturbation)
  v::Drive drive;  // --speed: the labelled trials' setSpeed units (default: the seed's 2.8 cm/s)
  std::string scenario_file;  // --scenario: write --trial's world as a scenario file instead of running it
  bool write_scenario = false;  // --scenario given (an empty name is refused, not taken for its absence)
  std::vector<std::string> trial_options;  // given options that only --trial reads
  std::vector<std::string> report_options;  // given options that only a report reads
  const v::ExperimentKind* trial = nullptr;  // --trial KIND LEVEL PARAM
  std::string trial_kind, trial_level;  // as given
  double trial_param = 0;
};

/// parseArgs' and the checks' answer when the run goes on.
constexpr int kGoOn = -1;

/// --trial KIND LEVEL PARAM (the last option), checked: kGoOn or an exit status.
int readTrial(sbot_tools::ArgReader& args, Command& c) {
  const std::string kind = args.value("KIND LEVEL PARAM"), level = args.value("LEVEL PARAM after KIND");
  const v::ExperimentKind* k = v::findExperimentKind(kind);
  if (!k) {
    std::fprintf(stderr, "sbot_validate: --trial expects %s, found '%s'\n", v::experimentKindNames().c_str(), kind.c_str());
    return 2;
  }
  sbot_tools::requireLevel("sbot_validate", "--trial " + kind + " " + level, level);
  const double p = sbot_tools::numberArg(args.tool(), "--trial " + kind + " " + level + " (" + k->unit + ")",
                                         args.value("PARAM after KIND LEVEL"), k->min, k->max);
  if (args.more()) {  // options after it would be ignored: the trial runs as soon as it is read
    std::fprintf(stderr, "sbot_validate: --trial KIND LEVEL PARAM comes last; found '%s' after it\n", args.peek().c_str());
    return 2;
  }
  if (!c.report_options.empty()) {  // a single trial would run without them
    std::fprintf(stderr, "sbot_validate: %s makes a report; --trial runs one trial (its own options: --trace, "
                         "--index, --speed, --track-mu, --scenario)\n", c.report_options.front().c_str());
    return 2;
  }
  if (kind == "speed" && p != std::round(p)) {  // setSpeed takes whole units: 0.4 would drive at 0
    std::fprintf(stderr, "sbot_validate: --trial speed %s expects a whole number of setSpeed units, found %g\n",
                 level.c_str(), p);
    return 2;
  }
  c.trial = k;
  c.trial_kind = kind;
  c.trial_level = level;
  c.trial_param = p;
  return kGoOn;
}

int usage(const std::string& a) {
  if (a != "--help") std::fprintf(stderr, "sbot_validate: unknown option '%s'\n", a.c_str());
  std::fprintf(stderr, "usage: sbot_validate [--out DIR] [--quick] [--trials N] [--jobs N] [--only LIST]\n"
                       "                     [--tables YAML] [--reasons YAML] [--heightmap PNG]\n"
                       "       sbot_validate [--trace] [--index N] [--speed UNITS] [--track-mu MU|lab_floor] --trial KIND LEVEL PARAM\n"
                       "       sbot_validate --scenario FILE [--index N] [--speed UNITS] [--track-mu MU|lab_floor] --trial KIND LEVEL PARAM\n");
  return a == "--help" ? 0 : 2;
}

/// The command line into `c`: kGoOn or an exit status (usage, --help, a refused option).
int parseArgs(int argc, char** argv, Command& c) {
  Options& o = c.o;
  sbot_tools::ArgReader args("sbot_validate", argc, argv);
  std::set<std::string> given;  // an option given twice: the second would silently replace the first
  while (args.more()) {
    const std::string a = args.option();
    if (a.rfind("--", 0) == 0 && !given.insert(a).second) {
      std::fprintf(stderr, "sbot_validate: %s is given twice\n", a.c_str());
      return 2;
    }
    if (a == "--out") o.out = args.value(), c.report_options.push_back(a);
    else if (a == "--quick") o.quick = true, c.report_options.push_back(a);
    else if (a == "--trials") o.trials = args.count(1, 1000), c.report_options.push_back(a);
    else if (a == "--jobs") o.jobs = args.count(1, 64), c.report_options.push_back(a);
    else if (a == "--heightmap") o.heightmap = args.value(), c.report_options.push_back(a);
    else if (a == "--reasons") o.reasons = args.value(), c.report_options.push_back(a);
    else if (a == "--tables") o.tables = args.value(), c.report_options.push_back(a);
    else if (a == "--trace") c.trace = true;  // with --trial (before it): the robot's state every 0.1 s
    else if (a == "--index") c.index = args.count(0, 999), c.trial_options.push_back(a);  // with --trial: the cell's trial N
    else if (a == "--speed") c.drive.units = args.count(1, 70), c.trial_options.push_back(a);  // with --trial: setSpeed units
    else if (a == "--track-mu") {  // with --trial (before it): the treels' mu on the terrain (a table's track_mu)
      const std::string m = args.value();
      c.drive.track_mu = m == v::kLabFloorName ? v::kLabFloorTrackMu : sbot_tools::numberArg(args.tool(), "--track-mu", m, 1e-6, 100);
      c.trial_options.push_back(a);
    }
    else if (a == "--scenario") c.scenario_file = args.value(), c.write_scenario = true, c.trial_options.push_back(a);  // with --trial: write, do not run
    else if (a == "--trial") return readTrial(args, c);  // --trial KIND LEVEL PARAM: one trial, printed (tuning aid)
    else if (a == "--only") {
      const std::string list = args.value();
      if (list.empty()) {  // an empty shell variable would otherwise run the whole suite
        std::fprintf(stderr, "sbot_validate: --only expects a list of sections and table ids, found ''\n");
        return 2;
      }
      std::stringstream ss(list);
      for (std::string s; std::getline(ss, s, ',');) o.only.insert(s);
    } else {
      return usage(a);
    }
  }
  if (c.trace) {  // a whole report's trials would interleave their traces from the worker processes
    std::fprintf(stderr, "sbot_validate: --trace goes with --trial (before it): one trial, traced\n");
    return 2;
  }
  if (!c.trial_options.empty()) {  // the report would run without them, at the tables' own values
    std::fprintf(stderr, "sbot_validate: %s goes with --trial (before it); a report takes its speeds and floors from the tables\n",
                 c.trial_options.front().c_str());
    return 2;
  }
  return kGoOn;
}

/// --trial: the one trial, printed, or written as a scenario (--scenario).
int runTrial(const Command& c) {
  const v::ExperimentKind& k = *c.trial;
  const double p = c.trial_param;
  if (c.write_scenario) return writeTrialScenario(c.scenario_file, k, c.trial_level, p, c.index, c.drive);
  v::setTrace(c.trace);
  v::setRoughHeightmap(findHeightmap());
  const Outcome r = k.run(c.trial_level, p, c.index, c.drive);
  std::printf("%s %s %g: %s", c.trial_kind.c_str(), c.trial_level.c_str(), p, r.label.c_str());
  for (const auto& [m, x] : {std::make_pair(k.value, r.value), std::make_pair(k.value2, r.value2)})
    if (!m.name.empty()) std::printf("; %s %g%s", m.name.c_str(), x, m.unit.empty() ? "" : (" " + m.unit).c_str());
  std::printf("\n");
  return 0;
}

/// Whether the report has section or table `name`: the tables file lists it and --only (if any) names it.
bool wanted(const Options& o, const v::ReferenceTables& tables, const std::string& name) {
  const bool listed =
      std::any_of(tables.report.begin(), tables.report.end(), [&](const v::ReportEntry& e) { return e.name() == name; });
  return listed && (o.only.empty() || o.only.count(name));
}

/// The reasons for mismatches (--reasons, else the seed's for the seed's tables, else none), and a
/// warning for each reason that names no cell (a typo: it would never be shown). kGoOn or 2.
int loadReasons(const Options& o, const v::ReferenceTables& tables, const std::string& source_dir) {
  try {  // before any work: a report whose mismatches cannot be explained is not written
    // Your own tables without --reasons: the seed's reasons are about the seed's cells, and would
    // "explain" a cell of yours that happens to share a name.
    if (!o.reasons.empty()) {
      reasons = v::MismatchReasons::load(o.reasons);
      if (reasons.keys().empty()) std::fprintf(stderr, "sbot_validate: warning: --reasons %s holds no reasons\n", o.reasons.c_str());
    }
    else if (o.tables.empty()) reasons = v::MismatchReasons::load(source_dir + "/" + v::kMismatchReasonsFile, v::kMismatchReasonsFile);
    else reasons = v::MismatchReasons::none();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sbot_validate: --reasons: %s\n", e.what());
    return 2;
  }
  std::set<std::string> keys;
  for (const v::ReportEntry& e : tables.report) {
    for (const v::ReferenceCell& c : e.table.cells) keys.insert(e.table.key(c));
    if (e.section == "4.1pair") keys.insert({kPairFullKey, kPairStableKey, kPairStepSingleKey, kPairStepTwoKey});
    if (e.section == "fig4.4")
      for (const char* level : kFig44ReadLevels) keys.insert(fig44Key(level));
  }
  for (const std::string& k : reasons.keys())
    if (!keys.count(k))
      std::fprintf(stderr, "sbot_validate: warning: %s: the reason for '%s' names no cell of %s\n", reasons.source().c_str(),
                   k.c_str(), tables.source.c_str());
  return kGoOn;
}

/// What a report reads, loaded and checked before any work (a bad tables file, --only name,
/// height map, reasons file, model description or output folder would waste the runs before it):
/// kGoOn or an exit status.
int loadReportInputs(Options& o, const std::vector<std::string>& report_options, v::ReferenceTables& tables) {
  if (o.quick) { o.trials = std::min(o.trials, 3); o.rough_runs = 4; }
  o.rough_runs = std::max(o.rough_runs, o.quick ? 4 : 12);
  if (o.heightmap.empty()) o.heightmap = findHeightmap();
  v::setRoughHeightmap(o.heightmap);
  const std::string source_dir = SWARMBOT3D_SOURCE_DIR;
  try {  // before any work: a file with an error in its last table would waste the first ones' runs
    const v::ReferenceVocabulary vocabulary{kSections, kParagraphs, kAllLevels, {{"4.1pair", kHardwareGroup}}};
    tables = o.tables.empty() ? v::ReferenceTables::load(source_dir + "/" + v::kReferenceTablesFile, vocabulary,
                                                         v::kReferenceTablesFile)
                              : v::ReferenceTables::load(o.tables, vocabulary);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sbot_validate: --tables: %s\n", e.what());
    return 2;
  }
  for (const std::string& s : o.only) {  // a misspelt name would leave an empty report
    if (std::none_of(tables.report.begin(), tables.report.end(), [&](const v::ReportEntry& e) { return e.name() == s; })) {
      std::string known;
      for (const v::ReportEntry& e : tables.report) known += (known.empty() ? "" : ", ") + e.name();
      std::fprintf(stderr, "sbot_validate: --only: unknown section '%s' (in %s: %s)\n", s.c_str(), tables.source.c_str(),
                   known.c_str());
      return 2;
    }
  }
  const bool heightmap_given = std::find(report_options.begin(), report_options.end(), "--heightmap") != report_options.end();
  const bool fig44 = wanted(o, tables, "fig4.4");
  if (heightmap_given && !fig44)  // a typo in it would otherwise pass unseen
    std::fprintf(stderr, "sbot_validate: warning: --heightmap is not used: the run has no fig4.4 section\n");
  if (fig44) {  // before any work: every rough-terrain run would fail on it
    sbot::TerrainConfig t;
    t.type = sbot::TerrainConfig::Type::Rough;
    t.heightmap_image = o.heightmap;
    try {
      sbot::makeHeightMap(t);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sbot_validate: --heightmap (or $SBOT_HEIGHTMAP): %s\n", e.what());
      return 2;
    }
  }
  if (loadReasons(o, tables, source_dir) != kGoOn) return 2;
  for (const std::string& level : kAllLevels)  // before any work: every trial of that level would fail on it
    sbot_tools::requireLevel("sbot_validate", "model description of level '" + level + "' (or $SBOT_DESCRIPTION_DIR)", level);
  // Before any work: a report that cannot be saved would be found out only at the end.
  sbot_tools::requireOutputDirectory("sbot_validate", "--out", o.out);
  return kGoOn;
}

/// The report's opening paragraph: what a cell shows and how the trials run.
void writeIntro(std::ostream& md, const Options& o) {
  md << "# swarmbot3d validation report\n\n"
     << "Generated by `sbot_validate` (src/validation/) on the headless core. Every cell: the reference "
        "(the hardware's or the seed's value, from the tables file named in the summary), ours (modal label "
        "and the distribution over the trials), match / mismatch. A tie (e.g. 6 / 6 of 12) is printed as "
        "\"tie: a / b\" and matches only if the reference accepts every tied label, in every tallied table. "
     << "Trials per cell: " << o.trials << (o.quick ? " (--quick)" : "") << ". Speed in gap and slope experiments: "
     << "2.8 cm/s (10 API units) as in 4.2.3. Each trial is a fresh World with small seeded perturbations "
        "of the start pose (heading +-3 deg, lateral +-1 cm, distance +-5 mm). Worlds use each level's "
        "recommended step, gravity and quickstep iterations (sidecar `solver_iterations`: Medium 25, "
        "Detailed 40, others the world default 20). The front gripper's servos hold elevation 0 (as the powered real "
        "gripper does); the side arm is held folded by the core.\n\n";
}

/// Every section and table the report has, in the tables file's order, tallied per group. The
/// report so far is saved after every section as report.partial.md, so that a run stopped part-way
/// (Ctrl-C, a killed job, a full disk at the end) keeps the sections it finished; the finished run
/// removes it.
std::map<std::string, Tally> runSections(std::ostringstream& md, const Options& o, const v::ReferenceTables& tables,
                                         const RtmRuns& rtm) {
  std::vector<std::string> to_come;
  for (const v::ReportEntry& e : tables.report)
    if (wanted(o, tables, e.name())) to_come.push_back(e.name());
  const std::string partial = o.out + "/" + kPartialReportFile;
  auto checkpoint = [&] {
    std::string note = "\n---\n*Partial report: sbot_validate did not finish this run (or is still running it). The "
                       "sections above are complete; not reached:";
    for (const std::string& s : to_come) note += " " + s;
    note += ". No summary or exit status was written.*\n";
    try {
      sbot::writeTextFileAtomically(partial, md.str() + note);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sbot_validate: warning: the partial report was not saved: %s\n", e.what());
    }
  };
  checkpoint();
  std::map<std::string, Tally> tallies;
  for (const v::ReportEntry& e : tables.report) {
    if (!wanted(o, tables, e.name())) continue;
    if (!e.section.empty()) {
      if (e.section == "facts") writeFacts(md, o);
      else if (e.section == "4.1pair") writePairRows(md, o, tallies[kHardwareGroup]);
      else if (e.section == "4.4") writeRtm(md, o, rtm);
      else if (e.section == "compat") writeCompat(md, o);
      else if (e.section == "fig4.4") writeFig44(md, o);
    } else {
      writeTable(md, e.table, o, tallies);
    }
    to_come.erase(to_come.begin());
    checkpoint();
  }
  return tallies;
}

std::string cellList(const std::vector<std::string>& keys) {
  std::string s;
  for (const std::string& k : keys) s += (s.empty() ? "" : "; ") + k;
  return s;
}

/// The summary: each group's tally (and what --only left out of it), the wall time, the cells that
/// could not run, unexplained mismatches and stale reasons. `counts`: the tallies in one line.
/// Returns whether every required group matched.
bool writeSummary(std::ostream& md, const Options& o, const v::ReferenceTables& tables,
                  std::map<std::string, Tally>& tallies, std::string& counts) {
  md << "## Summary\n\n";
  bool required_match = true;
  for (const v::ReferenceGroup& g : tables.groups) {
    const Tally& t = tallies[g.name];
    if (g.required) required_match = required_match && t.match == t.total;
    // What --only left out of the tally: a "4/4" of a group with nine cells would read as all of it.
    int cells_not_run = 0;
    std::vector<std::string> sections_not_run;
    for (const v::ReportEntry& e : tables.report) {
      if (wanted(o, tables, e.name())) continue;
      if (e.section.empty() && e.table.group == g.name) cells_not_run += static_cast<int>(e.table.cells.size());
      if (e.section == "4.1pair" && g.name == kHardwareGroup) sections_not_run.push_back(e.section);
    }
    std::string left_out;
    if (cells_not_run > 0) left_out = std::to_string(cells_not_run) + " cells";
    for (const std::string& sec : sections_not_run) left_out += (left_out.empty() ? "" : " and ") + ("section " + sec);
    if (t.total == 0 && left_out.empty()) continue;
    md << "- " << g.title << " matched: " << t.str();
    if (!left_out.empty()) md << " (" << left_out << " of this tally not run: --only)";
    md << "\n";
    counts += (counts.empty() ? "" : ", ") + g.name + " " + t.str() + (left_out.empty() ? "" : " (" + left_out + " not run)");
  }
  if (counts.empty()) {  // every table shown, none compared: an exit status 0 would say nothing
    md << "- No cell is tallied: no table run names a group (`group:` in the tables file), so nothing was "
          "compared and the exit status says nothing.\n";
    std::fprintf(stderr, "sbot_validate: warning: no cell is tallied (no table run names a group of %s)\n",
                 tables.source.c_str());
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - g_start).count();
  md << "- Wall time: " << fmt(total, 0) << " s on " << o.jobs << " processes\n";
  if (!g_error_cells.empty())
    md << "- Cells with trials that could not run (\"error\"; the cause is on stderr): " << cellList(g_error_cells) << "\n";
  if (!reasons.unexplained().empty())
    md << "- Mismatches not explained yet (new since the analysis): " << cellList(reasons.unexplained()) << "\n";
  if (!reasons.stale().empty())
    md << "- Recorded reasons whose cell now matches (remove them from `" << reasons.source()
       << "`): " << cellList(reasons.stale()) << "\n";
  md << "\nReference tables: `" << tables.source << "`. ";
  if (reasons.fromFile()) md << "Each mismatch is explained under its table (from `" << reasons.source() << "`)";
  else md << "Each mismatch is listed under its table, not explained (no reasons file: `--reasons FILE`)";
  if (o.tables.empty()) md << "; the analysis behind them is *Why cells do not match* in `docs/validation.md`";
  md << ".\n";
  return required_match;
}

/// The report printed and saved in --out (the partial one removed); the exit status of the run.
int saveReport(const std::ostringstream& md, const Options& o, const std::string& counts, bool required_match) {
  std::printf("%s", md.str().c_str());
  std::fflush(stdout);
  try {
    sbot::writeTextFile(o.out + "/report.md", md.str());
  } catch (const std::exception& e) {  // the report is on stdout above: say so, and fail the run
    std::fprintf(stderr, "sbot_validate: the report was not saved (it is printed above): %s\n", e.what());
    return 2;
  }
  std::remove((o.out + "/" + kPartialReportFile).c_str());
  progress("wrote " + o.out + "/report.md (" + counts + ")");
  if (!g_error_cells.empty()) {
    std::fprintf(stderr, "sbot_validate: %zu cell(s) had trials that could not run: %s\n", g_error_cells.size(),
                 cellList(g_error_cells).c_str());
    return 3;
  }
  return required_match ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (!v::studyKnobsOk("sbot_validate")) return 2;
  Command c;
  const int parsed = parseArgs(argc, argv, c);
  if (parsed != kGoOn) return parsed;
  if (c.trial) return runTrial(c);
  Options& o = c.o;
  v::ReferenceTables tables;
  const int loaded = loadReportInputs(o, c.report_options, tables);
  if (loaded != kGoOn) return loaded;
  RtmRuns rtm;
  if (wanted(o, tables, "4.4")) rtm = measureRtm(o);
  std::ostringstream md;
  writeIntro(md, o);
  std::map<std::string, Tally> tallies = runSections(md, o, tables, rtm);
  std::string counts;
  const bool required_match = writeSummary(md, o, tables, tallies, counts);
  return saveReport(md, o, counts, required_match);
}
