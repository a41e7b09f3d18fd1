// The dataset: dataset.yaml (its world, noise and runs sections), the types over it, and writing it
// back. The runs' CSV files are read by dataset_csv.cpp.
#include "calibration/dataset.h"

#include <sys/stat.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/output_files.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/world.h"  // positionProblem
#include "sbot_sim/core/yaml_checks.h"

#include "calibration/dataset_internal.h"

namespace sbot::calib {
using detail::channelRangeProblem;
using detail::fmtNumber;

namespace {

/// A column name as a message shows it: at most 40 characters (a header that is one 10 kB cell).
std::string shownName(const std::string& name) { return name.size() <= 40 ? name : name.substr(0, 40) + "..."; }

std::string location(const std::string& file, int line, int column, const std::string& column_name) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  if (column > 0) s += ":" + std::to_string(column);
  if (!column_name.empty()) s += " (column '" + shownName(column_name) + "')";
  return s;
}


[[noreturn]] void fail(const std::string& file, const YAML::Node& n, const std::string& field, const std::string& what) {
  const YAML::Mark m = n.IsDefined() ? n.Mark() : YAML::Mark::null_mark();
  const int line = m.line >= 0 ? m.line + 1 : 0, col = m.column >= 0 ? m.column + 1 : 0;
  throw DatasetError(file, line, col, "", (field.empty() ? "" : "field '" + field + "': ") + what);
}

bool isDirectory(const std::string& p);

std::string readFile(const std::string& path, const std::string& referrer, const YAML::Node& where) {
  // Not a regular file (a folder, /dev/zero, a FIFO), too large, or unreadable: sbot/core/input_file.h.
  if (const std::string problem = inputFileProblem(path); !problem.empty()) {
    if (referrer.empty()) throw DatasetError(path, 0, 0, "", problem);
    fail(referrer, where, "", "'" + path + "' " + problem);
  }
  try {
    return readInputFile(path);
  } catch (const ConfigError& e) {
    throw DatasetError(path, 0, 0, "", e.what());
  }
}

bool isDirectory(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}


double number(const YAML::Node& n, const std::string& file, const std::string& field) {
  double v;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(file, n, field, "expected a number, found '" + (n.IsScalar() ? n.as<std::string>() : "<not a scalar>") + "'");
  }
  if (!std::isfinite(v)) fail(file, n, field, "must be a finite number");
  return v;
}

Vec3 vec3(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsSequence() || n.size() != 3) fail(file, n, field, "expected [x, y, z]");
  return Vec3(number(n[0], file, field), number(n[1], file, field), number(n[2], file, field));
}

void allowOnly(const YAML::Node& n, const std::string& file, const std::string& field,
               const std::set<std::string>& keys) {
  if (const YAML::Node k = unknownKey(n, keys))
    fail(file, k, field.empty() ? k.Scalar() : field + "." + k.Scalar(), unknownFieldMessage(keys));
}

std::string defaultGroup(const std::string& name) {
  const auto u = name.find('_');
  return u == std::string::npos ? name : name.substr(0, u);
}

/// [s] the latest start of a run in its session (Run::start_time): 10 days.
constexpr double kMaxStartTime = 864000;

}  // namespace

DatasetError::DatasetError(const std::string& file, int line, int column, const std::string& column_name,
                           const std::string& what)
    : ConfigError(file, column_name, what), line_(line), column_(column), column_name_(column_name),
      message_(location(file, line, column, column_name) + ": " + what) {}

NoiseModel::NoiseModel() {
  table = {{"position", {0.003, 0}},  // overhead tracker, sigma 3 mm
           {"yaw", {0.01745, 0}},     // 1 degree
           {"speed", {1.0, 0}},       // API speed units (encoders)
           {"torque", {2.0, 0}},      // API torque units
           {"tilt", {0.0087, 0}},     // 0.5 degree (inclinometer)
           {"ir", {2.0, 0.1}},        // API units; 10 % proportional (Table 2.8)
           {"ground", {1.0, 0.1}},
           {"light", {2.0, 0.05}}};
}

