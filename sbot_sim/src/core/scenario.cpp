#include "sbot_sim/core/scenario.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/yaml_checks.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/world.h"  // robotNameProblem

namespace sbot {
namespace {

/// Seeds are whole numbers a double holds exactly.
constexpr long long kMaxSeed = 1LL << 53;

// Reads typed fields of one YAML mapping and reports errors with the full dotted field path.
class Fields {
 public:
  // An absent or empty (null) section reads as all defaults.
  Fields(const YAML::Node& node, std::string path, const std::string& file)
      : node_(node), present_(node.IsDefined() && !node.IsNull()), path_(std::move(path)), file_(file) {
    if (present_ && !node_.IsMap()) throw ConfigError(file_, path_, "expected a mapping");
  }
  std::string path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  bool has(const std::string& key) const { return present_ && node_[key] && !node_[key].IsNull(); }
  /// Whether a value is given for `key`; a key given as YAML null (`~`, `null` or nothing after the
  /// colon) is refused rather than read as the default: leave the key out for that.
  bool given(const std::string& key) const {
    if (!present_ || !node_[key]) return false;
    if (node_[key].IsNull())
      throw ConfigError(file_, path(key), "is null (~); give a value, or leave the field out for its default");
    return true;
  }
  YAML::Node node(const std::string& key) const {
    return has(key) ? node_[key] : YAML::Node(YAML::NodeType::Undefined);
  }

  double number(const std::string& key, double fallback) const {
    if (!given(key)) return fallback;
    double v;
    try {
      v = node_[key].as<double>();
    } catch (const YAML::Exception&) {
      throw ConfigError(file_, path(key), "expected a number, found '" + scalar(key) + "'");
    }
    if (!std::isfinite(v)) throw ConfigError(file_, path(key), "must be finite");
    return v;
  }
  double within(const std::string& key, double fallback, double lo, double hi) const {
    const double v = number(key, fallback);
    if (v < lo || v > hi) throw ConfigError(file_, path(key), "must be in [" + fmt(lo) + ", " + fmt(hi) + "], found " + fmt(v));
    return v;
  }
  /// A whole number in [lo, hi] (counts, iterations, seeds: a cast would wrap or truncate silently).
  long long integer(const std::string& key, long long fallback, long long lo, long long hi) const {
    const double v = number(key, static_cast<double>(fallback));
    if (v != std::floor(v) || v < lo || v > hi)
      throw ConfigError(file_, path(key), "must be a whole number in [" + fmt(lo) + ", " + fmt(hi) + "], found " + fmt(v));
    return static_cast<long long>(v);
  }
  /// `v` (read from `key`) unless `problem` (an input_limits.h / positionProblem check) refuses it.
  template <class T>
  T checked(const std::string& key, T v, const std::string& problem) const {
    if (!problem.empty()) throw ConfigError(file_, path(key), problem);
    return v;
  }
  /// An angle [rad] within input_limits.h's range.
  double angle(const std::string& key, double fallback) const {
    const double v = number(key, fallback);
    return checked(key, v, angleProblem(v));
  }
  /// An edge or length of geometry [m] within input_limits.h's range.
  double geomSize(const std::string& key, double fallback) const {
    const double v = number(key, fallback);
    return checked(key, v, geomSizeProblem(v));
  }
  std::string text(const std::string& key, const std::string& fallback) const {
    if (!given(key)) return fallback;
    if (!node_[key].IsScalar()) throw ConfigError(file_, path(key), "expected a string");
    return node_[key].as<std::string>();
  }
  bool flag(const std::string& key, bool fallback) const {
    if (!given(key)) return fallback;
    try {
      return node_[key].as<bool>();
    } catch (const YAML::Exception&) {
      throw ConfigError(file_, path(key), "expected true or false");
    }
  }
  Vec3 vec3(const std::string& key, const Vec3& fallback) const {
    Vec3 v = fallback;
    numbers(key, 3, "[x, y, z]", v.data());
    return v;
  }
  /// [x, y]; absent: `fallback`.
  void xy(const std::string& key, double* x, double* y) const {
    double v[2] = {*x, *y};
    numbers(key, 2, "[x, y]", v);
    *x = v[0];
    *y = v[1];
  }
  /// Typos in scenario files should not be silently ignored.
  void allowOnly(const std::set<std::string>& keys) const {
    if (!present_) return;
    if (const YAML::Node k = unknownKey(node_, keys)) throw ConfigError(file_, path(k.Scalar()), unknownFieldMessage(keys));
  }

