#include "sbot_sim/core/swarm/swarm_graph.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace swarm {

int SwarmGraph::indexOf(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {

struct UnionFind {
  std::vector<std::size_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

SwarmGraph computeSwarmGraph(World& world) {
  SwarmGraph g;
  g.time = world.time();
  const std::vector<Robot*> robots = world.robots();
  g.n = robots.size();
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const Pose p = robots[i]->basePose();
    g.names.push_back(robots[i]->name());
    g.positions.push_back(p.position);
    g.headings.push_back(p.yaw());
    index[robots[i]->name()] = i;
  }
  g.connections.assign(g.n * g.n, kNone);
  UnionFind uf(g.n);
  for (const Connection& c : world.connections().list()) {
    auto a = index.find(c.holder), b = index.find(c.held);
    if (a == index.end() || b == index.end() || a->second == b->second) continue;
    std::uint8_t& cell = g.connections[a->second * g.n + b->second];
    // A robot gripping another with both its gripper and its arm: the front gripper (rigid) wins.
    const std::uint8_t kind = c.kind == Connection::SideArm ? kSideArm : kFrontGripper;
    cell = cell == kNone ? kind : std::min(cell, kind);
    uf.join(a->second, b->second);
  }
  std::map<std::size_t, std::uint32_t> ids;
  g.component.resize(g.n);
  for (std::size_t i = 0; i < g.n; ++i) {
    const std::size_t root = uf.find(i);
    auto it = ids.find(root);
    if (it == ids.end()) it = ids.emplace(root, static_cast<std::uint32_t>(ids.size())).first;
    g.component[i] = it->second;
  }
  g.components = ids.size();
  return g;
}

std::uint8_t parseLinkKind(const std::string& text, const std::string& file, const std::string& field) {
  if (text == "front_gripper" || text == "1") return kFrontGripper;
  if (text == "side_arm" || text == "2") return kSideArm;
  throw ConfigError(file, field, "expected front_gripper or side_arm, found '" + text + "'");
}

double turretRingRadius(const World& world, const std::string& robot) {
  const Robot* r = const_cast<World&>(world).findRobot(robot);
  if (!r) throw UnknownName("unknown robot '" + robot + "'");
  double radius = 0;
  if (const LinkDescription* l = r->description().findLink("turret"))
    for (const auto& s : l->collisions)
      if (s.type != CollisionShape::Type::Box) radius = std::max(radius, s.radius);
  return radius > 0 ? radius : 0.057 * (r->description().totalMass() < 0.1 ? 0.5 : 1.0);
}

int createStaticLink(World& world, const LinkSpec& link, bool place) {
  Robot& holder = world.robot(link.holder);
  Robot& held = world.robot(link.held);
  if (link.holder == link.held) throw ConfigError("<world>", "links", "a robot cannot grip itself (" + link.holder + ")");
  const std::string grip_link = holder.hasLink("gripper_tip") ? "gripper_tip" : "turret";
  if (place) {
    // Robots already connected to `held` move with it (chains declared in any order); if the
    // holder is among them the link closes a loop and nothing is moved.
    const SwarmGraph g = computeSwarmGraph(world);
    const int ih = g.indexOf(link.holder), id = g.indexOf(link.held);
    if (g.component[ih] != g.component[id]) {
      const Pose tip = holder.linkPose(grip_link);
      const Vec3 axis = holder.linkPose("turret").position;
      Vec3 dir = tip.position - axis;
      dir.z() = 0;
      if (dir.norm() < 1e-6) dir = holder.basePose().orientation * Vec3::UnitX();
      dir.normalize();
      const Pose held_base = held.basePose();
      const Vec3 held_turret = held.linkPose("turret").position;
      // Put held's turret axis r_ring beyond the tip, at the holder's height.
      Vec3 target = tip.position + turretRingRadius(world, link.held) * dir;
      const Vec3 offset_xy(held_turret.x() - held_base.position.x(), held_turret.y() - held_base.position.y(), 0);
      Vec3 base_target = target - offset_xy;
      base_target.z() = holder.basePose().position.z();
      const Vec3 shift = base_target - held_base.position;
      for (std::size_t i = 0; i < g.n; ++i) {
        if (g.component[i] != g.component[id]) continue;
        Robot& r = world.robot(g.names[i]);
        Pose p = r.basePose();
        p.position += shift;
        r.setBasePose(p);
      }
    }
  }
  dBodyID hb = holder.linkBody(grip_link);
  dBodyID tb = held.linkBody("turret");
  if (!tb) tb = held.baseBody();
  return world.connections().connect(link.holder, hb, link.held, tb,
                                     link.kind == kSideArm ? Connection::SideArm : Connection::FrontGripper);
}

void addScenarioLinks(World& world, const std::vector<LinkSpawn>& links) {
  for (const auto& l : links)
    createStaticLink(world, LinkSpec{l.holder, l.held, static_cast<std::uint8_t>(l.kind)}, true);
}

}  // namespace swarm
}  // namespace sbot
