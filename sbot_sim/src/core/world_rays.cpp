// World's ray queries: castRay, castRays, castRayBundles and castRaysOfLengths, with the spatial
// index they share (one broad-phase search for the box around a bundle, then each ray against the
// candidate geoms whose boxes its segment meets; for lines of sight of many lengths, the candidates
// filed by bearing sector).
#include "sbot_sim/core/world.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "world_internal.h"

namespace sbot {
namespace {

struct RayQuery {
  const Robot* ignore;
  RayHit* best;
};

// Test the ray against one geom and keep the nearest hit.
void rayAgainstGeom(RayQuery& q, dGeomID ray, dGeomID other) {
  const GeomInfo* gi = infoOf(other);
  if (gi && q.ignore && gi->robot == q.ignore) return;  // a sensor does not see its own robot
  dContactGeom c;
  if (dCollide(ray, other, 1, &c, sizeof(c)) != 1 || c.depth >= q.best->distance) return;
  RayHit& b = *q.best;
  b.hit = true;
  b.distance = c.depth;
  b.point = Vec3(c.pos[0], c.pos[1], c.pos[2]);
  b.normal = Vec3(c.normal[0], c.normal[1], c.normal[2]);
  b.surface = gi ? gi->material : kGround;
  b.robot = gi ? gi->robot : nullptr;
}

// The query walks of castRay and castRays: when (o1, o2) involves a robot's space, descend into it
// with `callback` unless it is the ignored robot's (skips its ~20 geoms at once) and return true.
bool descendIntoSpace(void* data, dGeomID o1, dGeomID o2, const Robot* ignore, dNearCallback* callback) {
  if (!dGeomIsSpace(o1) && !dGeomIsSpace(o2)) return false;
  const dGeomID sub = dGeomIsSpace(o1) ? o1 : o2;
  if (!ignore || sub != reinterpret_cast<dGeomID>(ignore->space())) dSpaceCollide2(o1, o2, data, callback);
  return true;
}

void rayCallback(void* data, dGeomID o1, dGeomID o2) {
  auto& q = *static_cast<RayQuery*>(data);
  if (descendIntoSpace(data, o1, o2, q.ignore, &rayCallback)) return;
  const bool first_is_ray = dGeomGetClass(o1) == dRayClass;
  rayAgainstGeom(q, first_is_ray ? o1 : o2, first_is_ray ? o2 : o1);
}

}  // namespace

dGeomID World::queryRay(double length) const {
  if (!query_ray_) {
    query_ray_ = dCreateRay(nullptr, length);
    dGeomRaySetClosestHit(query_ray_, 1);
  }
  dGeomRaySetLength(query_ray_, length);
  return query_ray_;
}

RayHit World::castRay(const Vec3& origin, const Vec3& direction, double length, const Robot* ignore) const {
  RayHit best;
  best.distance = length;
  dGeomID ray = queryRay(length);
  const Vec3 d = direction.normalized();
  dGeomRaySet(ray, origin.x(), origin.y(), origin.z(), d.x(), d.y(), d.z());
  RayQuery query{ignore, &best};
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(space_), &query, &rayCallback);
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(static_space_), &query, &rayCallback);
  return best;
}

namespace {

struct BoxQuery {
  dGeomID box;
  const Robot* ignore;
  std::vector<World::BoxedGeom>* found;
};

/// Whether the segment from `origin` to `end` has a bounding box that meets `aabb` (ODE's layout).
/// An axis-aligned ground plane's box is the half space below it, so the proximity ring's level
/// rays skip it (most of a flat-ground ring's ray tests, each a dGeomRaySet and a dCollide).
bool segmentMayMeet(const Vec3& origin, const Vec3& end, const dReal* aabb) {
  dReal segment[6];
  for (int k = 0; k < 3; ++k) {
    segment[2 * k] = std::min(origin[k], end[k]);
    segment[2 * k + 1] = std::max(origin[k], end[k]);
  }
  return boxesMeet(segment, aabb);
}

// Collect the geoms whose bounding boxes meet the query box.
void boxCallback(void* data, dGeomID o1, dGeomID o2) {
  auto& q = *static_cast<BoxQuery*>(data);
  if (descendIntoSpace(data, o1, o2, q.ignore, &boxCallback)) return;
  const dGeomID other = o1 == q.box ? o2 : o1;
  const GeomInfo* gi = infoOf(other);
  if (gi && q.ignore && gi->robot == q.ignore) return;
  World::BoxedGeom c;
  c.geom = other;
  dGeomGetAABB(other, c.aabb);
  q.found->push_back(c);
}

/// Grows [lo, hi] to hold the segments of the n unit `directions` from `origin`, `length` long.
void growRayBounds(const Vec3& origin, const Vec3* directions, std::size_t n, double length, Vec3& lo, Vec3& hi) {
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 end = origin + directions[i] * length;
    lo = lo.cwiseMin(origin).cwiseMin(end);
    hi = hi.cwiseMax(origin).cwiseMax(end);
  }
}

}  // namespace

