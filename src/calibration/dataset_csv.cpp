// A run's CSV file (docs/calibration.md): its header, its rows, and the checks on the whole run.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <tuple>

#include "calibration/dataset.h"
#include "calibration/dataset_internal.h"
#include "calibration/sensor_bridge.h"  // SensorBridge::supports
#include "sbot_sim/core/world.h"        // kMaxCoordinate

namespace sbot::calib {

namespace detail {

std::string fmtNumber(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

std::string channelRangeProblem(const std::string& channel, double v) {
  const std::string g = NoiseModel::group(channel);
  double lo = 0, hi = 0;
  std::string unit;
  if (g == "ir") hi = 8191;
  else if (g == "ground") hi = 255;
  else if (g == "light") hi = 700;
  else if (g == "position") lo = -kMaxCoordinate, hi = kMaxCoordinate, unit = " m";
  else if (g == "yaw" || g == "tilt") lo = -1000, hi = 1000, unit = " rad";  // unwrapped angles may run on
  else if (g == "speed" || g == "torque") lo = -1000, hi = 1000, unit = " API units";
  else return "";
  if (v >= lo && v <= hi) return "";
  return "value " + fmtNumber(v) + " outside the range of " + channel + " [" + fmtNumber(lo) + ", " + fmtNumber(hi) +
         "]" + unit;
}

}  // namespace detail

using detail::channelRangeProblem;
using detail::fmtNumber;

bool isKnownColumn(const std::string& c) {
  static const std::set<std::string> fixed{"t",           "cmd_left",     "cmd_right",   "x",        "y",
                                           "yaw",         "z",            "speed_left",  "speed_right",
                                           "torque_left", "torque_right", "pitch",       "roll",
                                           "force_x",     "force_y",      "passive"};
  if (fixed.count(c)) return true;
  static const std::regex indexed("(ir([0-9]|1[0-4])|ground[0-3]|light[0-7])");
  return std::regex_match(c, indexed);
}

namespace {

/// The first byte no text CSV holds: NUL, or a control character other than tab, CR and LF
/// (binary and compressed files have them within their first bytes). Bytes >= 0x80 pass: a Latin-1
/// comment in a user column is still text.
struct NonTextByte {
  int line = 0;            ///< 1-based; 0: none found
  std::size_t byte = 0;    ///< 1-based within its line
  unsigned char value = 0;
};
NonTextByte firstNonTextByte(const std::string& text) {
  NonTextByte b{1, 0, 0};
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++b.line;
      line_start = i + 1;
    } else if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
      b.byte = i - line_start + 1;
      b.value = c;
      return b;
    }
  }
  return {};
}

std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

bool parseNumber(const std::string& cell, double& out) {
  if (cell.empty()) return false;
  const char* b = cell.c_str();
  char* e = nullptr;
  errno = 0;
  out = std::strtod(b, &e);
  // strtod also reads hexadecimal ("0x10" = 16), which no measurement file means.
  if (cell.find_first_of("xX") != std::string::npos) return false;
  return e != b && e == b + cell.size();  // the whole cell: not up to a NUL byte inside it
}

/// Why a drive run's times look like milliseconds (or its positions like kilometres) although each
/// row gap and the run's length passed their limits ("" if nothing does): rows a second or more
/// apart (a tracker at under 1 Hz) and a robot that moved under 1/100 of what its commands ask for.
/// Either alone is possible (a slow logger; a robot pushing a wall); together they are a 1000x
/// stretched time axis, which the replay would simulate for hours.
std::string timeUnitProblem(const Run& run, std::vector<double> row_gaps) {
  // The seed's API speed unit, 2.8 mm/s (Fast's is half: the 100x margin covers every level).
  constexpr double kNominalSpeedUnit = 0.0028;  // [m/s]
  const auto x = run.channels.find("x"), y = run.channels.find("y");
  if (row_gaps.empty() || x == run.channels.end() || y == run.channels.end() || x->second.v.size() < 2 ||
      x->second.v.size() != y->second.v.size())
    return "";
  std::nth_element(row_gaps.begin(), row_gaps.begin() + row_gaps.size() / 2, row_gaps.end());
  const double median_gap = row_gaps[row_gaps.size() / 2];
  if (median_gap < 1.0) return "";
  double asked = 0;  // [m] the forward distance the commands ask for, where the tracks are driven
  for (std::size_t i = 0; i < run.cmd_t.size(); ++i) {
    const double until = i + 1 < run.cmd_t.size() ? run.cmd_t[i + 1] : run.t_end;
    if (run.passiveAt(run.cmd_t[i])) continue;
    asked += std::abs(0.5 * (run.cmd_left[i] + run.cmd_right[i])) * kNominalSpeedUnit *
             std::max(0.0, until - std::max(0.0, run.cmd_t[i]));
  }
  const Series &sx = x->second, &sy = y->second;
  const double moved = std::hypot(sx.v.back() - sx.v.front(), sy.v.back() - sy.v.front());  // [m]
  double path = 0;  // [m] along the samples (noise only lengthens it)
  for (std::size_t i = 1; i < sx.v.size(); ++i) path += std::hypot(sx.v[i] - sx.v[i - 1], sy.v[i] - sy.v[i - 1]);
  if (asked < 0.05 || path * 100 >= asked) return "";
  return "rows " + fmtNumber(median_gap) + " s apart (median) and the robot moved " + fmtNumber(moved) + " m (" +
         fmtNumber(path) + " m along its samples) in " + fmtNumber(run.t_end) +
         " s where its commands ask for about " + fmtNumber(asked) +
         " m: are the times in milliseconds? (t must be in seconds, x and y in metres)";
}

