// What the robot description's loaders share (robot_description.cpp reads the URDF,
// robot_sidecar.cpp the sidecar): the bounds on a description's numbers and their checks. Private
// to the core: no public header includes it.
#pragma once

#include <cmath>
#include <sstream>
#include <string>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_limits.h"
#include "sbot_sim/core/robot_description.h"

namespace sbot {

constexpr double kMaxTorqueWindow = 10;  ///< [s] treels.torque_window
// Bounds on a description's numbers: far beyond any s-bot (12 cm, 0.66 kg), yet finite values past
// them (1e300) overflow ODE's normalisations, which abort the process instead of reporting.
constexpr double kMaxLength = 100;     ///< [m] offsets and shape sizes
constexpr double kMaxMass = 1000;      ///< [kg] per link
constexpr double kMaxInertia = 1000;   ///< [kg m^2] per inertia entry

inline void requirePositive(double v, const std::string& file, const std::string& field) {
  if (!(std::isfinite(v) && v > 0)) throw ConfigError(file, field, "must be a finite number > 0");
}

/// A shape's edge, radius or length: degenerate geometry is refused here, not by an ODE assertion.
inline void requireGeomSize(double v, const std::string& file, const std::string& field) {
  if (const std::string problem = geomSizeProblem(v); !problem.empty()) throw ConfigError(file, field, problem);
}

inline void requireAtMost(double v, double limit, const std::string& file, const std::string& field, const char* unit) {
  if (!(std::abs(v) <= limit)) {
    std::ostringstream why;
    why << "must be at most " << limit << " " << unit << " in size, found " << v;
    throw ConfigError(file, field, why.str());
  }
}

/// Reads d.sidecar_path into `d` (level, treels, turret, materials, gripper, side arm, extra),
/// refusing what is malformed with a ConfigError naming the field (robot_sidecar.cpp).
void parseSidecar(RobotDescription& d);

}  // namespace sbot
