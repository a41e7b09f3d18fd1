// Placing robots in the world: the checks on a position, a new robot set down onto the terrain
// under its outline, and the overlap tests behind placeRobot and robotsOverlapProblem.
#include "sbot_sim/core/world.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "world_internal.h"

namespace sbot {

std::string positionProblem(const Vec3& p) {
  if (p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate) return "";
  std::ostringstream msg;
  msg << "position (" << p.x() << ", " << p.y() << ", " << p.z() << ") m is outside the simulated space (every "
      << "coordinate finite and within +-" << kMaxCoordinate << " m)";
  return msg.str();
}

namespace {

/// Points (x, y) under a collision geom's own outline: a box's eight corners, a sphere's or a
/// cylinder's rim (eight points a circle, at each end of a cylinder), and the centre. Its axis-aligned
/// box reached further: a robot 2 cm clear of a wall at 45 deg had a corner of it over the wall and
/// was spawned on the wall's height, 10 cm up. Other classes: the corners of that box.
std::vector<std::pair<double, double>> footprintOf(dGeomID g) {
  const dReal* c = dGeomGetPosition(g);
  const dReal* R = dGeomGetRotation(g);  // 3x4, row-major
  auto world = [&](double x, double y, double z) {
    return std::pair<double, double>(c[0] + R[0] * x + R[1] * y + R[2] * z, c[1] + R[4] * x + R[5] * y + R[6] * z);
  };
  std::vector<std::pair<double, double>> out{{c[0], c[1]}};
  // Eight points of a circle about the geom's z axis at height z in its frame.
  auto rim = [&](double radius, double z) {
    for (int k = 0; k < 8; ++k) out.push_back(world(radius * std::cos(k * M_PI / 4), radius * std::sin(k * M_PI / 4), z));
  };
  switch (dGeomGetClass(g)) {
    case dBoxClass: {
      dVector3 size;
      dGeomBoxGetLengths(g, size);
      for (int sx : {-1, 1})
        for (int sy : {-1, 1})
          for (int sz : {-1, 1}) out.push_back(world(sx * size[0] / 2, sy * size[1] / 2, sz * size[2] / 2));
      break;
    }
    case dSphereClass:
      rim(dGeomSphereGetRadius(g), 0);
      break;
    case dCylinderClass: {
      dReal radius, length;
      dGeomCylinderGetParams(g, &radius, &length);
      rim(radius, -length / 2);
      rim(radius, length / 2);
      break;
    }
    default: {
      dReal aabb[6];
      dGeomGetAABB(g, aabb);
      for (double x : {aabb[0], aabb[1]})
        for (double y : {aabb[2], aabb[3]}) out.push_back({x, y});
    }
  }
  return out;
}

}  // namespace

Robot& World::addRobot(const RobotDescription& description, const Pose2D& pose, const std::string& name) {
  Robot& r = addRobotAt(description, Pose(Vec3(pose.x, pose.y, 0), quatFromRPY(0, 0, pose.yaw)), name);
  // Drop it onto the terrain: lowest collision point 1 mm above the highest ground below the robot.
  double lowest = std::numeric_limits<double>::infinity();
  double ground = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < dSpaceGetNumGeoms(r.space()); ++i) {
    const dGeomID g = dSpaceGetGeom(r.space(), i);
    dReal aabb[6];
    dGeomGetAABB(g, aabb);
    lowest = std::min(lowest, static_cast<double>(aabb[4]));
    for (const auto& [x, y] : footprintOf(g)) ground = std::max(ground, terrainHeight(x, y));
  }
  ground = std::max(ground, terrainHeight(pose.x, pose.y));
  Pose p = r.basePose();
  p.position.z() += ground - lowest + 0.001;
  r.setBasePose(p);
  return r;
}

namespace {

struct OverlapQuery {
  const Robot* robot;
  World::Overlap* deepest;
};

void overlapCallback(void* data, dGeomID o1, dGeomID o2) {
  auto& q = *static_cast<OverlapQuery*>(data);
  if (o1 == o2) return;  // the robot's own space, met inside the world's
  if (dGeomIsSpace(o1) || dGeomIsSpace(o2)) {
    dSpaceCollide2(o1, o2, data, &overlapCallback);
    return;
  }
  const GeomInfo *a = infoOf(o1), *b = infoOf(o2);
  const bool a_own = a && a->robot == q.robot, b_own = b && b->robot == q.robot;
  if (a_own == b_own) return;  // two of its own geoms (its joints decide), or neither
  dContactGeom c[4];
  const int n = dCollide(o1, o2, 4, c, sizeof(dContactGeom));
  const GeomInfo* other = a_own ? b : a;
  for (int i = 0; i < n; ++i) {
    if (c[i].depth <= q.deepest->depth) continue;
    q.deepest->depth = c[i].depth;
    if (other && other->robot) q.deepest->with = "robot '" + other->robot->name() + "'";
    else if (other && other->material != kGround) q.deepest->with = "box '" + other->link + "'";
    else q.deepest->with = "the ground";
  }
}

}  // namespace

World::Overlap World::deepestOverlap(const Robot& robot, bool robots_only) const {
  Overlap deepest;
  OverlapQuery q{&robot, &deepest};
  const dGeomID own = reinterpret_cast<dGeomID>(robot.space());
  if (!robots_only) dSpaceCollide2(own, reinterpret_cast<dGeomID>(static_space_), &q, &overlapCallback);
  dSpaceCollide2(own, reinterpret_cast<dGeomID>(space_), &q, &overlapCallback);
  return deepest;
}

std::string World::robotsOverlapProblem() const {
  for (const auto& r : robots_) {
    const Overlap o = deepestOverlap(*r, true);
    if (o.depth <= kPlacementTolerance) continue;
    std::ostringstream why;
    why << "robot '" << r->name() << "' and " << o.with << " overlap by " << std::fixed << std::setprecision(3)
        << o.depth << " m at their start poses (at most " << kPlacementTolerance << " m)";
    return why.str();
  }
  return "";
}

std::string World::placeRobot(Robot& robot, const Pose& pose) {
  const std::vector<Robot::BodyState> before = robot.bodyStates();
  robot.setBasePose(pose);
  const Overlap o = deepestOverlap(robot);
  if (o.depth <= kPlacementTolerance) return "";
  robot.setBodyStates(before);
  std::ostringstream why;
  why << "robot '" << robot.name() << "' there would sit " << std::fixed << std::setprecision(3) << o.depth
      << " m deep inside " << o.with << " (at most " << kPlacementTolerance << " m): not moved";
  return why.str();
}

}  // namespace sbot