std::string NoiseModel::group(const std::string& c) {
  if (c == "x" || c == "y") return "position";
  if (c == "yaw") return "yaw";
  if (c == "speed_left" || c == "speed_right") return "speed";
  if (c == "torque_left" || c == "torque_right") return "torque";
  if (c == "pitch" || c == "roll") return "tilt";
  if (c.rfind("ground", 0) == 0) return "ground";
  if (c.rfind("ir", 0) == 0) return "ir";
  if (c.rfind("light", 0) == 0) return "light";
  return c;
}

double NoiseModel::sigma(const std::string& channel, double value) const {
  auto it = table.find(group(channel));
  if (it == table.end()) return 1.0;
  return std::max(1e-12, it->second.first + it->second.second * std::abs(value));
}

std::vector<double> unwrapped(const Series& s) {
  std::vector<double> out(s.v.size());
  for (std::size_t i = 0; i < s.v.size(); ++i) {
    if (i == 0) {
      out[i] = s.v[i];
      continue;
    }
    const double d = s.v[i] - s.v[i - 1];
    out[i] = out[i - 1] + std::atan2(std::sin(d), std::cos(d));
  }
  return out;
}

std::pair<double, double> Run::commandAt(double t) const {
  if (cmd_t.empty() || t < cmd_t.front()) return {0, 0};
  const auto it = std::upper_bound(cmd_t.begin(), cmd_t.end(), t + 1e-9);
  const std::size_t i = static_cast<std::size_t>(it - cmd_t.begin()) - 1;
  return {cmd_left[i], cmd_right[i]};
}

namespace {
std::size_t heldIndex(const std::vector<double>& ts, double t) {
  const auto it = std::upper_bound(ts.begin(), ts.end(), t + 1e-9);
  return static_cast<std::size_t>(it - ts.begin()) - 1;
}
}  // namespace

std::pair<double, double> Run::forceAt(double t) const {
  if (force_t.empty() || t < force_t.front()) return {0, 0};
  const std::size_t i = heldIndex(force_t, t);
  return {force_x[i], force_y[i]};
}

bool Run::passiveAt(double t) const {
  if (passive_t.empty() || t < passive_t.front()) return false;
  return passive[heldIndex(passive_t, t)] != 0;
}

std::size_t Run::sampleCount() const {
  std::size_t n = 0;
  for (const auto& [k, s] : channels) n += s.v.size();
  return n;
}

std::set<std::string> Dataset::channels() const {
  std::set<std::string> out;
  for (const auto& r : runs)
    for (const auto& [k, s] : r.channels)
      if (!s.v.empty()) out.insert(k);
  return out;
}

bool Dataset::hasChannelGroup(const std::string& g) const {
  for (const auto& c : channels()) {
    const std::string cg = NoiseModel::group(c);
    if (cg == g || (g == "pose" && (cg == "position" || cg == "yaw"))) return true;
  }
  return false;
}

std::set<std::string> Dataset::obstacleSurfaces() const {
  std::set<std::string> out;
  for (const auto& b : world.terrain.boxes) out.insert(b.surface);
  return out;
}

std::size_t Dataset::sampleCount() const {
  std::size_t n = 0;
  for (const auto& r : runs) n += r.sampleCount();
  return n;
}

Dataset onlyRuns(const Dataset& ds, const std::set<std::string>& keep) {
  Dataset kept = ds;
  kept.runs.clear();
  for (const Run& r : ds.runs)
    if (keep.count(r.name)) kept.runs.push_back(r);
  return kept;
}

Dataset withoutRuns(const Dataset& ds, const std::set<std::string>& skip) {
  std::set<std::string> missing = skip, keep;
  std::vector<std::string> known;
  for (const Run& r : ds.runs) {
    missing.erase(r.name);
    known.push_back(r.name);
    if (!skip.count(r.name)) keep.insert(r.name);
  }
  if (!missing.empty())
    throw std::invalid_argument("dataset " + ds.name + " has no run named " + nameList(missing) + " (its runs: " +
                                nameList(known) + ")");
  Dataset kept = onlyRuns(ds, keep);
  if (kept.runs.empty())
    throw std::invalid_argument("leaving out " + std::to_string(skip.size()) + " run(s) leaves dataset " + ds.name +
                                " with no run");
  return kept;
}