const Vec3* World::unitDirections(const std::vector<Vec3>& directions) const {
  ray_units_.resize(directions.size());
  for (std::size_t i = 0; i < directions.size(); ++i) ray_units_[i] = directions[i].normalized();
  return ray_units_.data();
}

void World::findRayCandidates(const Vec3& lo, const Vec3& hi, const Robot* ignore) const {
  constexpr double kMargin = 1e-6;  // [m] keeps the box's sides from vanishing (axis-aligned rays)
  if (!query_box_) query_box_ = dCreateBox(nullptr, 1, 1, 1);
  const Vec3 centre = 0.5 * (lo + hi), size = (hi - lo).array() + 2 * kMargin;
  dGeomBoxSetLengths(query_box_, size.x(), size.y(), size.z());
  dGeomSetPosition(query_box_, centre.x(), centre.y(), centre.z());
  ray_candidates_.clear();
  BoxQuery box{query_box_, ignore, &ray_candidates_};
  dSpaceCollide2(query_box_, reinterpret_cast<dGeomID>(space_), &box, &boxCallback);
  dSpaceCollide2(query_box_, reinterpret_cast<dGeomID>(static_space_), &box, &boxCallback);
}

void World::castAgainstCandidates(const Vec3& origin, const Vec3* directions, std::size_t n, double length,
                                  const Robot* ignore, RayHit* hits) const {
  RayHit miss;
  miss.distance = length;
  std::fill(hits, hits + n, miss);
  if (ray_candidates_.empty()) return;
  dGeomID ray = queryRay(length);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& d = directions[i];
    const Vec3 end = origin + d * length;
    bool ray_set = false;
    RayQuery query{ignore, &hits[i]};
    for (const BoxedGeom& c : ray_candidates_) {
      if (!segmentMayMeet(origin, end, c.aabb)) continue;
      if (!ray_set) dGeomRaySet(ray, origin.x(), origin.y(), origin.z(), d.x(), d.y(), d.z());
      ray_set = true;
      rayAgainstGeom(query, ray, c.geom);
    }
  }
}

// One broad-phase search for the box around every ray's segment instead of one per ray (for a
// sensor's 5-ray cone that was most of the cost of a ray: ODE's space traversal) or per bundle (a
// 15-sensor ring); a ray can only hit a geom whose bounding box meets its segment's, so the hits
// are castRay's.
std::vector<RayHit> World::castRays(const Vec3& origin, const std::vector<Vec3>& directions, double length,
                                    const Robot* ignore) const {
  const Vec3* units = unitDirections(directions);
  Vec3 lo = origin, hi = origin;
  growRayBounds(origin, units, directions.size(), length, lo, hi);
  if (directions.empty()) ray_candidates_.clear();
  else findRayCandidates(lo, hi, ignore);
  std::vector<RayHit> hits(directions.size());
  castAgainstCandidates(origin, units, directions.size(), length, ignore, hits.data());
  return hits;
}

std::vector<RayHit> World::castRayBundles(const std::vector<Vec3>& origins, const std::vector<Vec3>& directions,
                                          double length, const Robot* ignore) const {
  if (origins.empty() ? !directions.empty() : directions.size() % origins.size() != 0)
    throw std::invalid_argument("castRayBundles: " + std::to_string(directions.size()) +
                                " directions do not make equal bundles for " + std::to_string(origins.size()) +
                                " origins");
  std::vector<RayHit> hits(directions.size());
  if (origins.empty()) return hits;
  const std::size_t n = directions.size() / origins.size();
  const Vec3* units = unitDirections(directions);
  Vec3 lo = origins.front(), hi = origins.front();
  for (std::size_t k = 0; k < origins.size(); ++k) growRayBounds(origins[k], units + k * n, n, length, lo, hi);
  findRayCandidates(lo, hi, ignore);
  for (std::size_t k = 0; k < origins.size(); ++k)
    castAgainstCandidates(origins[k], units + k * n, n, length, ignore, &hits[k * n]);
  return hits;
}