 private:
  std::string scalar(const std::string& key) const {
    return node_[key].IsScalar() ? node_[key].as<std::string>() : "<not a scalar>";
  }
  static std::string fmt(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  }
  /// A list of exactly `n` finite numbers into out[0..n); absent: out unchanged.
  void numbers(const std::string& key, int n, const char* shape, double* out) const {
    if (!given(key)) return;
    const YAML::Node list = node_[key];
    if (!list.IsSequence() || static_cast<int>(list.size()) != n)
      throw ConfigError(file_, path(key), std::string("expected ") + shape);
    for (int i = 0; i < n; ++i) {
      try {
        out[i] = list[i].as<double>();
      } catch (const YAML::Exception&) {
        throw ConfigError(file_, path(key), std::string("expected ") + shape + " of numbers");
      }
      if (!std::isfinite(out[i])) throw ConfigError(file_, path(key), "must be finite");
    }
  }
  YAML::Node node_;
  bool present_;
  std::string path_;
  const std::string& file_;
};

std::string checkLevel(const std::string& level, const std::string& file, const std::string& field) {
  for (const auto& l : modelLevels())
    if (l == level) return level;
  throw ConfigError(file, field, "unknown model level '" + level + "' (levels: fast, simple, basic, medium, detailed)");
}

Pose2D parsePose(const YAML::Node& n, const std::string& path, const std::string& file) {
  Fields f(n, path, file);
  f.allowOnly({"x", "y", "yaw"});
  const Pose2D pose{f.number("x", 0), f.number("y", 0), f.angle("yaw", 0)};
  if (const std::string where = positionProblem(Vec3(pose.x, pose.y, 0)); !where.empty())
    throw ConfigError(file, path, where);
  return pose;
}

void parseTerrain(const YAML::Node& n, TerrainConfig& t, const std::string& file) {
  Fields f(n, "world.terrain", file);
  f.allowOnly({"type", "ground_plane", "boxes", "arena", "heightmap_image", "resolution", "size",
               "height_range", "seed"});
  const std::string type = f.text("type", "plane");
  if (type == "plane") t.type = TerrainConfig::Type::Plane;
  else if (type == "composite") t.type = TerrainConfig::Type::Composite;
  else if (type == "rough") t.type = TerrainConfig::Type::Rough;
  else throw ConfigError(file, f.path("type"), "expected plane, composite or rough, found '" + type + "'");
  if (t.type != TerrainConfig::Type::Rough)  // they would be ignored: a forgotten `type: rough`
    for (const char* key : {"heightmap_image", "resolution", "size", "height_range", "seed"})
      if (f.has(key)) throw ConfigError(file, f.path(key), "belongs to a rough terrain; this one is " + type);
  t.ground_plane = f.flag("ground_plane", true);
  t.heightmap_image = f.text("heightmap_image", "");
  if (!t.heightmap_image.empty() && t.heightmap_image[0] != '/') {
    // Relative image paths are relative to the scenario file.
    const auto slash = file.find_last_of('/');
    if (slash != std::string::npos) t.heightmap_image = file.substr(0, slash + 1) + t.heightmap_image;
  }
  t.resolution = static_cast<int>(f.integer("resolution", t.resolution, 8, 4096));
  if (f.has("size")) {
    const double s = f.within("size", 5.0, kMinTerrainSize, kMaxTerrainSize);
    t.size_x = t.size_y = s;
  }
  t.height_range = f.within("height_range", 0.0, 0, kMaxTerrainSize);
  t.heightmap_seed = static_cast<std::uint64_t>(f.integer("seed", 1, 0, kMaxSeed));

  if (const YAML::Node boxes = f.node("boxes")) {
    if (!boxes.IsSequence()) throw ConfigError(file, f.path("boxes"), "expected a list");
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      Fields b(boxes[i], f.path("boxes") + "[" + std::to_string(i) + "]", file);
      b.allowOnly({"name", "center", "size", "yaw", "pitch", "surface"});
      BoxObstacle box;
      box.name = b.text("name", "box_" + std::to_string(i));
      box.center = b.vec3("center", Vec3::Zero());
      b.checked("center", 0, positionProblem(box.center));
      box.size = b.vec3("size", Vec3::Ones());
      b.checked("size", 0, boxSizeProblem(box.size));
      box.yaw = b.angle("yaw", 0);
      box.pitch = b.angle("pitch", 0);
      box.surface = b.text("surface", "ground");
      for (const BoxObstacle& other : t.boxes)
        if (other.name == box.name)
          throw ConfigError(file, b.path("name"), "'" + box.name + "' names another box too (effects and reports name boxes)");
      t.boxes.push_back(box);
    }
  }
  if (const YAML::Node arena = f.node("arena")) {
    Fields a(arena, f.path("arena"), file);
    a.allowOnly({"size", "height", "thickness", "surface"});
    const double s = a.geomSize("size", 4.0), h = a.geomSize("height", 0.1), th = a.geomSize("thickness", 0.02);
    const std::string surface = a.text("surface", "wall");
    const double o = s / 2 + th / 2;
    const std::size_t own_boxes = t.boxes.size();
    t.boxes.push_back({"arena_north", Vec3(0, o, h / 2), Vec3(s + 2 * th, th, h), 0, 0, surface});
    t.boxes.push_back({"arena_south", Vec3(0, -o, h / 2), Vec3(s + 2 * th, th, h), 0, 0, surface});
    t.boxes.push_back({"arena_east", Vec3(o, 0, h / 2), Vec3(th, s, h), 0, 0, surface});
    t.boxes.push_back({"arena_west", Vec3(-o, 0, h / 2), Vec3(th, s, h), 0, 0, surface});
    for (std::size_t i = 0; i < own_boxes; ++i)
      if (t.boxes[i].name.rfind("arena_", 0) == 0)
        throw ConfigError(file, f.path("boxes") + "[" + std::to_string(i) + "].name",
                          "'" + t.boxes[i].name + "' is the name of one of the arena's walls (arena_north/south/east/west)");
  }
}

void parseWorld(const YAML::Node& n, WorldConfig& w, const std::string& file) {
  Fields f(n, "world", file);
  // lamps / ambient_light: the sensed environment, not physics (parseSensedEnvironment).
  f.allowOnly({"step", "gravity", "solver", "solver_iterations", "solver_sor", "lock_idle_turret", "sleep_at_rest",
               "contact", "terrain", "lamps", "ambient_light"});
  w.solver = f.text("solver", w.solver);
  if (w.solver != "quickstep" && w.solver != "exact")
    throw ConfigError(file, f.path("solver"), "expected 'quickstep' or 'exact', found '" + w.solver + "'");
  w.step = f.within("step", w.step, kMinStep, kMaxStep);
  w.gravity = f.number("gravity", w.gravity);
  if (w.gravity < 0) throw ConfigError(file, f.path("gravity"), "must be >= 0 (its magnitude: gravity points along -z)");
  if (w.gravity > kMaxGravity)
    throw ConfigError(file, f.path("gravity"), "must be <= " + std::to_string(static_cast<int>(kMaxGravity)) +
                                                   " m/s^2 (100 g; no contact holds beyond)");
  w.solver_iterations = static_cast<int>(f.integer("solver_iterations", w.solver_iterations, 1, 100000));
  w.solver_sor = f.within("solver_sor", w.solver_sor, 0.01, kMaxSolverSor);
  w.lock_idle_turret = f.flag("lock_idle_turret", w.lock_idle_turret);
  w.rest.enabled = f.flag("sleep_at_rest", w.rest.enabled);
  if (const YAML::Node c = f.node("contact")) {
    Fields cf(c, "world.contact", file);
    cf.allowOnly({"mu", "erp", "cfm", "bounce", "max_contacts", "coulomb", "materials"});
    w.contact.mu = cf.number("mu", w.contact.mu);
    if (w.contact.mu < 0) throw ConfigError(file, cf.path("mu"), "must be >= 0");
    w.contact.erp = cf.within("erp", w.contact.erp, 0, 1);
    w.contact.cfm = cf.number("cfm", w.contact.cfm);
    if (w.contact.cfm < 0) throw ConfigError(file, cf.path("cfm"), "must be >= 0");
    w.contact.bounce = cf.within("bounce", w.contact.bounce, 0, 1);
    // World::handlePair collects at most 16 contacts per geom pair.
    w.contact.max_contacts = static_cast<int>(cf.integer("max_contacts", w.contact.max_contacts, 1, 16));
    w.contact.coulomb = cf.flag("coulomb", w.contact.coulomb);
    if (const YAML::Node m = cf.node("materials")) {
      Fields mf(m, "world.contact.materials", file);
      for (const auto& kv : m) {
        const std::string material = kv.first.as<std::string>();
        w.contact.material_mu[material] = mf.number(material, 0);
        if (w.contact.material_mu[material] < 0) throw ConfigError(file, mf.path(material), "must be >= 0");
      }
    }
  }
  parseTerrain(f.node("terrain"), w.terrain, file);
  // A friction coefficient for a name nothing is made of would never apply (a typo, or a surface
  // the terrain does not have): robots' materials, the library's surfaces and this terrain's.
  std::set<std::string> names = robotMaterials();
  for (const auto& s : knownSurfaces()) names.insert(s);
  for (const auto& s : surfaceLabels(w.terrain)) names.insert(s);
  for (const auto& [material, mu] : w.contact.material_mu)
    if (!names.count(material))
      throw ConfigError(file, "world.contact.materials." + material,
                        "no robot material or terrain surface is called '" + material + "' (names: " + nameList(names) + ")");
}

}  // namespace

