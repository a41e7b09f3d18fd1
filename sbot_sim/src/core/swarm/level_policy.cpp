#include "sbot_sim/core/swarm/level_policy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace sbot {
namespace swarm {

namespace {

// Features of one line of height samples h[i] at spacing ds.
void measureLine(const std::vector<double>& h, double ds, const LevelPolicyConfig& c, TerrainFeatures& f) {
  const int n = static_cast<int>(h.size());
  std::vector<bool> in_gap(n, false);
  if (n < 2) return;
  // Gaps: a run of samples more than gap_depth below the rim before it, ending where the surface
  // comes back to the rim's height. A drop whose far side is beyond the line's end (the look-ahead
  // sees the near edge only) is a gap at least as wide as what is seen; so is a low run at the start
  // (the robot is over a gap it is leaving). A real step down (no far rim) thus reads as a gap
  // growing with the look-ahead: wider than small_gap_max, it needs the detailed level as well.
  auto mark = [&](int from, int to) {
    f.gap = std::max(f.gap, (to - from) * ds);
    for (int k = from; k < to; ++k) in_gap[k] = true;
  };
  {
    int j = 1;
    while (j < n && !(h[j] > h[j - 1] + c.gap_depth)) ++j;
    // Leading low run: everything before a rise, if the line's start is below the rise's top.
    if (j < n) {
      bool all_low = true;
      for (int i = 0; i < j; ++i) all_low &= h[i] < h[j] - c.gap_depth;
      if (all_low) mark(0, j);
    }
  }
  for (int i = 1; i < n; ++i) {
    if (in_gap[i] || !(h[i] < h[i - 1] - c.gap_depth)) continue;
    const double rim_before = h[i - 1];
    int j = i;
    while (j < n && h[j] < rim_before - c.gap_depth) ++j;
    mark(i, j);
    i = j;
  }
  for (int i = 1; i < n; ++i)
    if (!in_gap[i] && !in_gap[i - 1]) f.step = std::max(f.step, std::abs(h[i] - h[i - 1]));
  const int w = std::max(3, static_cast<int>(std::round(c.slope_window / ds)));
  for (int s = 0; s + w <= n; s += std::max(1, w / 2)) {
    bool clean = true;
    for (int k = s; k < s + w; ++k) clean &= !in_gap[k];
    if (!clean) continue;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int k = 0; k < w; ++k) {
      const double x = k * ds, y = h[s + k];
      sx += x; sy += y; sxx += x * x; sxy += x * y;
    }
    const double den = w * sxx - sx * sx;
    const double b = den > 0 ? (w * sxy - sx * sy) / den : 0;
    const double a = (sy - b * sx) / w;
    double var = 0;
    for (int k = 0; k < w; ++k) {
      const double r = h[s + k] - (a + b * k * ds);
      var += r * r;
    }
    f.slope = std::max(f.slope, std::atan(std::abs(b)));
    f.roughness = std::max(f.roughness, std::sqrt(var / w));
  }
}

}  // namespace

double HeightCache::operator()(double x, double y) {
  const auto ix = static_cast<std::int64_t>(std::llround(x / res_));
  const auto iy = static_cast<std::int64_t>(std::llround(y / res_));
  const std::uint64_t key = (static_cast<std::uint64_t>(ix) << 32) ^ (static_cast<std::uint64_t>(iy) & 0xffffffffu);
  auto it = cells_.find(key);
  if (it != cells_.end()) return it->second;
  const double h = height_(ix * res_, iy * res_);
  cells_.emplace(key, h);
  return h;
}

TerrainFeatures measureTerrain(const HeightFunction& height, const Pose2D& pose, const LevelPolicyConfig& c) {
  TerrainFeatures f;
  const double cy = std::cos(pose.yaw), sy = std::sin(pose.yaw);
  const int n = std::max(2, static_cast<int>(std::round((c.lookahead + c.lookbehind) / c.sample)) + 1);
  std::vector<double> h(n);
  for (double lateral : {0.0, c.half_width, -c.half_width}) {
    for (int i = 0; i < n; ++i) {
      const double s = -c.lookbehind + i * c.sample;
      h[i] = height(pose.x + s * cy - lateral * sy, pose.y + s * sy + lateral * cy);
    }
    measureLine(h, c.sample, c, f);
  }
  return f;
}

int requiredTier(const TerrainFeatures& f, const LevelPolicyConfig& c) {
  if (f.gap > c.small_gap_max || f.roughness > c.rough_detailed || f.step > c.step_detailed ||
      f.slope > c.slope_detailed)
    return 2;
  if (f.gap > 0 || f.roughness > c.rough_medium || f.step > c.step_medium || f.slope > c.slope_medium) return 1;
  return 0;
}

std::string describe(const TerrainFeatures& f) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "gap %.0f mm, step %.1f mm, slope %.1f deg, roughness %.2f mm", f.gap * 1000,
                f.step * 1000, f.slope * 180 / M_PI, f.roughness * 1000);
  return buf;
}

const std::string& LevelPolicy::levelOfTier(int tier) const {
  return tier >= 2 ? config_.detailed_level : tier == 1 ? config_.medium_level : config_.flat_level;
}

std::string LevelPolicy::decide(const std::string& robot, double t, const HeightFunction& height,
                                const Pose2D& pose, bool gripping) {
  return decide(robot, t, measureTerrain(height, pose, config_), gripping);
}

std::string LevelPolicy::decide(const std::string& robot, double t, const TerrainFeatures& f, bool gripping) {
  State& s = robots_[robot];
  s.last = f;
  if (!s.override_level.empty()) return s.override_level;
  const int need = gripping ? 2 : requiredTier(f, config_);
  if (need >= s.tier) {
    s.tier = need;
    s.lower_since = -1;
  } else {
    if (s.lower_since < 0) s.lower_since = t;
    if (t - s.lower_since >= config_.demote_delay - 1e-9) {
      s.tier = need;
      s.lower_since = -1;
    }
  }
  return levelOfTier(s.tier);
}

void LevelPolicy::setOverride(const std::string& robot, const std::string& level) {
  robots_[robot].override_level = level;
}

std::string LevelPolicy::overrideOf(const std::string& robot) const {
  auto it = robots_.find(robot);
  return it == robots_.end() ? std::string() : it->second.override_level;
}

TerrainFeatures LevelPolicy::lastFeatures(const std::string& robot) const {
  auto it = robots_.find(robot);
  return it == robots_.end() ? TerrainFeatures() : it->second.last;
}

}  // namespace swarm
}  // namespace sbot