namespace {

/// The parsed top-level mapping of dataset.yaml, refused unless it is valid YAML and a mapping.
YAML::Node readRoot(const std::string& f) {
  const std::string text = readFile(f, "", YAML::Node());
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw DatasetError(f, e.mark.line + 1, e.mark.column + 1, "", "not valid YAML: " + e.msg);
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty()) throw DatasetError(f, 0, 0, "", problem);
  if (!root.IsMap()) throw DatasetError(f, 1, 1, "", "expected a mapping at the top level");
  return root;
}

/// format, name, description, robot and the alignment fields.
void loadHeaderFields(const YAML::Node& root, const std::string& f, Dataset& ds) {
  allowOnly(root, f, "", {"format", "name", "description", "robot", "world", "noise", "runs", "surfaces",
                          "align_initial_pose", "align_segment", "generator"});
  if (!root["format"]) fail(f, root, "format", "missing (expected 'format: sbot-dataset/1')");
  if (root["format"].as<std::string>() != "sbot-dataset/1")
    fail(f, root["format"], "format", "unsupported format '" + root["format"].as<std::string>() + "' (expected sbot-dataset/1)");
  ds.name = root["name"] ? root["name"].as<std::string>() : ds.dir.substr(ds.dir.find_last_of('/') + 1);
  if (root["description"]) ds.description = root["description"].as<std::string>();
  if (root["robot"]) {
    ds.robot = root["robot"].as<std::string>();
    const auto& levels = modelLevels();
    if (std::find(levels.begin(), levels.end(), ds.robot) == levels.end())
      fail(f, root["robot"], "robot", "unknown model level '" + ds.robot + "' (levels: fast, simple, basic, medium, detailed)");
  }
  if (root["align_initial_pose"]) ds.align_initial_pose = root["align_initial_pose"].as<bool>();
  if (root["align_segment"]) {
    ds.align_segment = number(root["align_segment"], f, "align_segment");
    if (!(ds.align_segment == 0 || ds.align_segment >= kMinAlignSegment))
      fail(f, root["align_segment"], "align_segment",
           "must be 0 (align the start only) or at least " + fmtNumber(kMinAlignSegment) +
               " s: shorter segments re-anchor the model so often that they hide its error");
  }
}

/// world.obstacles: boxes on the known surfaces.
void loadObstacles(const YAML::Node& obs, const std::string& f, const std::set<std::string>& surfaces, Dataset& ds) {
  if (!obs.IsSequence()) fail(f, obs, "world.obstacles", "expected a list");
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const std::string field = "world.obstacles[" + std::to_string(i) + "]";
    const YAML::Node o = obs[i];
    if (!o.IsMap()) fail(f, o, field, "expected a mapping {name, center, size, yaw, surface}");
    allowOnly(o, f, field, {"name", "center", "size", "yaw", "pitch", "surface"});
    BoxObstacle b;
    b.name = o["name"] ? o["name"].as<std::string>() : "obstacle_" + std::to_string(i);
    if (!o["center"]) fail(f, o, field + ".center", "missing");
    if (!o["size"]) fail(f, o, field + ".size", "missing");
    b.center = vec3(o["center"], f, field + ".center");
    b.size = vec3(o["size"], f, field + ".size");
    if ((b.size.array() <= 0).any()) fail(f, o["size"], field + ".size", "every edge must be > 0");
    b.yaw = o["yaw"] ? number(o["yaw"], f, field + ".yaw") : 0.0;
    b.pitch = o["pitch"] ? number(o["pitch"], f, field + ".pitch") : 0.0;
    b.surface = o["surface"] ? o["surface"].as<std::string>() : "wall";
    if (!surfaces.count(b.surface)) {
      fail(f, o["surface"] ? o["surface"] : o, field + ".surface",
           "unknown surface '" + b.surface + "' (known: " + nameList(surfaces) + "; declare others under 'surfaces:')");
    }
    ds.world.terrain.boxes.push_back(b);
  }
}