// The Fast level is scaled for 1/50 g (seed 3.1, 4.2.4: "tested separately and alone"): refuse it
// under another gravity, and beside full-size robots, which would then live in 1/50 g.
void checkGravityOfLevels(const Scenario& s, const std::string& file) {
  const RobotDescription* scaled = nullptr;
  const RobotDescription* full_size = nullptr;
  for (const RobotSpawn& r : s.robots) {
    const RobotDescription& d = loadLevel(r.level);
    const std::string problem = gravityProblem(d, s.world.gravity);
    if (!problem.empty()) throw ConfigError(file, "robots (" + r.name + ")", problem);
    (scaledForItsGravity(d) ? scaled : full_size) = &d;
  }
  if (scaled && full_size)
    throw ConfigError(file, "robots", "level " + scaled->level + " is scaled for " + std::to_string(scaled->gravity) +
                                          " m/s^2 and cannot share a world with full-size robots (" + full_size->level +
                                          "); the seed runs it alone (4.2.4)");
}

/// world.lamps and world.ambient_light, checked as Environment::addLamp / setAmbientLight would.
void parseSensedEnvironment(const YAML::Node& world, Scenario& s, const std::string& file) {
  Fields w(world, "world", file);
  s.ambient_light = w.number("ambient_light", 0);
  w.checked("ambient_light", 0, lightIntensityProblem(s.ambient_light, "mcd/cm^2"));
  const YAML::Node lamps = w.node("lamps");
  if (!lamps) return;
  if (!lamps.IsSequence()) throw ConfigError(file, w.path("lamps"), "expected a list of {position, intensity, colour}");
  for (std::size_t i = 0; i < lamps.size(); ++i) {
    Fields l(lamps[i], "world.lamps[" + std::to_string(i) + "]", file);
    l.allowOnly({"position", "intensity", "colour"});
    if (!l.has("position")) throw ConfigError(file, l.path("position"), "missing (expected [x, y, z] in m)");
    LampSpawn lamp;
    lamp.position = l.vec3("position", lamp.position);
    if (const std::string where = positionProblem(lamp.position); !where.empty())
      throw ConfigError(file, l.path("position"), where);
    lamp.intensity = l.number("intensity", 0);
    l.checked("intensity", 0, lightIntensityProblem(lamp.intensity, "mcd"));
    lamp.colour = l.vec3("colour", lamp.colour);
    if (lamp.colour.minCoeff() < 0 || lamp.colour.maxCoeff() > 1)
      throw ConfigError(file, l.path("colour"), "expected [r, g, b] in [0, 1]");
    s.lamps.push_back(lamp);
  }
}

