#include "reference_tables.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/errors.h"
#include "experiments.h"
#include "yaml_file.h"

namespace sbot {
namespace validation {

bool ReferenceTable::severalLevels() const {
  for (const ReferenceCell& c : cells)
    if (c.level != cells.front().level) return true;
  return false;
}

bool ReferenceTable::severalVariants() const {
  for (const ReferenceCell& c : cells)
    if (c.variant != cells.front().variant) return true;
  return false;
}

bool ReferenceTable::severalFloors() const {
  for (const ReferenceCell& c : cells)
    if (c.track_mu != cells.front().track_mu) return true;
  return false;
}

bool ReferenceTable::otherSpeeds() const {
  for (const ReferenceCell& c : cells)
    if (c.speed_units != kSlowUnits) return true;
  return false;
}

std::string NumberFormat::text(double v) const {
  std::ostringstream s;
  if (decimals >= 0) s << std::fixed << std::setprecision(decimals) << v * scale;
  else s << std::setprecision(6) << v * scale;  // no decimals given: the value as written, not rounded
  return s.str() + (unit.empty() ? "" : " " + unit);
}

std::string ReferenceTable::paramText(const ReferenceCell& c) const { return param.text(c.param); }

std::string ReferenceTable::key(const ReferenceCell& c) const {
  return id + " " + paramText(c) + (c.variant.empty() ? "" : " " + c.variant) + (severalLevels() ? " " + c.level : "");
}

const ReferenceGroup* ReferenceTables::findGroup(const std::string& name) const {
  for (const ReferenceGroup& g : groups)
    if (g.name == name) return &g;
  return nullptr;
}

namespace {

/// "pass|stuck" as the report shows it: "pass or stuck" (a '|' would split the Markdown table's cell).
std::string alternatives(const std::string& accepts) {
  std::string out;
  for (char ch : accepts) out += ch == '|' ? std::string(" or ") : std::string(1, ch);
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

/// Reads the fields of one YAML map, refusing any it does not know (a misspelt field would
/// otherwise be silently ignored).
class Fields {
 public:
  Fields(const YAML::Node& node, std::string where, const std::function<void(const std::string&)>& fail)
      : node_(node), where_(std::move(where)), fail_(fail) {
    if (!node.IsMap()) fail_(where_ + ": expected a map of fields");
  }
  bool has(const std::string& k) {
    known_.insert(k);
    return node_[k].IsDefined() && !node_[k].IsNull();
  }
  std::string text(const std::string& k, bool required, const std::string& fallback = "", const char* what = "a text") {
    if (!has(k)) {
      if (required) fail_(where_ + ": missing field '" + k + "'");
      return fallback;
    }
    if (!node_[k].IsScalar()) fail_(where_ + ": field '" + k + "' must be " + what + ", found a " +
                                    (node_[k].IsSequence() ? "list" : "map"));
    const std::string t = node_[k].as<std::string>();
    if (required && t.empty()) fail_(where_ + ": field '" + k + "' is empty");
    return t;
  }
  /// A number; an empty text is not one (read as the field's absence, `param: ""` would run a
  /// 0 m gap).
  double number(const std::string& k, bool required, double fallback = 0) {
    if (!has(k)) return required ? (text(k, true), 0.0) : fallback;
    const std::string t = text(k, false, "", "a number");
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !std::isfinite(v))
      fail_(where_ + ": field '" + k + "' expects a finite number, found '" + t + "'");
    return v;
  }
  /// The treels' Coulomb coefficient on a table's terrain: a number in (0, 100], or `lab_floor`
  /// (kLabFloorTrackMu); fallback when the field is absent (0: the experiment's own).
  double trackMu(const std::string& k, double fallback) {
    if (!has(k)) return fallback;
    const std::string t = text(k, false);
    if (t == kLabFloorName) return kLabFloorTrackMu;
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !(v >= 1e-6 && v <= 100))  // --track-mu's range
      fail_(where_ + ": field '" + k + "' expects a friction coefficient in [1e-6, 100] or lab_floor, found '" + t + "'");
    return v;
  }
  bool flag(const std::string& k) {
    const std::string t = text(k, false, "false");
    if (t != "true" && t != "false") fail_(where_ + ": field '" + k + "' expects true or false, found '" + t + "'");
    return t == "true";
  }
  std::vector<std::string> list(const std::string& k) {
    std::vector<std::string> out;
    if (!has(k)) return out;
    if (!node_[k].IsSequence()) fail_(where_ + ": field '" + k + "' must be a list");
    for (const auto& x : node_[k]) {
      if (!x.IsScalar()) fail_(where_ + ": field '" + k + "' must be a list of texts");
      out.push_back(x.as<std::string>());
    }
    return out;
  }
  YAML::Node node(const std::string& k) {
    known_.insert(k);
    return node_[k];
  }
  /// Call after reading: refuses fields nobody asked for.
  void noOthers() {
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>("");
      if (!known_.count(k)) fail_(where_ + ": unknown field '" + k + "' (fields: " + nameList(known_) + ")");
    }
  }