namespace {

/// Whether the segment from `origin` along unit `d`, `length` long, crosses `aabb` (ODE's layout;
/// the slab test). Unlike segmentMayMeet's box against box, a long diagonal segment misses most of
/// the boxes its own box covers.
bool segmentCrosses(const Vec3& origin, const Vec3& d, double length, const dReal* aabb) {
  constexpr double kSlack = 1e-9;  // [m] a ray grazing a box's face is tested, as ODE would
  double t0 = 0, t1 = length;
  for (int k = 0; k < 3; ++k) {
    const double lo = aabb[2 * k] - kSlack, hi = aabb[2 * k + 1] + kSlack;
    if (std::abs(d[k]) < 1e-12) {
      if (origin[k] < lo || origin[k] > hi) return false;
      continue;
    }
    double ta = (lo - origin[k]) / d[k], tb = (hi - origin[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

/// A stand-in for atan2(dy, dx) that needs no trigonometry (the "diamond angle"), in (-2, 2]: 0
/// along +x, +-1 along +-y, 2 along -x. It grows with the bearing, and turning half a turn adds 2,
/// which is all the sectors below need (they are then up to 2x wider in angle at the diagonals).
double diamondBearing(double dx, double dy) {
  const double sum = std::abs(dx) + std::abs(dy);
  if (sum == 0) return 0;
  const double t = dy / sum;  // [-1, 1]
  return dx >= 0 ? t : (dy >= 0 ? 2 - t : -2 - t);
}

/// castRaysOfLengths' groups filed by the bearing sectors (of kSectors about the origin, equal in
/// diamondBearing) their boxes cover; `of[k]` lists the groups a ray of sector k may cross, nearest
/// box first.
struct SectorIndex {
  static constexpr int kSectors = 64;
  static constexpr double kTurn = 4;  ///< a full turn in diamondBearing
  std::vector<std::vector<std::size_t>> of;
  std::vector<std::size_t> all;  ///< every group (for rays with no bearing), nearest box first
  std::vector<double> near;      ///< [m] each group's box's distance from the origin (0: around it)
  int sectorOf(const Vec3& d) const { return sectorOfBearing(diamondBearing(d.x(), d.y())); }
  static int sectorOfBearing(double bearing) {
    const int k = static_cast<int>(std::floor((bearing + kTurn / 2) / kTurn * kSectors));
    return ((k % kSectors) + kSectors) % kSectors;
  }
};

template <class Group>
SectorIndex fileBySector(const Vec3& origin, const std::vector<Group>& groups) {
  constexpr double kMargin = 1e-6;  // bearings at a sector's edge are filed on both sides
  SectorIndex index;
  index.of.resize(SectorIndex::kSectors);
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    index.all.push_back(gi);
    const dReal* b = groups[gi].aabb;
    double near2 = 0;  // (an unbounded side adds nothing: max(-inf, 0) = 0)
    for (int k = 0; k < 3; ++k) {
      const double outside = std::max({b[2 * k] - origin[k], 0.0, origin[k] - b[2 * k + 1]});
      near2 += outside * outside;
    }
    // A box with NaN bounds (none is known) would break the sort below: it goes first instead.
    index.near.push_back(std::isfinite(near2) ? std::sqrt(near2) : 0.0);
    const bool around = origin.x() >= b[0] && origin.x() <= b[1] && origin.y() >= b[2] && origin.y() <= b[3];
    if (around || !std::isfinite(b[0] + b[1] + b[2] + b[3])) {  // seen from inside, or unbounded (a plane)
      for (auto& sector : index.of) sector.push_back(gi);
      continue;
    }
    // A box that does not hold the origin spans less than half a turn: its corners' bearings about
    // the bearing of its centre give the interval.
    const double centre = diamondBearing(0.5 * (b[0] + b[1]) - origin.x(), 0.5 * (b[2] + b[3]) - origin.y());
    double lo = 0, hi = 0;
    for (int cx = 0; cx < 2; ++cx)
      for (int cy = 2; cy < 4; ++cy) {
        const double rel =
            std::remainder(diamondBearing(b[cx] - origin.x(), b[cy] - origin.y()) - centre, SectorIndex::kTurn);
        lo = std::min(lo, rel);
        hi = std::max(hi, rel);
      }
    const int first = SectorIndex::sectorOfBearing(centre + lo - kMargin);
    const int span = SectorIndex::sectorOfBearing(centre + hi + kMargin) - first;
    const int count = (span + SectorIndex::kSectors) % SectorIndex::kSectors + 1;
    for (int k = 0; k < count; ++k) index.of[(first + k) % SectorIndex::kSectors].push_back(gi);
  }
  auto nearestFirst = [&](std::size_t a, std::size_t b) { return index.near[a] < index.near[b]; };
  for (auto& sector : index.of) std::stable_sort(sector.begin(), sector.end(), nearestFirst);
  std::stable_sort(index.all.begin(), index.all.end(), nearestFirst);
  return index;
}

}  // namespace

std::vector<RayHit> World::castRaysOfLengths(const Vec3& origin, const std::vector<Vec3>& directions,
                                             const std::vector<double>& lengths, const Robot* ignore) const {
  if (directions.size() != lengths.size())
    throw std::invalid_argument("castRaysOfLengths: " + std::to_string(directions.size()) + " directions but " +
                                std::to_string(lengths.size()) + " lengths");
  std::vector<RayHit> hits(directions.size());
  for (std::size_t i = 0; i < hits.size(); ++i) hits[i].distance = lengths[i];
  if (directions.empty()) return hits;
  const Vec3* units = unitDirections(directions);
  Vec3 lo = origin, hi = origin;
  for (std::size_t i = 0; i < directions.size(); ++i) growRayBounds(origin, units + i, 1, lengths[i], lo, hi);
  findRayCandidates(lo, hi, ignore);
  // Runs of one robot's geoms (the search descends into a robot's space and lists its geoms
  // together), each with the box around them.
  candidate_groups_.clear();
  for (std::size_t i = 0; i < ray_candidates_.size(); ++i) {
    const GeomInfo* gi = infoOf(ray_candidates_[i].geom);
    const Robot* robot = gi ? gi->robot : nullptr;
    const GeomInfo* prev = i > 0 ? infoOf(ray_candidates_[i - 1].geom) : nullptr;
    const bool extends = i > 0 && robot && prev && prev->robot == robot;
    if (!extends) {
      CandidateGroup g{i, i, {}};
      std::copy(ray_candidates_[i].aabb, ray_candidates_[i].aabb + 6, g.aabb);
      candidate_groups_.push_back(g);
    }
    CandidateGroup& g = candidate_groups_.back();
    g.end = i + 1;
    for (int k = 0; k < 3; ++k) {
      g.aabb[2 * k] = std::min(g.aabb[2 * k], ray_candidates_[i].aabb[2 * k]);
      g.aabb[2 * k + 1] = std::max(g.aabb[2 * k + 1], ray_candidates_[i].aabb[2 * k + 1]);
    }
  }
  // Every ray leaves the same origin, so a group's box can only be crossed by the rays whose
  // bearing (azimuth about the origin) lies within the bearings of its corners: the groups are
  // filed by bearing sector, and a ray tests its own sector's (a group whose box holds the origin
  // in plan, or has no bounds, such as a ground plane, is filed in every sector).
  const SectorIndex sectors = fileBySector(origin, candidate_groups_);
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const Vec3& d = units[i];
    if (!(lengths[i] > 0)) continue;
    dGeomID ray = nullptr;
    RayQuery query{ignore, &hits[i]};
    const bool steep = d.x() * d.x() + d.y() * d.y() < 1e-18;  // no bearing: test every group
    const std::vector<std::size_t>& filed = steep ? sectors.all : sectors.of[sectors.sectorOf(d)];
    for (std::size_t gi : filed) {
      // Nearest box first: once a box lies beyond the nearest hit so far (at first, the line's
      // end), so do all the others, and nothing in them can be nearer.
      const double reach = hits[i].distance;
      if (sectors.near[gi] >= reach) break;
      const CandidateGroup& g = candidate_groups_[gi];
      if (!segmentCrosses(origin, d, reach, g.aabb)) continue;
      for (std::size_t c = g.begin; c < g.end; ++c) {
        if (g.end - g.begin > 1 && !segmentCrosses(origin, d, hits[i].distance, ray_candidates_[c].aabb)) continue;
        if (!ray) {
          ray = queryRay(lengths[i]);
          dGeomRaySet(ray, origin.x(), origin.y(), origin.z(), d.x(), d.y(), d.z());
        }
        rayAgainstGeom(query, ray, ray_candidates_[c].geom);
      }
    }
  }
  return hits;
}

}  // namespace sbot