Scenario parseScenario(const std::string& yaml_text, const std::string& file, int robot_count) {
  if (robot_count > kMaxRobots)
    throw ConfigError(file, "swarm.count", "robot count override " + std::to_string(robot_count) + " exceeds " +
                                               std::to_string(kMaxRobots));
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(file, "", "not valid YAML (line " + std::to_string(e.mark.line + 1) + "): " + e.msg);
  }
  if (const std::string problem = yamlStructureProblem(root); !problem.empty()) throw ConfigError(file, "", problem);
  if (!root.IsMap()) throw ConfigError(file, "", "expected a mapping at the top level");
  Fields f(root, "", file);
  f.allowOnly({"seed", "duration", "world", "robots", "swarm", "links", "name", "description", "effects"});
  Scenario s;
  s.source = file;
  s.world.seed = static_cast<std::uint64_t>(f.integer("seed", 1, 0, kMaxSeed));
  s.duration = f.within("duration", 0, 0, kMaxDuration);
  s.effects_file = f.text("effects", "");
  if (!s.effects_file.empty() && s.effects_file[0] != '/') {
    const auto slash = file.find_last_of('/');
    if (slash != std::string::npos) s.effects_file = file.substr(0, slash + 1) + s.effects_file;
  }
  parseWorld(f.node("world"), s.world, file);
  parseSensedEnvironment(f.node("world"), s, file);

  if (const YAML::Node robots = f.node("robots")) {
    if (!robots.IsSequence()) throw ConfigError(file, "robots", "expected a list");
    for (std::size_t i = 0; i < robots.size(); ++i) {
      const std::string path = "robots[" + std::to_string(i) + "]";
      Fields r(robots[i], path, file);
      r.allowOnly({"name", "level", "pose"});
      RobotSpawn spawn;
      spawn.name = r.text("name", "sbot_" + std::to_string(i));
      const std::string problem = robotNameProblem(spawn.name);
      if (!problem.empty()) throw ConfigError(file, r.path("name"), problem);
      spawn.level = checkLevel(r.text("level", "simple"), file, r.path("level"));
      spawn.pose = parsePose(r.node("pose"), r.path("pose"), file);
      s.robots.push_back(spawn);
    }
  }
  std::set<std::string> dropped;  // listed robots the count override leaves out (no swarm section)
  if (const YAML::Node swarm = f.node("swarm")) {
    Fields sw(swarm, "swarm", file);
    sw.allowOnly({"count", "level", "layout", "spacing", "center", "area"});
    const int count = robot_count >= 0 ? robot_count : static_cast<int>(sw.integer("count", 0, 0, kMaxRobots));
    const std::string level = checkLevel(sw.text("level", "simple"), file, "swarm.level");
    const std::string layout = sw.text("layout", "grid");
    if (layout != "grid" && layout != "random")
      throw ConfigError(file, "swarm.layout", "expected grid or random, found '" + layout + "'");
    const double spacing = sw.within("spacing", 0.3, kMinGeomSize, kMaxGeomSize);
    double cx = 0, cy = 0;
    sw.xy("center", &cx, &cy);
    sw.checked("center", 0, positionProblem(Vec3(cx, cy, 0)));
    const int side = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count)))));
    std::mt19937_64 rng(s.world.seed * 7919 + 17);
    const double area = sw.within("area", side * spacing, kMinGeomSize, kMaxGeomSize);
    std::uniform_real_distribution<double> uni(-area / 2, area / 2), ang(-M_PI, M_PI);
    const std::size_t first = s.robots.size();
    for (int i = 0; i < count; ++i) {
      RobotSpawn spawn;
      spawn.name = "sbot_" + std::to_string(first + i);
      spawn.level = level;
      if (layout == "grid") {
        spawn.pose = {cx + (i % side - (side - 1) / 2.0) * spacing, cy + (i / side - (side - 1) / 2.0) * spacing,
                      ang(rng)};
      } else if (layout == "random") {
        // Rejection sampling keeps robots at least `spacing` apart.
        for (int attempt = 0;; ++attempt) {
          spawn.pose = {cx + uni(rng), cy + uni(rng), ang(rng)};
          bool clear = true;
          for (const auto& o : s.robots)
            clear &= std::hypot(o.pose.x - spawn.pose.x, o.pose.y - spawn.pose.y) >= spacing;
          if (clear) break;
          if (attempt > 10000) throw ConfigError(file, "swarm.area", "too small for " + std::to_string(count) + " robots");
        }
      } else {
        throw ConfigError(file, "swarm.layout", "expected grid or random, found '" + layout + "'");
      }
      s.robots.push_back(spawn);
    }
  } else if (robot_count >= 0 && static_cast<int>(s.robots.size()) > robot_count) {
    for (std::size_t i = robot_count; i < s.robots.size(); ++i) dropped.insert(s.robots[i].name);
    s.robots.resize(robot_count);
  }
  std::set<std::string> names;
  for (const auto& r : s.robots) {
    if (!names.insert(r.name).second) throw ConfigError(file, "robots", "duplicate robot name '" + r.name + "'");
  }
  if (const YAML::Node links = f.node("links")) {
    if (!links.IsSequence()) throw ConfigError(file, "links", "expected a list");
    for (std::size_t i = 0; i < links.size(); ++i) {
      const std::string path = "links[" + std::to_string(i) + "]";
      Fields l(links[i], path, file);
      l.allowOnly({"holder", "held", "kind"});
      LinkSpawn link;
      link.holder = l.text("holder", "");
      link.held = l.text("held", "");
      for (const auto* n : {&link.holder, &link.held}) {
        const std::string field = l.path(n == &link.holder ? "holder" : "held");
        if (n->empty()) throw ConfigError(file, field, "required");
        if (dropped.count(*n))
          throw ConfigError(file, field, "robot '" + *n + "' is left out by the robot count override " +
                                             std::to_string(robot_count) + " (~robots): the link needs it");
        if (!names.count(*n)) throw ConfigError(file, field, "unknown robot '" + *n + "'");
      }
      if (link.holder == link.held) throw ConfigError(file, path, "a robot cannot grip itself");
      const std::string kind = l.text("kind", "front_gripper");
      if (kind == "front_gripper") link.kind = 1;
      else if (kind == "side_arm") link.kind = 2;
      else throw ConfigError(file, l.path("kind"), "expected front_gripper or side_arm, found '" + kind + "'");
      // A gripper holds one robot: a second link would silently replace the first.
      for (std::size_t k = 0; k < s.links.size(); ++k)
        if (s.links[k].holder == link.holder && s.links[k].kind == link.kind)
          throw ConfigError(file, path, "'" + link.holder + "' already holds '" + s.links[k].held + "' with its " + kind +
                                            " (links[" + std::to_string(k) + "]); it holds one robot");
      s.links.push_back(link);
    }
  }
  checkGravityOfLevels(s, file);
  return s;
}