/// world.lamps: positions in the world, intensities >= 0.
void loadLamps(const YAML::Node& lamps, const std::string& f, Dataset& ds) {
  if (!lamps.IsSequence()) fail(f, lamps, "world.lamps", "expected a list");
  for (std::size_t i = 0; i < lamps.size(); ++i) {
    const std::string field = "world.lamps[" + std::to_string(i) + "]";
    allowOnly(lamps[i], f, field, {"name", "position", "intensity"});
    Lamp l;
    if (!lamps[i]["position"]) fail(f, lamps[i], field + ".position", "missing");
    l.position = vec3(lamps[i]["position"], f, field + ".position");
    const std::string where = positionProblem(l.position);
    if (!where.empty()) fail(f, lamps[i]["position"], field + ".position", where);
    l.intensity = lamps[i]["intensity"] ? number(lamps[i]["intensity"], f, field + ".intensity") : 0.0;
    if (l.intensity < 0) fail(f, lamps[i]["intensity"], field + ".intensity", "must be >= 0");
    ds.lamps.push_back(l);
  }
}

/// World: scenario syntax for step/contact/terrain (parsed by the core's scenario parser), plus
/// obstacles, lamps and ambient light.
void loadWorld(const YAML::Node& w, const std::string& f, const std::set<std::string>& surfaces, Dataset& ds) {
  if (!w.IsMap()) fail(f, w, "world", "expected a mapping");
  allowOnly(w, f, "world", {"step", "gravity", "solver", "solver_iterations", "solver_sor", "sleep_at_rest", "contact",
                            "terrain", "obstacles", "lamps", "ambient_light"});
  YAML::Node scenario;
  YAML::Node sw;
  sw["sleep_at_rest"] = false;  // the workbench's default (Dataset::world)
  for (const char* k : {"step", "gravity", "solver", "solver_iterations", "solver_sor", "sleep_at_rest", "contact",
                        "terrain"})
    if (w[k]) sw[k] = w[k];
  scenario["world"] = sw;
  try {
    ds.world = parseScenario(YAML::Dump(scenario), f).world;
  } catch (const ConfigError& e) {
    // The scenario parser's message starts with the file we gave it: keep one copy of it.
    std::string what = e.what();
    if (what.rfind(f + ": ", 0) == 0) what = what.substr(f.size() + 2);
    throw DatasetError(f, w.Mark().line + 1, w.Mark().column + 1, "", what);
  }
  ds.world_sets_step = static_cast<bool>(w["step"]);
  ds.world_sets_gravity = static_cast<bool>(w["gravity"]);
  if (ds.world_sets_gravity) {
    const std::string problem = gravityProblem(loadLevel(ds.robot), ds.world.gravity);
    if (!problem.empty()) fail(f, w["gravity"], "world.gravity", problem);
  }
  for (const auto& b : ds.world.terrain.boxes)
    if (!surfaces.count(b.surface)) fail(f, w["terrain"], "world.terrain.boxes", "unknown surface '" + b.surface + "'");
  if (const YAML::Node obs = w["obstacles"]) loadObstacles(obs, f, surfaces, ds);
  if (const YAML::Node lamps = w["lamps"]) loadLamps(lamps, f, ds);
  if (w["ambient_light"]) ds.ambient_light = number(w["ambient_light"], f, "world.ambient_light");
}