/// Refuses a file with a byte no text CSV holds (a binary or compressed file).
void refuseNonText(const std::string& text, const std::string& file) {
  if (const NonTextByte b = firstNonTextByte(text); b.line > 0) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x", b.value);
    throw DatasetError(file, b.line, 0, "", "not a text CSV file: byte " + std::to_string(b.byte) + " of the line is " +
                                                hex + ", a control character no text holds (a binary or compressed file?)");
  }
}

/// The next line that is neither blank nor a comment ('#'), its CR dropped, in `raw`; false at the end.
bool nextContentLine(std::istream& in, int& line_no, std::string& raw) {
  while (std::getline(in, raw)) {
    ++line_no;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    const std::string t = trim(raw);
    if (!t.empty() && t[0] != '#') return true;
  }
  return false;
}

/// A line's cells, each trimmed; a trailing comma ends in an empty cell.
std::vector<std::string> splitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

struct CsvHeader {
  std::vector<std::string> names;       ///< every column, as written
  std::map<std::string, int> col;       ///< known column -> 0-based index (user '_' columns left out)
  int line = 0;                         ///< the header's line number
  std::vector<std::string> measured;    ///< the columns compared with the model
};

/// The column names of the header line and their indices; unknown and repeated names refused.
CsvHeader readHeader(std::istream& in, int& line_no, const std::string& file) {
  CsvHeader h;
  std::string raw;
  if (nextContentLine(in, line_no, raw)) {
    h.names = splitCells(trim(raw));
    h.line = line_no;
  }
  if (h.names.empty()) throw DatasetError(file, 0, 0, "", "empty file: expected a header line with column names");
  for (std::size_t i = 0; i < h.names.size(); ++i) {
    const std::string& n = h.names[i];
    if (n.empty()) throw DatasetError(file, h.line, i + 1, "", "empty column name in the header");
    if (n[0] == '_') continue;  // user columns (comments, annotations) are ignored
    if (!isKnownColumn(n))
      throw DatasetError(file, h.line, i + 1, n,
                         "unknown column (expected t, cmd_left, cmd_right, x, y, yaw, speed_left, speed_right, "
                         "torque_left, torque_right, pitch, roll, ir0..ir14, ground0..ground3, light0..light7; "
                         "prefix user columns with '_')");
    if (h.col.count(n)) throw DatasetError(file, h.line, i + 1, n, "column appears twice");
    h.col[n] = static_cast<int>(i);
  }
  return h;
}

/// Refuses a header without the columns the run's kind needs, then finds the measured columns and
/// refuses those the kind cannot have.
void checkColumns(CsvHeader& h, const std::string& file, RunKind kind) {
  const bool drive = kind == RunKind::Drive;
  auto need = [&](const std::string& c) {
    if (h.col.count(c)) return;
    std::string have;
    for (const auto& n : h.names) have += (have.empty() ? "" : ", ") + n;
    throw DatasetError(file, h.line, 0, c,
                       "missing column '" + c + "' (a " + (drive ? "drive" : "place") + " run needs " +
                           (drive ? "t, cmd_left, cmd_right" : "x, y, yaw") + "; the header has " + have + ")");
  };
  if (drive) {
    need("t");
    need("cmd_left");
    need("cmd_right");
  } else {
    need("x");
    need("y");
    need("yaw");
  }
  for (const auto& [c, i] : h.col) {
    if (c == "t" || c == "cmd_left" || c == "cmd_right" || c == "force_x" || c == "force_y" || c == "passive") {
      if (!drive && c != "t")
        throw DatasetError(file, h.line, i + 1, c, "input columns are only allowed in drive runs");
      continue;
    }
    if (!drive && (c == "x" || c == "y" || c == "yaw" || c == "z")) continue;
    if (drive && c == "z") throw DatasetError(file, h.line, i + 1, c, "column z is only allowed in place runs");
    if (!drive && !SensorBridge::supports(NoiseModel::group(c)))
      throw DatasetError(file, h.line, i + 1, c,
                         "a place run measures sensors only (ir*, ground*, light*): a robot set down has no " + c);
    h.measured.push_back(c);
  }
  if (h.measured.empty())
    throw DatasetError(file, h.line, 0, "",
                       drive ? "no measured column (x, y, yaw, speed_*, torque_*, pitch, roll, ir*, ground*, light*)"
                             : "no sensor column (ir*, ground*, light*, ...)");
}

