// Which model level a robot needs for the terrain ahead of it (seed 4.3, dynamic model switching):
// "The simulation starts with the Basic model on a flat plane. As soon as a harder terrain is
// encountered (smaller gaps up to 5 cm, a slope, or medium rough terrain), the representation is
// switched to the Medium model. When also this one is not sufficient anymore (gaps larger than 5 cm,
// or very rough terrain situations), the Detailed model description is then used. As soon as a
// smooth plane is detected again, the simulator switches back to the Basic model."
//
// The policy samples the terrain height along the robot's heading, from `lookbehind` behind
// base_link (the part still under the robot) to `lookahead` in front, on three lines (centre and
// +-half_width: the tracks), every `sample` metres, and measures on them:
//   gap        a run of samples more than gap_depth below the rim before it: its width (a drop
//              whose far rim is not in view counts with the width seen)
//   step       the largest height change between neighbouring samples outside gaps
//   slope      the steepest least-squares incline over slope_window outside gaps
//   roughness  the largest standard deviation of heights about that incline, same windows
// Tier 2 (detailed_level) if gap > small_gap_max, roughness > rough_detailed, step > step_detailed or
// slope > slope_detailed; tier 1 (medium_level) if any gap, roughness > rough_medium,
// step > step_medium or slope > slope_medium; otherwise tier 0 (flat_level). Gripping needs the
// detailed level too: `gripping` forces tier 2 (the caller knows whether a robot grips or is held).
//
// Hysteresis: a harder tier is taken at once; an easier one only after the requirement stayed
// below the current tier for demote_delay seconds (the hard part is behind the robot; with the
// lookbehind it is behind its rear end). A manual override pins a robot's level until cleared.
// Every threshold is a parameter (LevelPolicyConfig; the swarm_manager node reads them as ROS
// parameters of the same names).
#pragma once

#include <functional>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <string>

#include "sbot_sim/core/types.h"

namespace sbot {
namespace swarm {

struct LevelPolicyConfig {
  double lookahead = 0.18;        ///< [m] in front of base_link (gripper tip: 0.09 m)
  double lookbehind = 0.07;       ///< [m] behind base_link (under the robot: rear wheels 0.04 m)
  double half_width = 0.04;       ///< [m] lateral offset of the side lines (the tracks)
  double sample = 0.005;          ///< [m] sample spacing along the lines
  double gap_depth = 0.02;        ///< [m] a dip deeper than this is a gap (rough bumps are not gaps)
  double small_gap_max = 0.05;    ///< [m] seed: gaps up to 5 cm -> medium, wider -> detailed
  double step_medium = 0.006;     ///< [m]
  double step_detailed = 0.020;   ///< [m]
  double slope_medium = 0.06;     ///< [rad] (3.4 deg)
  double slope_detailed = 0.45;   ///< [rad] (26 deg)
  double slope_window = 0.10;     ///< [m] fit window of slope and roughness
  double rough_medium = 0.0010;   ///< [m] height standard deviation about the local incline
  double rough_detailed = 0.0024; ///< [m]
  double demote_delay = 0.6;      ///< [s] the easier tier must hold this long before demoting
  std::string flat_level = "basic", medium_level = "medium", detailed_level = "detailed";
};

struct TerrainFeatures {
  double gap = 0;        ///< [m] widest gap
  double step = 0;       ///< [m] largest step
  double slope = 0;      ///< [rad] steepest incline
  double roughness = 0;  ///< [m] largest local height standard deviation
};

using HeightFunction = std::function<double(double x, double y)>;

/// Memoised height on a `resolution` grid (the terrain is static): a robot looking ahead every
/// 0.2 s sees mostly the cells it saw last time, so World::terrainHeight (a ray cast against every
/// static geom) runs ~once per cell. Not thread-safe.
class HeightCache {
 public:
  HeightCache(HeightFunction height, double resolution = 0.005) : height_(std::move(height)), res_(resolution) {}
  double operator()(double x, double y);
  HeightFunction function() { return [this](double x, double y) { return (*this)(x, y); }; }
  std::size_t size() const { return cells_.size(); }

 private:
  HeightFunction height_;
  double res_;
  std::unordered_map<std::uint64_t, double> cells_;
};

/// Measure the terrain around a robot at `pose` (x, y, yaw).
TerrainFeatures measureTerrain(const HeightFunction& height, const Pose2D& pose, const LevelPolicyConfig& c);
/// 0 flat, 1 medium, 2 detailed.
int requiredTier(const TerrainFeatures& f, const LevelPolicyConfig& c);
std::string describe(const TerrainFeatures& f);

/// Per-robot decisions with hysteresis and manual overrides.
class LevelPolicy {
 public:
  explicit LevelPolicy(const LevelPolicyConfig& config = LevelPolicyConfig()) : config_(config) {}
  const LevelPolicyConfig& config() const { return config_; }

  /// The level `robot` should have at time `t` [s] given the terrain around `pose`.
  std::string decide(const std::string& robot, double t, const HeightFunction& height, const Pose2D& pose,
                     bool gripping = false);
  /// Same, from measured features.
  std::string decide(const std::string& robot, double t, const TerrainFeatures& f, bool gripping = false);

  /// Pin a robot to `level` (empty: back to automatic).
  void setOverride(const std::string& robot, const std::string& level);
  std::string overrideOf(const std::string& robot) const;
  const std::string& levelOfTier(int tier) const;
  TerrainFeatures lastFeatures(const std::string& robot) const;

 private:
  struct State {
    int tier = 0;
    double lower_since = -1;  ///< [s] since when the requirement is below `tier`; -1 = it is not
    TerrainFeatures last;
    std::string override_level;
  };
  LevelPolicyConfig config_;
  std::map<std::string, State> robots_;
};

}  // namespace swarm
}  // namespace sbot