/// noise: group: sigma or group: {abs, rel}.
void loadNoise(const YAML::Node& n, const std::string& f, Dataset& ds) {
  if (!n.IsMap()) fail(f, n, "noise", "expected a mapping group: sigma or group: {abs, rel}");
  for (const auto& kv : n) {
    const std::string g = kv.first.as<std::string>();
    if (!ds.noise.table.count(g))
      fail(f, kv.first, "noise." + g, "unknown channel group (position, yaw, speed, torque, tilt, ir, ground, light)");
    if (kv.second.IsMap()) {
      allowOnly(kv.second, f, "noise." + g, {"abs", "rel"});
      ds.noise.table[g] = {kv.second["abs"] ? number(kv.second["abs"], f, "noise." + g + ".abs") : 0.0,
                           kv.second["rel"] ? number(kv.second["rel"], f, "noise." + g + ".rel") : 0.0};
    } else {
      ds.noise.table[g] = {number(kv.second, f, "noise." + g), 0.0};
    }
    const auto& v = ds.noise.table[g];
    if (v.first < 0 || v.second < 0 || v.first + v.second <= 0)
      fail(f, kv.second, "noise." + g, "noise scales must be >= 0 and not both zero");
  }
}

/// A run's file, name (a plain file name, unique in the dataset) and kind.
void loadRunIdentity(const YAML::Node& r, const std::string& f, const std::string& field, std::set<std::string>& names,
                     Run& run) {
  if (!r["file"]) fail(f, r, field + ".file", "missing");
  run.file = r["file"].as<std::string>();
  if (run.file.empty()) fail(f, r["file"], field + ".file", "empty file name");
  if (r["name"]) {
    run.name = r["name"].as<std::string>();
  } else {  // the file's name without its folders and extension
    const std::string base = run.file.substr(run.file.find_last_of('/') + 1);
    run.name = base.substr(0, base.find_last_of('.'));
  }
  // The name becomes a file name in the reports (data/<version>/<name>.csv).
  if (run.name.empty() || run.name == "." || run.name == ".." || run.name.find_first_of("/\\") != std::string::npos)
    fail(f, r["name"] ? r["name"] : r["file"], field + ".name",
         "run name '" + run.name + "' must be a plain file name (not empty, no '/' or '\\')");
  if (!names.insert(run.name).second) fail(f, r["name"] ? r["name"] : r, field + ".name", "duplicate run name '" + run.name + "'");
  const std::string kind = r["kind"] ? r["kind"].as<std::string>() : "drive";
  if (kind == "drive") run.kind = RunKind::Drive;
  else if (kind == "place") run.kind = RunKind::Place;
  else fail(f, r["kind"], field + ".kind", "expected drive or place, found '" + kind + "'");
}

/// A run's start pose (required for a drive run), group and start time.
void loadRunStart(const YAML::Node& r, const std::string& f, const std::string& field, Run& run) {
  if (const YAML::Node p = r["initial_pose"]) {
    if (!p.IsMap()) fail(f, p, field + ".initial_pose", "expected {x, y, yaw}");
    allowOnly(p, f, field + ".initial_pose", {"x", "y", "yaw"});
    for (const char* k : {"x", "y", "yaw"})
      if (!p[k]) fail(f, p, field + ".initial_pose." + k, "missing (a start pose gives x, y and yaw)");
    run.initial_pose.x = number(p["x"], f, field + ".initial_pose.x");
    run.initial_pose.y = number(p["y"], f, field + ".initial_pose.y");
    run.initial_pose.yaw = number(p["yaw"], f, field + ".initial_pose.yaw");
    // The measured channels' own bounds (channelRangeProblem): a start the world cannot place was
    // named only by the first replay, without the file or the field.
    const std::pair<const char*, double> start[] = {
        {"x", run.initial_pose.x}, {"y", run.initial_pose.y}, {"yaw", run.initial_pose.yaw}};
    for (const auto& [k, v] : start)
      if (const std::string why = channelRangeProblem(k, v); !why.empty()) fail(f, p[k], field + ".initial_pose." + k, why);
  } else if (run.kind == RunKind::Drive) {
    fail(f, r, field + ".initial_pose", "missing (a drive run starts from a known pose)");
  }
  run.group = r["group"] ? r["group"].as<std::string>() : defaultGroup(run.name);
  if (r["start_time"]) {
    run.start_time = number(r["start_time"], f, field + ".start_time");
    if (run.start_time < 0) fail(f, r["start_time"], field + ".start_time", "must be >= 0");
    if (run.start_time > kMaxStartTime)  // a battery's time, not a date: 1e300 s drained it at once
      fail(f, r["start_time"], field + ".start_time",
           "must be at most " + fmtNumber(kMaxStartTime) + " s (a time in the session, not a date)");
  }
}

