// World's terrain: the static geoms (ground plane, boxes, the rough height field) in their own
// space, the index of their bounding boxes, and the height of the terrain under a point.
#include "sbot_sim/core/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/terrain.h"
#include "world_internal.h"

namespace sbot {

void World::buildTerrain() {
  const TerrainConfig& t = config_.terrain;
  for (const auto& box : t.boxes) {
    std::string problem = positionProblem(box.center);
    if (problem.empty()) problem = positionProblem(box.size);
    // A box without volume is degenerate for ODE's collision tests (an assertion, not an error).
    if (problem.empty()) problem = boxSizeProblem(box.size);
    if (!problem.empty()) throw ConfigError("<world>", "terrain.boxes (" + box.name + ")", problem);
  }
  if (t.type == TerrainConfig::Type::Rough) {
    const std::string problem = positionProblem(Vec3(t.size_x, t.size_y, t.height_range));
    if (!problem.empty()) throw ConfigError("<world>", "terrain (size, height_range)", problem);
  }
  auto addStatic = [this](dGeomID g, const std::string& material, const std::string& name) {
    dGeomSetData(g, new GeomInfo{nullptr, material, name});
    static_geoms_.push_back(g);
  };
  if (t.type != TerrainConfig::Type::Rough && t.ground_plane) {
    addStatic(dCreatePlane(static_space_, 0, 0, 1, 0), kGround, "ground_plane");
  }
  for (const auto& box : t.boxes) {
    dGeomID g = dCreateBox(static_space_, box.size.x(), box.size.y(), box.size.z());
    dGeomSetPosition(g, box.center.x(), box.center.y(), box.center.z());
    const Quat q = quatFromRPY(0, box.pitch, box.yaw);
    dQuaternion oq{q.w(), q.x(), q.y(), q.z()};
    dGeomSetQuaternion(g, oq);
    addStatic(g, box.surface, box.name);
  }
  if (t.type == TerrainConfig::Type::Rough) {
    HeightMap map = makeHeightMap(t);
    heightfield_ = map.heights;
    heightfield_data_ = dGeomHeightfieldDataCreate();
    // ODE height fields are y-up; the geom is rotated so that its y axis is world z (see terrain.h).
    dGeomHeightfieldDataBuildDouble(heightfield_data_, heightfield_.data(), 0, t.size_x, t.size_y,
                                    map.cols, map.rows, 1.0, 0.0, 1.0, 0);
    const double lo = *std::min_element(heightfield_.begin(), heightfield_.end());
    const double hi = *std::max_element(heightfield_.begin(), heightfield_.end());
    dGeomHeightfieldDataSetBounds(heightfield_data_, lo - 0.01, hi + 0.01);
    dGeomID g = dCreateHeightfield(static_space_, heightfield_data_, 1);
    dMatrix3 R;
    dRFromAxisAndAngle(R, 1, 0, 0, M_PI / 2);
    dGeomSetRotation(g, R);
    addStatic(g, kGround, "rough_terrain");
  }
}

void World::indexTerrain() { readBoxedGeoms(static_space_, terrain_index_); }

double World::terrainHeight(double x, double y) const {
  // Cast down against static geometry only: handles planes, tilted boxes and height fields alike.
  double best = config_.terrain.type == TerrainConfig::Type::Rough || !config_.terrain.ground_plane
                    ? -std::numeric_limits<double>::infinity()
                    : 0.0;
  constexpr double kTop = 100.0;
  dGeomID ray = queryRay(2 * kTop);
  dGeomRaySet(ray, x, y, kTop, 0, 0, -1);
  // Through the static space: its bounding-box test skips the geoms not under (x, y) (a composite
  // course has hundreds of boxes; testing each was 10 % of a model-switching run).
  struct Highest {
    double top, best;
  } q{kTop, best};
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(static_space_), &q, [](void* data, dGeomID a, dGeomID b) {
    auto& h = *static_cast<Highest*>(data);
    dContactGeom c;
    if (dCollide(a, b, 1, &c, sizeof(c)) == 1) h.best = std::max(h.best, h.top - c.depth);
  });
  best = q.best;
  return std::isfinite(best) ? best : 0.0;
}

}  // namespace sbot