/// One data row's cells, read as numbers; every refusal names the row's line and the cell's column.
struct CsvRow {
  const std::string& file;
  const std::map<std::string, int>& col;
  int line_no;
  std::vector<std::string> cells;

  [[noreturn]] void fail(const std::string& c, const std::string& what) const {
    throw DatasetError(file, line_no, col.at(c) + 1, c, what);
  }
  /// False for an empty cell ("not measured").
  bool value(const std::string& c, double& v) const {
    const std::string& cell = cells[col.at(c)];
    if (cell.empty()) return false;
    if (!parseNumber(cell, v)) fail(c, "not a number: '" + cell + "'");
    if (std::isnan(v)) fail(c, "NaN (leave the cell empty for 'not measured')");
    if (!std::isfinite(v)) fail(c, "infinite value");
    return true;
  }
};

/// The time column's history over the rows: order, gaps.
struct TimeTrack {
  double last_t = -std::numeric_limits<double>::infinity();
  int last_t_line = 0;
  double max_gap = 0;  // [s] the longest time between two consecutive rows, and where it ends
  int max_gap_line = 0;
  std::vector<double> row_gaps;  // [s] between consecutive rows (timeUnitProblem)
};

/// The row's time stamp (its index where the file has no t column), refused unless it increases.
double readTime(const CsvRow& r, int row, TimeTrack& tt) {
  double t = row;
  if (!r.col.count("t")) return t;
  if (!r.value("t", t)) r.fail("t", "missing time stamp");
  if (!(t > tt.last_t))
    r.fail("t", "time is not increasing (" + std::to_string(t) + " after " + std::to_string(tt.last_t) + " on line " +
                    std::to_string(tt.last_t_line) + ")");
  if (row > 0) tt.row_gaps.push_back(t - tt.last_t);
  if (row > 0 && t - tt.last_t > tt.max_gap) {
    tt.max_gap = t - tt.last_t;
    tt.max_gap_line = r.line_no;
  }
  tt.last_t = t;
  tt.last_t_line = r.line_no;
  return t;
}

/// A drive row's inputs: the track commands, the pulling force, the passive flag.
void readDriveInputs(const CsvRow& r, double t, Run& run) {
  double l, rt;
  const bool hl = r.value("cmd_left", l), hr = r.value("cmd_right", rt);
  if (hl != hr) r.fail(hl ? "cmd_right" : "cmd_left", "cmd_left and cmd_right must be given together");
  if (hl) {
    for (auto [c, v] : {std::pair<const char*, double>{"cmd_left", l}, {"cmd_right", rt}})
      if (std::abs(v) > 127)
        r.fail(c, "command outside the API range [-127, 127]");
      else if (v != std::round(v))
        r.fail(c, "command " + fmtNumber(v) + " is not a whole number of API units (setSpeed takes integers)");
    run.cmd_t.push_back(t);
    run.cmd_left.push_back(l);
    run.cmd_right.push_back(rt);
  }
  double fx = 0, fy = 0, pv = 0;
  const bool hfx = r.col.count("force_x") && r.value("force_x", fx);
  const bool hfy = r.col.count("force_y") && r.value("force_y", fy);
  for (auto [c, v, has] : {std::tuple<const char*, double, bool>{"force_x", fx, hfx}, {"force_y", fy, hfy}})
    if (has && std::abs(v) > kMaxPullForce)
      r.fail(c, "value " + fmtNumber(v) + " N outside [-" + fmtNumber(kMaxPullForce) + ", " + fmtNumber(kMaxPullForce) +
                    "] N (an s-bot weighs 6.6 N: is it in newtons?)");
  if (hfx || hfy) {
    auto prev = run.forceAt(t);
    run.force_t.push_back(t);
    run.force_x.push_back(hfx ? fx : prev.first);
    run.force_y.push_back(hfy ? fy : prev.second);
  }
  if (r.col.count("passive") && r.value("passive", pv)) {
    if (pv != 0 && pv != 1) r.fail("passive", "expected 0 or 1");
    run.passive_t.push_back(t);
    run.passive.push_back(pv);
  }
}

