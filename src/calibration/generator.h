// Synthetic measurement datasets: the simulator with hidden effects (and optionally a world the
// dataset does not describe, e.g. a tilted floor) plus realistic measurement noise, over a standard
// experiment set. Used by the statistical tests and to make the worked example.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "calibration/dataset.h"
#include "calibration/parallel.h"
#include "sbot_sim/core/effects/effects_file.h"

namespace sbot::calib {

struct GeneratorOptions {
  std::string name = "synthetic";
  std::string level = "simple";
  std::string solver = "quickstep";        ///< the simulated world's stepper (world.solver)
  std::uint64_t seed = 1;
  std::vector<EffectConfig> hidden;        ///< effects switched on in the "real" robot
  double tilt_deg = 0;                     ///< hidden floor tilt [deg] (not in the library)
  double duration = 8;                     ///< [s] length of each drive pattern
  /// Experiment families: straight, spin, arc, square, steps (drive runs); place (static IR
  /// placements before three surfaces, incidence 0-60 deg, 1-16 cm); approach (drive runs reversing
  /// toward the three walls at 0-60 deg, the IR ring logged at sensor_hz). Empty = the five drive
  /// families.
  std::set<std::string> experiments;
  int repeat = 1;                          ///< repeat the drive set (more runs)
  std::size_t max_runs = 0;                ///< 0 = all
  double tracker_hz = 30, encoder_hz = 10, torque_hz = 10, tilt_hz = 10, sensor_hz = 10;
  bool measure_speed = true, measure_torque = false, measure_tilt = true;
  double ir_outlier_rate = 0.01;           ///< fraction of IR samples replaced by outliers
  NoiseModel noise;                        ///< measurement noise actually added (sigma)
  double align_segment = 5.0;
};

/// The hidden truth of a generated dataset (for tests): effects and the world actually simulated.
struct GeneratedTruth {
  std::vector<EffectConfig> hidden;
  WorldConfig world;
  double tilt_deg = 0;
  double tilt_direction = 0;  ///< [rad] downhill direction
};

Dataset generateDataset(const GeneratorOptions& opt, WorkerPool& pool, GeneratedTruth* truth = nullptr);

/// Families the generator knows.
const std::vector<std::string>& generatorFamilies();

/// Least GeneratorOptions::duration [s] (at most kMaxRunDuration) and largest tilt_deg [deg]
/// (reasons in checkGeneratorOptions).
constexpr double kMinDuration = 2, kMaxTiltDeg = 30;

/// Throws std::invalid_argument naming the option (--families, --duration, --tilt) for an unknown
/// family, a duration or tilt outside its range, or IR families (place, approach) on a level whose
/// IR is a look-up table (no walls in it). generateDataset checks too; the command line calls it
/// before it creates the output folder.
void checkGeneratorOptions(const GeneratorOptions& opt);

}  // namespace sbot::calib
