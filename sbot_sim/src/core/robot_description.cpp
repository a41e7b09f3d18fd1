#include "sbot_sim/core/robot_description.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include <Eigen/Cholesky>
#include <urdf_parser/urdf_parser.h>
#include <yaml-cpp/yaml.h>

#include "sbot_sim/core/yaml_checks.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/world_config.h"
#include "description_checks.h"

#ifndef SBOT_DESCRIPTION_SOURCE_DIR
#define SBOT_DESCRIPTION_SOURCE_DIR ""
#endif

namespace sbot {
namespace {

Pose toPose(const urdf::Pose& p) {
  double x, y, z, w;
  p.rotation.getQuaternion(x, y, z, w);
  return Pose(Vec3(p.position.x, p.position.y, p.position.z), Quat(w, x, y, z).normalized());
}

/// The XML of `<link name="NAME" ...>` up to its end, comments removed ("" if not found).
std::string linkXml(const std::string& xml, const std::string& name) {
  std::string text;  // without <!-- comments -->
  for (std::size_t i = 0; i < xml.size();) {
    const std::size_t c = xml.find("<!--", i);
    text += xml.substr(i, c == std::string::npos ? std::string::npos : c - i);
    if (c == std::string::npos) break;
    const std::size_t e = xml.find("-->", c + 4);
    i = e == std::string::npos ? xml.size() : e + 3;
  }
  for (const char q : {'"', '\''}) {
    const std::size_t start = text.find("<link name=" + std::string(1, q) + name + q);
    if (start == std::string::npos) continue;
    const std::size_t open_end = text.find('>', start);
    if (open_end == std::string::npos) return "";
    if (text[open_end - 1] == '/') return text.substr(start, open_end + 1 - start);  // <link .../>
    const std::size_t end = text.find("</link>", open_end);
    return text.substr(start, end == std::string::npos ? std::string::npos : end - start);
  }
  return "";
}

std::size_t countTags(const std::string& xml, const std::string& tag) {
  std::size_t n = 0;
  for (std::size_t i = xml.find("<" + tag); i != std::string::npos; i = xml.find("<" + tag, i + 1)) {
    const char next = i + 1 + tag.size() < xml.size() ? xml[i + 1 + tag.size()] : '>';
    n += (next == '>' || next == ' ' || next == '/' || next == '\n' || next == '\t' || next == '\r');
  }
  return n;
}

void requireReasonableOrigin(const Pose& origin, const std::string& file, const std::string& field) {
  for (int k = 0; k < 3; ++k) requireAtMost(origin.position[k], kMaxLength, file, field + " xyz", "m");
}

LinkDescription convertLink(const urdf::Link& link, const std::string& xml, const std::string& file) {
  LinkDescription out;
  out.name = link.name;
  // urdfdom drops an <inertial> or <collision> it cannot parse (mass="nan", radius="x") with only
  // a message on stderr; the link would then load massless or without that shape.
  const std::string own = linkXml(xml, link.name);
  if (!own.empty()) {
    const std::size_t inertials = countTags(own, "inertial"), collisions = countTags(own, "collision");
    if (inertials != (link.inertial ? 1u : 0u) || collisions != link.collision_array.size())
      throw ConfigError(file, "link " + link.name,
                        "urdfdom could not parse all of it: it kept " + std::to_string(link.inertial ? 1 : 0) + " of " +
                            std::to_string(inertials) + " <inertial> and " + std::to_string(link.collision_array.size()) +
                            " of " + std::to_string(collisions) + " <collision> elements (its message is printed above)");
  }
  if (link.inertial) {
    const urdf::Inertial& in = *link.inertial;
    if (!(std::isfinite(in.mass) && in.mass >= 0))
      throw ConfigError(file, "link " + link.name + "/inertial/mass", "must be a finite number >= 0");
    requireAtMost(in.mass, kMaxMass, file, "link " + link.name + "/inertial/mass", "kg");
    out.mass = in.mass;
    out.inertial_origin = toPose(in.origin);
    requireReasonableOrigin(out.inertial_origin, file, "link " + link.name + "/inertial/origin");
    out.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const std::string field = "link " + link.name + "/inertial/inertia";
    if (!out.inertia.allFinite()) throw ConfigError(file, field, "must be finite");
    for (int k = 0; k < 9; ++k) requireAtMost(out.inertia(k / 3, k % 3), kMaxInertia, file, field, "kg m^2");
    if (in.mass > 0 && (in.ixx <= 0 || in.iyy <= 0 || in.izz <= 0)) {
      throw ConfigError(file, field, "diagonal inertia must be positive for a link with mass");
    }
    // ODE refuses (aborts on) an inertia tensor that is not positive definite: products of inertia
    // too large for the moments.
    if (in.mass > 0 && Eigen::LLT<Mat3>(out.inertia).info() != Eigen::Success) {
      throw ConfigError(file, field,
                        "must be positive definite (ixy, ixz, iyz too large for ixx, iyy, izz); a rigid body's is");
    }
  }
  for (const auto& col : link.collision_array) {
    if (!col || !col->geometry)
      throw ConfigError(file, "link " + link.name + "/collision", "has no geometry");
    const std::string field = "link " + link.name + "/collision/geometry";
    CollisionShape shape;
    shape.origin = toPose(col->origin);
    requireReasonableOrigin(shape.origin, file, "link " + link.name + "/collision/origin");
    switch (col->geometry->type) {
      case urdf::Geometry::SPHERE:
        shape.type = CollisionShape::Type::Sphere;
        shape.radius = static_cast<const urdf::Sphere&>(*col->geometry).radius;
        requireGeomSize(shape.radius, file, field + "/sphere radius");
        requireAtMost(shape.radius, kMaxLength, file, field + "/sphere radius", "m");
        break;
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(*col->geometry);
        shape.type = CollisionShape::Type::Cylinder;
        shape.radius = c.radius;
        shape.length = c.length;
        requireGeomSize(shape.radius, file, field + "/cylinder radius");
        requireGeomSize(shape.length, file, field + "/cylinder length");
        requireAtMost(std::max(shape.radius, shape.length), kMaxLength, file, field + "/cylinder", "m");
        break;
      }
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(*col->geometry);
        shape.type = CollisionShape::Type::Box;
        shape.size = Vec3(b.dim.x, b.dim.y, b.dim.z);
        for (int k = 0; k < 3; ++k) requireGeomSize(shape.size[k], file, field + "/box size");
        for (int k = 0; k < 3; ++k) requireAtMost(shape.size[k], kMaxLength, file, field + "/box size", "m");
        break;
      }
      default:
        throw ConfigError(file, "link " + link.name + "/collision/geometry",
                          "expected sphere, cylinder or box, found a mesh");
    }
    out.collisions.push_back(shape);
  }
  return out;
}