/// A place row's pose.
void readPlacement(const CsvRow& r, Run& run) {
  Placement p;
  if (!r.value("x", p.pose.x)) r.fail("x", "a placement needs x");
  if (!r.value("y", p.pose.y)) r.fail("y", "a placement needs y");
  if (!r.value("yaw", p.pose.yaw)) r.fail("yaw", "a placement needs yaw");
  double z;
  if (r.col.count("z") && r.value("z", z)) p.z = z;
  run.placements.push_back(p);
}

/// A row's measured values, each checked against its channel's range.
void readMeasured(const CsvRow& r, const std::vector<std::string>& measured, double t, int row, Run& run) {
  const bool drive = run.kind == RunKind::Drive;
  for (const auto& c : measured) {
    double v;
    if (!r.value(c, v)) continue;
    if (drive && t < 0)
      r.fail(c, "measured at t = " + fmtNumber(t) +
                    " s, before the replay's start at t = 0 (shift the run's times so that it starts at 0)");
    const std::string range = channelRangeProblem(c, v);
    if (!range.empty()) r.fail(c, range);
    Series& s = run.channels[c];
    s.t.push_back(drive ? t : row);
    s.v.push_back(v);
    s.line.push_back(r.line_no);
  }
}

/// The checks on the whole run: rows, commands, its length and gaps, its time unit, a measurement.
void checkRun(const CsvHeader& h, const TimeTrack& tt, int rows, const std::string& file, Run& run) {
  const bool drive = run.kind == RunKind::Drive;
  if (rows == 0) throw DatasetError(file, h.line, 0, "", "no data rows");
  if (drive && run.cmd_t.empty()) throw DatasetError(file, h.line, 0, "cmd_left", "no command in any row");
  if (drive && run.t_end > kMaxRunDuration)
    throw DatasetError(file, tt.last_t_line, h.col.at("t") + 1, "t",
                       "the run ends at t = " + fmtNumber(run.t_end) + " s; runs longer than " +
                           fmtNumber(kMaxRunDuration) + " s are refused (the replay simulates every step): are the times in seconds?");
  if (drive && tt.max_gap > kMaxRowGap)
    throw DatasetError(file, tt.max_gap_line, h.col.at("t") + 1, "t",
                       "a gap of " + fmtNumber(tt.max_gap) + " s since the previous row; gaps over " + fmtNumber(kMaxRowGap) +
                           " s are refused (the replay would simulate them blind): are the times in seconds?");
  if (drive)
    if (const std::string problem = timeUnitProblem(run, tt.row_gaps); !problem.empty())
      throw DatasetError(file, tt.last_t_line, h.col.at("t") + 1, "t", problem);
  if (run.sampleCount() == 0)
    throw DatasetError(file, h.line, 0, "", "no measured value in any row: nothing to compare the model with");
}

}  // namespace

void parseRunCsv(const std::string& text, const std::string& file, Run& run) {
  // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column's name.
  const bool bom = text.rfind("\xEF\xBB\xBF", 0) == 0;
  refuseNonText(text, file);
  std::istringstream in(bom ? text.substr(3) : text);
  int line_no = 0;
  CsvHeader header = readHeader(in, line_no, file);
  checkColumns(header, file, run.kind);

  TimeTrack tt;
  int row = 0;
  for (std::string raw; nextContentLine(in, line_no, raw);) {
    const CsvRow r{file, header.col, line_no, splitCells(raw)};
    if (r.cells.size() != header.names.size())
      throw DatasetError(file, line_no, 0, "",
                         "expected " + std::to_string(header.names.size()) + " cells, found " +
                             std::to_string(r.cells.size()));
    const double t = readTime(r, row, tt);
    if (run.kind == RunKind::Drive) readDriveInputs(r, t, run);
    else readPlacement(r, run);
    readMeasured(r, header.measured, t, row, run);
    run.t_end = t;
    ++row;
  }
  checkRun(header, tt, row, file, run);
  for (const auto& c : header.measured)
    if (!run.channels.count(c)) run.channels[c] = Series{};  // declared but never measured: kept empty
}

}  // namespace sbot::calib