Scenario loadScenario(const std::string& path, int robot_count) {
  return parseScenario(readInputFile(path, "scenario file"), path, robot_count);
}

std::string scenarioYaml(const Scenario& sc, const std::string& name, const std::string& description) {
  const WorldConfig& w = sc.world;
  const TerrainConfig& t = w.terrain;
  YAML::Emitter e;
  // Each double in its shortest form that reads back to the same value: the written world is the
  // trial's own, bit for bit, and still reads "0.05" rather than "0.050000000000000003".
  auto num = [](double v) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, v).ptr;
    return std::string(text, end);
  };
  auto vec3 = [&](const Vec3& v) { e << YAML::Flow << YAML::BeginSeq << num(v.x()) << num(v.y()) << num(v.z()) << YAML::EndSeq; };
  e << YAML::BeginMap;
  e << YAML::Key << "name" << YAML::Value << name;
  if (!description.empty()) e << YAML::Key << "description" << YAML::Value << description;
  e << YAML::Key << "seed" << YAML::Value << w.seed;
  e << YAML::Key << "duration" << YAML::Value << num(sc.duration);
  if (!sc.effects_file.empty()) e << YAML::Key << "effects" << YAML::Value << sc.effects_file;
  e << YAML::Key << "world" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "step" << YAML::Value << num(w.step);
  e << YAML::Key << "gravity" << YAML::Value << num(w.gravity);
  e << YAML::Key << "solver" << YAML::Value << w.solver;
  e << YAML::Key << "solver_iterations" << YAML::Value << w.solver_iterations;
  e << YAML::Key << "solver_sor" << YAML::Value << num(w.solver_sor);
  e << YAML::Key << "lock_idle_turret" << YAML::Value << w.lock_idle_turret;
  e << YAML::Key << "sleep_at_rest" << YAML::Value << w.rest.enabled;
  e << YAML::Key << "contact" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "mu" << YAML::Value << num(w.contact.mu);
  e << YAML::Key << "erp" << YAML::Value << num(w.contact.erp);
  e << YAML::Key << "cfm" << YAML::Value << num(w.contact.cfm);
  e << YAML::Key << "bounce" << YAML::Value << num(w.contact.bounce);
  e << YAML::Key << "max_contacts" << YAML::Value << w.contact.max_contacts;
  e << YAML::Key << "coulomb" << YAML::Value << w.contact.coulomb;
  e << YAML::Key << "materials" << YAML::Value << YAML::BeginMap;
  for (const auto& [material, mu] : w.contact.material_mu) e << YAML::Key << material << YAML::Value << num(mu);
  e << YAML::EndMap << YAML::EndMap;
  e << YAML::Key << "terrain" << YAML::Value << YAML::BeginMap;
  const char* type = t.type == TerrainConfig::Type::Plane ? "plane" : t.type == TerrainConfig::Type::Composite ? "composite" : "rough";
  e << YAML::Key << "type" << YAML::Value << type;
  e << YAML::Key << "ground_plane" << YAML::Value << t.ground_plane;
  if (t.type == TerrainConfig::Type::Rough) {
    if (t.size_x != t.size_y)
      throw ConfigError(name, "world.terrain.size", "a scenario's rough terrain is square; this one is " +
                                                        std::to_string(t.size_x) + " x " + std::to_string(t.size_y) + " m");
    if (!t.heightmap_image.empty()) e << YAML::Key << "heightmap_image" << YAML::Value << t.heightmap_image;
    e << YAML::Key << "resolution" << YAML::Value << t.resolution;
    e << YAML::Key << "size" << YAML::Value << num(t.size_x);
    e << YAML::Key << "height_range" << YAML::Value << num(t.height_range);
    e << YAML::Key << "seed" << YAML::Value << t.heightmap_seed;
  }
  if (!t.boxes.empty()) {
    e << YAML::Key << "boxes" << YAML::Value << YAML::BeginSeq;
    for (const BoxObstacle& b : t.boxes) {
      e << YAML::Flow << YAML::BeginMap;
      e << YAML::Key << "name" << YAML::Value << b.name;
      e << YAML::Key << "center" << YAML::Value;
      vec3(b.center);
      e << YAML::Key << "size" << YAML::Value;
      vec3(b.size);
      e << YAML::Key << "yaw" << YAML::Value << num(b.yaw) << YAML::Key << "pitch" << YAML::Value << num(b.pitch);
      e << YAML::Key << "surface" << YAML::Value << b.surface;
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }
  e << YAML::EndMap;  // terrain
  if (sc.ambient_light != 0) e << YAML::Key << "ambient_light" << YAML::Value << num(sc.ambient_light);
  if (!sc.lamps.empty()) {
    e << YAML::Key << "lamps" << YAML::Value << YAML::BeginSeq;
    for (const LampSpawn& l : sc.lamps) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "position" << YAML::Value;
      vec3(l.position);
      e << YAML::Key << "intensity" << YAML::Value << num(l.intensity) << YAML::Key << "colour" << YAML::Value;
      vec3(l.colour);
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }
  e << YAML::EndMap;  // world
  e << YAML::Key << "robots" << YAML::Value << YAML::BeginSeq;
  for (const RobotSpawn& r : sc.robots) {
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << r.name << YAML::Key << "level"
      << YAML::Value << r.level << YAML::Key << "pose" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "x"
      << YAML::Value << num(r.pose.x) << YAML::Key << "y" << YAML::Value << num(r.pose.y) << YAML::Key << "yaw"
      << YAML::Value << num(r.pose.yaw) << YAML::EndMap << YAML::EndMap;
  }
  e << YAML::EndSeq;
  if (!sc.links.empty()) {
    e << YAML::Key << "links" << YAML::Value << YAML::BeginSeq;
    for (const LinkSpawn& l : sc.links)
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "holder" << YAML::Value << l.holder << YAML::Key << "held"
        << YAML::Value << l.held << YAML::Key << "kind" << YAML::Value << (l.kind == 2 ? "side_arm" : "front_gripper")
        << YAML::EndMap;
    e << YAML::EndSeq;
  }
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

}  // namespace sbot