JointDescription convertJoint(const urdf::Joint& j, const std::string& file) {
  JointDescription out;
  out.name = j.name;
  out.parent = j.parent_link_name;
  out.child = j.child_link_name;
  out.origin = toPose(j.parent_to_joint_origin_transform);
  requireReasonableOrigin(out.origin, file, "joint " + j.name + "/origin");
  out.axis = Vec3(j.axis.x, j.axis.y, j.axis.z);
  switch (j.type) {
    case urdf::Joint::FIXED: out.type = JointDescription::Type::Fixed; break;
    case urdf::Joint::REVOLUTE: out.type = JointDescription::Type::Revolute; break;
    case urdf::Joint::CONTINUOUS: out.type = JointDescription::Type::Continuous; break;
    default:
      throw ConfigError(file, "joint " + j.name + "/type",
                        "expected fixed, revolute or continuous (the s-bot has no other joints)");
  }
  if (out.type != JointDescription::Type::Fixed) {
    if (out.axis.norm() < 1e-9) throw ConfigError(file, "joint " + j.name + "/axis", "zero axis");
    out.axis.normalize();
  }
  if (j.limits) {
    out.lower = j.limits->lower;
    out.upper = j.limits->upper;
    out.effort = j.limits->effort;
    out.velocity = j.limits->velocity;
  }
  if (out.type == JointDescription::Type::Revolute && !(out.lower <= out.upper)) {
    throw ConfigError(file, "joint " + j.name + "/limit", "lower limit above upper limit");
  }
  return out;
}

}  // namespace

const std::set<std::string>& robotMaterials() {
  static const std::set<std::string> m{"chassis", "track", "caster", "stickable", "sticky", "body"};
  return m;
}

const LinkDescription* RobotDescription::findLink(const std::string& name) const {
  for (const auto& l : links)
    if (l.name == name) return &l;
  return nullptr;
}

const JointDescription* RobotDescription::findJoint(const std::string& name) const {
  for (const auto& j : joints)
    if (j.name == name) return &j;
  return nullptr;
}