 private:
  const YAML::Node node_;
  const std::string where_;
  const std::function<void(const std::string&)>& fail_;
  std::set<std::string> known_;
};

/// Why a table whose parameters are shown as `f` (value x scale, then f.unit) misnames the
/// quantity of `kind` (its parameter in m, deg or rad: the text after the last ", " of its unit);
/// empty when it does not. A unit this list does not know is the file's own and is not checked.
std::string unitMismatch(const ExperimentKind& kind, const NumberFormat& f) {
  struct Known { const char* unit; const char* of; double scale; };  // f.unit = value x scale, value in `of`
  static const Known known[] = {{"m", "m", 1},        {"cm", "m", 100},      {"mm", "m", 1000},
                                {"rad", "rad", 1},    {"mrad", "rad", 1000}, {"deg", "deg", 1},
                                {"deg", "rad", 180 / M_PI}, {"°", "deg", 1},  {"°", "rad", 180 / M_PI}};
  const std::size_t comma = kind.unit.rfind(", ");
  const std::string of = comma == std::string::npos ? kind.unit : kind.unit.substr(comma + 2);
  const std::string quantity = comma == std::string::npos ? "parameter" : kind.unit.substr(0, comma);
  bool named = false;
  for (const Known& k : known) {
    if (f.unit != k.unit) continue;
    named = true;
    if (of == k.of && std::fabs(f.scale - k.scale) <= 1e-4 * k.scale) return "";
  }
  if (!named) return "";
  std::ostringstream m;
  m << kind.name << "'s parameter is a " << quantity << " in " << of << ", which the table's param format shows as x"
    << f.scale << " " << f.unit << ": give the cells of another quantity a table of their own, or a param format of their unit (";
  bool first = true;
  for (const Known& k : known)
    if (of == k.of) m << (first ? "" : ", ") << "unit " << k.unit << " scale " << k.scale, first = false;
  m << ")";
  return m.str();
}

/// {header, unit, scale, decimals}; without `default_header` the header is required.
NumberFormat readFormat(const YAML::Node& node, const std::string& where, const std::string& default_header,
                        const std::function<void(const std::string&)>& fail) {
  Fields f(node, where, fail);
  NumberFormat n;
  n.header = f.text("header", default_header.empty(), default_header);
  n.unit = f.text("unit", false);
  n.scale = f.number("scale", false, 1);
  if (!(n.scale > 0 && n.scale <= 1e6))
    fail(where + ": scale expects a number in (0, 1e6], found '" + f.text("scale", false) + "'");
  if (f.has("decimals")) {  // absent: -1, the value as written (not a value a file may give)
    const double decimals = f.number("decimals", true);
    if (decimals != std::round(decimals) || decimals < 0 || decimals > 6)
      fail(where + ": decimals expects a whole number from 0 to 6, found '" + f.text("decimals", false) + "'");
    n.decimals = static_cast<int>(decimals);
  }
  f.noOthers();
  return n;
}

ReferenceTable readTable(const YAML::Node& node, const std::string& where, const ReferenceTables& file,
                         const ReferenceVocabulary& vocabulary, const std::function<void(const std::string&)>& fail) {
  ReferenceTable t;
  Fields f(node, where, fail);
  t.id = f.text("id", true);
  const std::string at = "table '" + t.id + "'";
  if (t.id.find_first_of(", \n") != std::string::npos)
    fail(at + ": an id may not hold a comma, space or line break (--only lists ids separated by commas)");
  if (contains(vocabulary.sections, t.id))
    fail(at + ": '" + t.id + "' is the name of a built-in section (" + nameList(vocabulary.sections) +
         "); give the table another id");
  t.title = f.text("title", true);
  t.about = f.text("about", false);
  t.group = f.text("group", false);
  if (!t.group.empty() && !file.findGroup(t.group)) fail(at + ": group '" + t.group + "' is not defined under groups");
  const std::string experiment = f.text("experiment", false);
  const std::string level = f.text("level", false);
  const std::string variant = f.text("variant", false);
  // Texts that land in a Markdown table cell: a '|' or a line break would split the row.
  const auto oneCell = [&](const std::string& where, const std::string& field, const std::string& text) {
    if (text.find_first_of("|\n") != std::string::npos)
      fail(where + ": " + field + " '" + text + "' holds a '|' or a line break, which would split the report's table");
  };
  const double speed_units = f.number("speed_units", false, kSlowUnits);
  const double track_mu = f.trackMu("track_mu", 0);
  t.variant_header = f.text("variant_header", false);
  if (f.has("param")) t.param = readFormat(f.node("param"), at + ", param", t.param.header, fail);
  t.references = f.list("references");
  if (t.references.empty()) fail(at + ": 'references' must name at least one column (the first is compared)");
  for (std::size_t i = 0; i < t.references.size(); ++i)
    for (std::size_t k = 0; k < i; ++k)
      if (t.references[i] == t.references[k]) fail(at + ": 'references' names the column '" + t.references[i] + "' twice");
  for (const std::string& column : t.references)  // a cell's own fields cannot also be its columns
    for (const char* field : {"param", "experiment", "level", "variant", "speed_units", "track_mu"})
      if (column == field) fail(at + ": the reference column '" + column + "' has the name of a cell's field; rename it");
  t.ours_header = f.text("ours_header", false, t.ours_header);
  if (f.has("companion")) {
    Fields c(f.node("companion"), at + ", companion", fail);
    t.companion = c.text("experiment", true);
    t.companion_header = c.text("header", false, "ours, " + t.companion);
    c.noOthers();
    if (!findExperimentKind(t.companion) || findExperimentKind(t.companion)->labels.empty())
      fail(at + ", companion: experiment '" + t.companion + "' is not one of " + experimentKindNames(true));
  }
  if (f.has("value")) t.value = readFormat(f.node("value"), at + ", value", "", fail);
  t.after = f.list("after");
  for (const std::string& p : t.after)
    if (!contains(vocabulary.paragraphs, p))
      fail(at + ": 'after' names '" + p + "', not a built-in paragraph (" + nameList(vocabulary.paragraphs) + ")");
  if (!f.has("cells") || !f.node("cells").IsSequence() || f.node("cells").size() == 0)
    fail(at + ": 'cells' must be a non-empty list");
  std::set<std::string> keys;
  int index = 0;
  for (const auto& cn : f.node("cells")) {
    const std::string cat = at + ", cell " + std::to_string(index++);
    Fields cf(cn, cat, fail);
    ReferenceCell c;
    c.experiment = cf.text("experiment", experiment.empty(), experiment);
    c.level = cf.text("level", level.empty(), level);
    c.variant = cf.text("variant", false, variant);
    oneCell(cat, "variant", c.variant);
    c.param = cf.number("param", true);
    const double units = cf.number("speed_units", false, speed_units);
    if (units != std::round(units) || units < 1 || units > 70)
      fail(cat + ": speed_units expects a whole number of setSpeed units in [1, 70] (0.28 cm/s each), found " +
           cf.text("speed_units", false, std::to_string(static_cast<int>(units))));
    c.speed_units = static_cast<int>(units);
    c.track_mu = cf.trackMu("track_mu", track_mu);
    const ExperimentKind* kind = findExperimentKind(c.experiment);
    if (!kind || kind->labels.empty())
      fail(cat + ": experiment '" + c.experiment + "' is not one of " + experimentKindNames(true));
    // The companion runs on the same parameter: it must be of the same quantity and in its range.
    for (const ExperimentKind* k : {kind, t.companion.empty() ? nullptr : findExperimentKind(t.companion)}) {
      if (!k) continue;
      if (k->unit != kind->unit)
        fail(cat + ": the companion " + k->name + " takes a " + k->unit + ", the cell's " + c.experiment + " a " +
             kind->unit + ": a companion runs on the cell's own parameter");
      if (c.param < k->min || c.param > k->max) {
        std::ostringstream m;
        m << cat << ": param " << c.param << " is outside " << k->name << "'s range [" << k->min << ", " << k->max
          << "] (" << k->unit << ")";
        fail(m.str());
      }
    }
    const std::string misnamed = unitMismatch(*kind, t.param);
    if (!misnamed.empty()) fail(cat + ": " + misnamed);
    if (!contains(vocabulary.levels, c.level)) fail(cat + ": level '" + c.level + "' is not one of " + nameList(vocabulary.levels));
    for (std::size_t r = 0; r < t.references.size(); ++r) {
      const std::string& column = t.references[r];
      if (!cf.has(column)) fail(cat + ": missing the reference '" + column + "'");
      const YAML::Node v = cf.node(column);
      ReferenceValue value;
      if (v.IsScalar()) {
        value.accepts = v.as<std::string>();
        value.text = r == 0 ? alternatives(value.accepts) : value.accepts;
      } else {
        Fields vf(v, cat + ", " + column, fail);
        value.accepts = vf.text("accepts", true);
        value.text = vf.text("text", false, value.accepts);
        vf.noOthers();
      }
      if (r == 0) {  // the compared column: every alternative must be a label the experiment yields
        if (value.accepts.empty() || value.accepts.front() == '|' || value.accepts.back() == '|' ||
            value.accepts.find("||") != std::string::npos)
          fail(cat + ": reference '" + column + "' accepts '" + value.accepts +
               "': every alternative between '|' must be a label (an empty one matches nothing)");
        std::stringstream ss(value.accepts);
        for (std::string label; std::getline(ss, label, '|');)
          if (!contains(kind->labels, label))
            fail(cat + ": reference '" + column + "' accepts '" + label + "', which " + c.experiment +
                 " never yields (its labels: " + nameList(kind->labels) + ")");
      } else {
        value.accepts.clear();
      }
      if (value.text.empty()) fail(cat + ": reference '" + column + "' is empty");
      oneCell(cat, "reference '" + column + "' shows", value.text);
      c.references.push_back(value);
    }
    cf.noOthers();
    t.cells.push_back(c);
  }
  std::map<std::string, const ReferenceCell*> by_key;
  for (const ReferenceCell& c : t.cells) {
    const auto [it, fresh] = by_key.emplace(t.key(c), &c);
    if (fresh) continue;
    if (it->second->param != c.param)  // distinct cells that the parameter's format shows alike
      fail(at + ": the cells of param " + std::to_string(it->second->param) + " and " + std::to_string(c.param) +
           " are both shown as '" + t.paramText(c) + "': give param: {decimals: ...} more decimals (or none)");
    fail(at + ": two cells are both '" + t.key(c) + "'");
  }
  f.noOthers();
  return t;
}

}  // namespace

