// Measurement datasets, format `sbot-dataset/1` (docs/calibration.md): a directory with dataset.yaml
// and one CSV file per run. Loading validates everything and reports the file, line and column of
// the first problem (DatasetError).
#pragma once

#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/types.h"
#include "sbot_sim/core/world_config.h"

namespace sbot::calib {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Limits that catch times written in the wrong unit (ms, epoch stamps) before a replay simulates them.
constexpr double kMaxRunDuration = 3600.0;  ///< [s] last time stamp of a drive run
constexpr double kMaxRowGap = 60.0;         ///< [s] between two consecutive rows of a drive run
constexpr double kMaxPullForce = 100.0;     ///< [N] force_x / force_y (an s-bot weighs 6.6 N; the seed pulled with 1.2 N)
/// [s] shortest re-anchoring segment (align_segment): shorter ones follow the measurement so closely
/// that they hide the model's error (0.05 s hid a 10 % speed error entirely).
constexpr double kMinAlignSegment = 1.0;

/// A bad dataset: names the file, the 1-based line and column (0 when not applicable) and, for CSV
/// files, the column's name.
class DatasetError : public ConfigError {
 public:
  DatasetError(const std::string& file, int line, int column, const std::string& column_name,
               const std::string& what);
  const char* what() const noexcept override { return message_.c_str(); }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& columnName() const { return column_name_; }

 private:
  int line_, column_;
  std::string column_name_, message_;
};

struct Lamp {
  Vec3 position = Vec3::Zero();  ///< [m]
  double intensity = 0;          ///< [mcd]
};

/// Per-channel measurement noise scale, used to normalise residuals so channels can be combined.
/// sigma(channel, value) = abs + rel * |value|.
struct NoiseModel {
  std::map<std::string, std::pair<double, double>> table;  ///< channel group -> (abs, rel)
  NoiseModel();
  /// Group of a channel: "x", "y" -> "position"; "yaw"; "speed_left" -> "speed"; "ir3" -> "ir"; ...
  static std::string group(const std::string& channel);
  double sigma(const std::string& channel, double value) const;
};

struct Series {
  std::vector<double> t;  ///< [s] (drive) or placement row index (place)
  std::vector<double> v;
  std::vector<int> line;  ///< CSV line of each sample (for messages)
};

/// The series' values unwrapped (consecutive differences wrapped to (-pi, pi]): for yaw.
std::vector<double> unwrapped(const Series& s);

enum class RunKind { Drive, Place };

struct Placement {
  Pose2D pose;
  double z = kNaN;  ///< optional height of base_link above the terrain [m] (robot held), NaN = resting
};

struct Run {
  std::string name;
  std::string file;          ///< path as written in dataset.yaml (relative to the dataset)
  std::string path;          ///< resolved path
  RunKind kind = RunKind::Drive;
  Pose2D initial_pose;
  std::string group;         ///< experiment family (default: the run name up to the first '_')
  double start_time = 0;     ///< [s] when the run started in the session (battery time), default 0
  // drive: command rows (held until the next one) in API units
  std::vector<double> cmd_t, cmd_left, cmd_right;
  // drive, optional inputs (held until the next row that has them): an external horizontal force on
  // the robot [N] (world frame, e.g. a force meter pulling it) and passive tracks (motors off, 1/0).
  std::vector<double> force_t, force_x, force_y;
  std::vector<double> passive_t, passive;
  // place: one placement per row
  std::vector<Placement> placements;
  std::map<std::string, Series> channels;  ///< measured channels (x, y, yaw, speed_left, ir3, ...)
  double t_end = 0;                        ///< last time stamp of the file [s]

  /// Command in API units at time t (held; 0 before the first command row).
  std::pair<double, double> commandAt(double t) const;
  /// External force [N] at time t (held; 0 before the first force row).
  std::pair<double, double> forceAt(double t) const;
  /// Tracks passive at time t (held; false before the first row with `passive`).
  bool passiveAt(double t) const;
  std::size_t sampleCount() const;
};

/// The core's WorldConfig with sleeping at rest off (see Dataset::world).
inline WorldConfig workbenchWorld() {
  WorldConfig w;
  w.rest.enabled = false;
  return w;
}

struct Dataset {
  std::string dir;           ///< dataset directory
  std::string yaml_path;
  std::string name;
  std::string description;
  std::string robot = "medium";
  /// Terrain including the obstacles (as boxes with their surface labels). Sleeping at rest
  /// (RestConfig) is off unless the dataset's world says `sleep_at_rest: true`: a fit needs the
  /// replay to be a smooth function of the effects' parameters, and sleep switches on a threshold
  /// (with it a speed_scale + latency diagnosis settles on motor lag for one seed of two).
  WorldConfig world = workbenchWorld();
  /// world.step / world.gravity written in the dataset: replays use them; otherwise the model
  /// level's recommended step and gravity (Fast: 0.1 s, 1/50 g).
  bool world_sets_step = false, world_sets_gravity = false;
  std::vector<Lamp> lamps;
  double ambient_light = 0;
  NoiseModel noise;
  bool align_initial_pose = true;  ///< fit each drive run's start pose within the tracker noise
  /// Re-anchor the model's planar pose every this many seconds (0 = only at the start), see
  /// docs/calibration.md "Comparing trajectories".
  double align_segment = 5.0;
  std::vector<Run> runs;

  std::set<std::string> channels() const;  ///< every measured channel over all runs
  bool hasChannelGroup(const std::string& group) const;
  std::set<std::string> obstacleSurfaces() const;
  std::size_t sampleCount() const;
};

/// Every column name a run file may have.
bool isKnownColumn(const std::string& name);

/// Load `path` (a dataset directory or its dataset.yaml). Throws DatasetError.
Dataset loadDataset(const std::string& path);
/// Parse one run file (exposed for tests).
void parseRunCsv(const std::string& text, const std::string& file, Run& run);

/// `ds` with only the runs named in `keep`, in dataset order (names it does not have are ignored).
Dataset onlyRuns(const Dataset& ds, const std::set<std::string>& keep);
/// The dataset without the runs named in `skip` (e.g. runs a model cannot replay, evaluation.h
/// ReplaySensitivity). Throws std::invalid_argument naming a run the dataset does not have, or when
/// no run would be left.
Dataset withoutRuns(const Dataset& ds, const std::set<std::string>& skip);

/// Write a dataset (dataset.yaml + one CSV per run) into `dir` (created). Channels with different
/// time stamps are merged into one CSV with empty cells.
void writeDataset(const Dataset& ds, const std::string& dir);

}  // namespace sbot::calib