double RobotDescription::totalMass() const {
  double m = 0;
  for (const auto& l : links) m += l.mass;
  return m;
}

double RobotDescription::wheelRadius(const std::string& joint) const {
  auto it = treels.wheel_radii.find(joint);
  return it == treels.wheel_radii.end() ? treels.wheel_radius : it->second;
}

std::string RobotDescription::extraOr(const std::string& key, const std::string& fallback) const {
  auto it = extra.find(key);
  return it == extra.end() ? fallback : it->second;
}

double sidecarNumber(const RobotDescription& d, const char* entry, const char* key, double fallback) {
  const YAML::Node e = d.sidecar[entry];
  if (!e || !e.IsMap() || !e[key]) return fallback;
  double v;
  try {
    v = e[key].as<double>();
  } catch (const YAML::Exception&) {
    throw ConfigError(d.sidecar_path, std::string(entry) + "." + key, "expected a number");
  }
  if (!std::isfinite(v)) throw ConfigError(d.sidecar_path, std::string(entry) + "." + key, "must be finite");
  return v;
}

RobotDescription loadRobotDescription(const std::string& urdf_path, const std::string& sidecar_path) {
  RobotDescription d;
  d.urdf_path = urdf_path;
  d.sidecar_path = sidecar_path;
  d.urdf_xml = readInputFile(urdf_path);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(d.urdf_xml);
  if (!model) throw ConfigError(urdf_path, "", "not a valid URDF (urdfdom's message is printed above)");
  if (!model->getRoot()) throw ConfigError(urdf_path, "", "URDF has no root link");
  d.root_link = model->getRoot()->name;
  if (d.root_link != "base_link")
    throw ConfigError(urdf_path, "root link", "expected 'base_link', found '" + d.root_link + "'");

  // Breadth-first: parents before children, so bodies can be built in one pass.
  std::vector<urdf::LinkConstSharedPtr> queue{model->getRoot()};
  for (std::size_t i = 0; i < queue.size(); ++i) {
    const auto& link = queue[i];
    d.links.push_back(convertLink(*link, d.urdf_xml, urdf_path));
    if (i > 0) d.joints.push_back(convertJoint(*link->parent_joint, urdf_path));
    for (const auto& child : link->child_links) queue.push_back(child);
  }
  parseSidecar(d);
  return d;
}

std::string descriptionDirectory() {
  if (const char* env = std::getenv("SBOT_DESCRIPTION_DIR")) {
    if (*env) return env;
  }
  return SBOT_DESCRIPTION_SOURCE_DIR;
}

const std::vector<std::string>& modelLevels() {
  static const std::vector<std::string> levels{"fast", "simple", "basic", "medium", "detailed"};
  return levels;
}

namespace {
constexpr double kGravityTolerance = 0.01;  // relative
}

bool scaledForItsGravity(const RobotDescription& d) {
  constexpr double kEarth = 9.81;  // [m/s^2]
  return std::abs(d.gravity - kEarth) > kGravityTolerance * kEarth;
}

std::string gravityProblem(const RobotDescription& d, double world_gravity) {
  if (!scaledForItsGravity(d) || std::abs(world_gravity - d.gravity) <= kGravityTolerance * d.gravity) return "";
  std::ostringstream msg;
  msg << "level " << d.level << " is scaled for a gravity of " << d.gravity << " m/s^2 (" << d.sidecar_path
      << "), this world has " << world_gravity << " m/s^2: set the world's gravity to " << d.gravity
      << " (and its step to " << d.recommended_step << " s) and give it no full-size robots";
  return msg.str();
}

const RobotDescription& loadLevel(const std::string& level) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<RobotDescription>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(level);
  if (it != cache.end()) return *it->second;
  bool known = false;
  for (const auto& l : modelLevels()) known |= (l == level);
  if (!known) {
    throw UnknownName("unknown model level '" + level + "' (levels: fast, simple, basic, medium, detailed)");
  }
  const std::string dir = descriptionDirectory() + "/urdf/";
  auto d = std::make_unique<RobotDescription>(
      loadRobotDescription(dir + level + ".urdf", dir + level + ".sbot.yaml"));
  // The level names the robot in messages, topics and model switches: a copied sidecar that kept
  // another level's name made a Simple robot report itself as Medium.
  if (d->level != level)
    throw ConfigError(d->sidecar_path, "level", "says '" + d->level + "' in the sidecar of level '" + level + "'");
  return *cache.emplace(level, std::move(d)).first->second;
}

}  // namespace sbot