/// runs: each run's fields, then its CSV file (one file per run).
void loadRuns(const YAML::Node& root, const std::string& f, Dataset& ds) {
  const YAML::Node runs = root["runs"];
  if (!runs || !runs.IsSequence() || runs.size() == 0) fail(f, runs ? runs : root, "runs", "expected a non-empty list of runs");
  std::set<std::string> names;
  std::map<std::string, std::string> run_of_file;  // the file as the system resolves it -> its run
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const std::string field = "runs[" + std::to_string(i) + "]";
    const YAML::Node r = runs[i];
    if (!r.IsMap()) fail(f, r, field, "expected a mapping {name, file, kind, initial_pose}");
    allowOnly(r, f, field, {"name", "file", "kind", "initial_pose", "group", "description", "start_time"});
    Run run;
    loadRunIdentity(r, f, field, names, run);
    loadRunStart(r, f, field, run);
    run.path = run.file[0] == '/' ? run.file : ds.dir + "/" + run.file;
    // One file, one run's measurements: a second run naming it (a copy-paste slip) replayed the
    // first run's data from the second's start pose and counted it twice.
    char resolved[PATH_MAX];
    const std::string same = ::realpath(run.path.c_str(), resolved) ? std::string(resolved) : run.path;
    if (const auto [at, fresh] = run_of_file.emplace(same, run.name); !fresh)
      fail(f, r["file"], field + ".file", "'" + run.file + "' is already the file of run '" + at->second +
                                              "': each run needs its own measurements");
    parseRunCsv(readFile(run.path, f, r["file"]), run.path, run);
    ds.runs.push_back(std::move(run));
  }
}

Dataset loadDatasetFields(const std::string& path_in) {
  std::string yaml_path = path_in;
  if (isDirectory(path_in)) yaml_path = path_in + (path_in.back() == '/' ? "" : "/") + "dataset.yaml";
  Dataset ds;
  ds.yaml_path = yaml_path;
  const auto slash = yaml_path.find_last_of('/');
  ds.dir = slash == std::string::npos ? "." : yaml_path.substr(0, slash);
  const std::string& f = yaml_path;
  const YAML::Node root = readRoot(f);
  loadHeaderFields(root, f, ds);

  std::set<std::string> surfaces = knownSurfaces();
  if (const YAML::Node s = root["surfaces"]) {
    if (!s.IsSequence()) fail(f, s, "surfaces", "expected a list of extra surface labels");
    for (const auto& l : s) surfaces.insert(l.as<std::string>());
  }
  if (const YAML::Node w = root["world"]) loadWorld(w, f, surfaces, ds);
  if (const YAML::Node n = root["noise"]) loadNoise(n, f, ds);
  loadRuns(root, f, ds);
  return ds;
}

}  // namespace

Dataset loadDataset(const std::string& path) {
  try {
    return loadDatasetFields(path);
  } catch (const YAML::Exception& e) {  // a value of the wrong type (e.g. a list where a name belongs)
    const std::string yaml = isDirectory(path) ? path + (path.back() == '/' ? "" : "/") + "dataset.yaml" : path;
    throw DatasetError(yaml, e.mark.line + 1, e.mark.column + 1, "", "value of the wrong type: " + e.msg);
  }
}

// ---- writing -------------------------------------------------------------------------------------

