// The calibration workbench's view of the core's sensor modules (IR proximity, ground, light):
// read one channel ("ir3", "ground0", "light5") of the replayed robot as the API would, without
// noise, with the raw features (distance, incidence, surface) the report plots against.
#pragma once

#include <memory>
#include <string>

#include "calibration/dataset.h"

namespace sbot {
class World;
class Robot;
}  // namespace sbot

namespace sbot::calib {

struct SensorReading {
  double value = kNaN;      ///< API units (noise-free, not quantised)
  double distance = kNaN;   ///< [m] raw distance the sensor saw (NaN = nothing in range)
  double incidence = kNaN;  ///< [rad]
  std::string surface;
};

class SensorBridge {
 public:
  SensorBridge(World& world, Robot& robot, const Dataset& ds);
  ~SensorBridge();
  bool available() const;
  std::string whyUnavailable() const;
  /// The robot was teleported (place runs): refresh whatever the sensors cache.
  void placed();
  SensorReading read(const std::string& channel);
  /// Does this build simulate the channel group ("ir", "ground", "light")?
  static bool supports(const std::string& group);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sbot::calib