ReferenceTables ReferenceTables::load(const std::string& path, const ReferenceVocabulary& vocabulary, const std::string& shown_as) {
  const std::function<void(const std::string&)> fail = [&](const std::string& why) {
    throw std::runtime_error("reference tables " + path + ": " + why);
  };
  const YAML::Node root = loadYamlFile("reference tables", path);
  ReferenceTables file;
  file.source = shown_as.empty() ? path : shown_as;
  if (!root.IsMap()) fail("expected a map with 'groups' and 'report'");
  Fields top(root, "the file", fail);
  if (top.has("groups")) {
    if (!top.node("groups").IsSequence()) fail("'groups' must be a list");
    for (const auto& gn : top.node("groups")) {
      Fields g(gn, "a group", fail);
      ReferenceGroup group{g.text("name", true), g.text("title", true), g.flag("required")};
      g.noOthers();
      if (file.findGroup(group.name)) fail("group '" + group.name + "' is defined twice");
      file.groups.push_back(group);
    }
  }
  if (!top.has("report") || !top.node("report").IsSequence() || top.node("report").size() == 0)
    fail("'report' must be a non-empty list of sections and tables");
  top.noOthers();
  std::set<std::string> names;
  int index = 0;
  for (const auto& en : root["report"]) {
    const std::string where = "report entry " + std::to_string(index++);
    Fields e(en, where, fail);
    ReportEntry entry;
    if (e.has("section")) {
      entry.section = e.text("section", true);
      if (!contains(vocabulary.sections, entry.section))
        fail(where + ": section '" + entry.section + "' is not a built-in section (" + nameList(vocabulary.sections) + ")");
      for (const auto& [section, group] : vocabulary.section_groups)
        if (section == entry.section && !file.findGroup(group))
          fail(where + ": section '" + section + "' tallies its cells in group '" + group + "', which 'groups' does not define");
    } else if (e.has("table")) {
      entry.table = readTable(e.node("table"), where, file, vocabulary, fail);
    } else {
      fail(where + ": expected 'section: NAME' or 'table: {...}'");
    }
    e.noOthers();
    if (!names.insert(entry.name()).second) fail(where + ": '" + entry.name() + "' appears twice in the report");
    file.report.push_back(entry);
  }
  // A required group that nothing tallies would pass with no cell checked.
  for (const ReferenceGroup& g : file.groups) {
    if (!g.required) continue;
    bool tallied = false;
    for (const ReportEntry& e : file.report) {
      tallied |= e.section.empty() && e.table.group == g.name;
      for (const auto& [section, group] : vocabulary.section_groups) tallied |= e.section == section && group == g.name;
    }
    if (!tallied) fail("group '" + g.name + "' is required, but no table or section counts its cells in it");
  }
  return file;
}

}  // namespace validation
}  // namespace sbot