namespace {

std::string fmt(double v, int prec = 7) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

void writeRunCsv(const Run& run, const std::string& path) {
  OutputFile out(path);
  std::vector<std::string> cols;
  for (const auto& [c, s] : run.channels) cols.push_back(c);
  // Stable, readable order: pose, speeds, torques, tilt, then sensors.
  auto rank = [](const std::string& c) {
    static const std::vector<std::string> order{"x", "y", "yaw", "speed_left", "speed_right", "torque_left",
                                                "torque_right", "pitch", "roll"};
    auto it = std::find(order.begin(), order.end(), c);
    if (it != order.end()) return static_cast<int>(it - order.begin());
    const std::string g = NoiseModel::group(c);
    const int base = g == "ir" ? 100 : g == "ground" ? 200 : 300;
    return base + std::atoi(c.c_str() + c.find_first_of("0123456789"));
  };
  std::sort(cols.begin(), cols.end(), [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
  if (run.kind == RunKind::Drive) {
    const bool has_force = !run.force_t.empty(), has_passive = !run.passive_t.empty();
    out << "t,cmd_left,cmd_right" << (has_force ? ",force_x,force_y" : "") << (has_passive ? ",passive" : "");
    for (const auto& c : cols) out << "," << c;
    out << "\n";
    // Merge time stamps (rounded to the microsecond) of commands and every channel.
    std::map<long long, std::map<std::string, double>> rows;
    auto key = [](double t) { return static_cast<long long>(std::llround(t * 1e6)); };
    for (std::size_t i = 0; i < run.cmd_t.size(); ++i) {
      rows[key(run.cmd_t[i])]["cmd_left"] = run.cmd_left[i];
      rows[key(run.cmd_t[i])]["cmd_right"] = run.cmd_right[i];
    }
    for (std::size_t i = 0; i < run.force_t.size(); ++i) {
      rows[key(run.force_t[i])]["force_x"] = run.force_x[i];
      rows[key(run.force_t[i])]["force_y"] = run.force_y[i];
    }
    for (std::size_t i = 0; i < run.passive_t.size(); ++i) rows[key(run.passive_t[i])]["passive"] = run.passive[i];
    for (const auto& [c, s] : run.channels)
      for (std::size_t i = 0; i < s.t.size(); ++i) rows[key(s.t[i])][c] = s.v[i];
    std::vector<const char*> inputs{"cmd_left", "cmd_right"};
    if (has_force) {
      inputs.push_back("force_x");
      inputs.push_back("force_y");
    }
    if (has_passive) inputs.push_back("passive");
    for (const auto& [k, vals] : rows) {
      out << fmt(k * 1e-6, 10);
      for (const char* c : inputs) {
        out << ",";
        if (vals.count(c)) out << fmt(vals.at(c));
      }
      for (const auto& c : cols) {
        out << ",";
        if (vals.count(c)) out << fmt(vals.at(c));
      }
      out << "\n";
    }
  } else {
    bool has_z = false;
    for (const auto& p : run.placements) has_z |= !std::isnan(p.z);
    out << "x,y,yaw" << (has_z ? ",z" : "");
    for (const auto& c : cols) out << "," << c;
    out << "\n";
    for (std::size_t row = 0; row < run.placements.size(); ++row) {
      const Placement& p = run.placements[row];
      out << fmt(p.pose.x) << "," << fmt(p.pose.y) << "," << fmt(p.pose.yaw);
      if (has_z) out << "," << (std::isnan(p.z) ? "" : fmt(p.z));
      for (const auto& c : cols) {
        out << ",";
        const Series& s = run.channels.at(c);
        auto it = std::find(s.t.begin(), s.t.end(), static_cast<double>(row));
        if (it != s.t.end()) out << fmt(s.v[it - s.t.begin()]);
      }
      out << "\n";
    }
  }
  out.commit();
}

}  // namespace

void writeDataset(const Dataset& ds, const std::string& dir) {
  makeOutputDirectory(dir);
  YAML::Emitter e;
  e.SetDoublePrecision(10);
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << "sbot-dataset/1";
  e << YAML::Key << "name" << YAML::Value << ds.name;
  if (!ds.description.empty()) e << YAML::Key << "description" << YAML::Value << ds.description;
  e << YAML::Key << "robot" << YAML::Value << ds.robot;
  e << YAML::Key << "world" << YAML::Value << YAML::BeginMap;
  if (ds.world_sets_step) e << YAML::Key << "step" << YAML::Value << ds.world.step;
  if (ds.world_sets_gravity) e << YAML::Key << "gravity" << YAML::Value << ds.world.gravity;
  if (ds.world.solver != "quickstep") e << YAML::Key << "solver" << YAML::Value << ds.world.solver;
  e << YAML::Key << "terrain" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "type" << YAML::Value
    << "plane" << YAML::EndMap;
  if (!ds.world.terrain.boxes.empty()) {
    e << YAML::Key << "obstacles" << YAML::Value << YAML::BeginSeq;
    for (const auto& b : ds.world.terrain.boxes) {
      e << YAML::Flow << YAML::BeginMap;
      e << YAML::Key << "name" << YAML::Value << b.name;
      e << YAML::Key << "center" << YAML::Value << YAML::Flow << YAML::BeginSeq << b.center.x() << b.center.y()
        << b.center.z() << YAML::EndSeq;
      e << YAML::Key << "size" << YAML::Value << YAML::Flow << YAML::BeginSeq << b.size.x() << b.size.y()
        << b.size.z() << YAML::EndSeq;
      e << YAML::Key << "yaw" << YAML::Value << b.yaw;
      if (b.pitch != 0) e << YAML::Key << "pitch" << YAML::Value << b.pitch;
      e << YAML::Key << "surface" << YAML::Value << b.surface;
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }
  if (!ds.lamps.empty()) {
    e << YAML::Key << "lamps" << YAML::Value << YAML::BeginSeq;
    for (const auto& l : ds.lamps) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "position" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << l.position.x() << l.position.y() << l.position.z() << YAML::EndSeq << YAML::Key << "intensity"
        << YAML::Value << l.intensity << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }
  if (ds.ambient_light != 0) e << YAML::Key << "ambient_light" << YAML::Value << ds.ambient_light;
  e << YAML::EndMap;
  e << YAML::Key << "noise" << YAML::Value << YAML::BeginMap;
  for (const auto& [g, v] : ds.noise.table) {
    e << YAML::Key << g << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "abs" << YAML::Value << v.first
      << YAML::Key << "rel" << YAML::Value << v.second << YAML::EndMap;
  }
  e << YAML::EndMap;
  if (!ds.align_initial_pose) e << YAML::Key << "align_initial_pose" << YAML::Value << false;
  e << YAML::Key << "align_segment" << YAML::Value << ds.align_segment;
  e << YAML::Key << "runs" << YAML::Value << YAML::BeginSeq;
  for (const auto& r : ds.runs) {
    e << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "name" << YAML::Value << r.name;
    e << YAML::Key << "file" << YAML::Value << (r.file.empty() ? r.name + ".csv" : r.file);
    e << YAML::Key << "kind" << YAML::Value << (r.kind == RunKind::Drive ? "drive" : "place");
    if (!r.group.empty() && r.group != defaultGroup(r.name)) e << YAML::Key << "group" << YAML::Value << r.group;
    if (r.start_time != 0) e << YAML::Key << "start_time" << YAML::Value << r.start_time;
    e << YAML::Key << "initial_pose" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "x"
      << YAML::Value << r.initial_pose.x << YAML::Key << "y" << YAML::Value << r.initial_pose.y << YAML::Key
      << "yaw" << YAML::Value << r.initial_pose.yaw << YAML::EndMap;
    e << YAML::EndMap;
  }
  e << YAML::EndSeq;
  e << YAML::EndMap;
  writeTextFile(dir + "/dataset.yaml", std::string("# sbot-dataset/1 (see docs/calibration.md)\n") + e.c_str() + "\n");
  for (const auto& r : ds.runs) writeRunCsv(r, dir + "/" + (r.file.empty() ? r.name + ".csv" : r.file));
}

}  // namespace sbot::calib
