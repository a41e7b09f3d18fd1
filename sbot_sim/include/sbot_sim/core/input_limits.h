// The stated ranges of values that reach the simulation from outside (scenario files, URDFs,
// service calls): each check returns why a value is refused ("" when it is accepted), so that the
// scenario parser and the node's services refuse the same values with the same words.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>

#include "sbot_sim/core/types.h"

namespace sbot {

/// [m] The smallest edge, radius or length of anything that becomes ODE geometry (terrain boxes,
/// arena walls, URDF shapes). A box 1e-20 m thin passed as "> 0" and made ODE fail
/// `!bSafeNormalize3Fault` in dxNormalize3 when a robot touched it; the thinnest shape of the
/// shipped models is 1.5 mm (sbot_description/urdf), 15 times this.
constexpr double kMinGeomSize = 1e-4;
/// [m] The largest: the simulated space's extent (world.h kMaxCoordinate, 1e5 m), twice.
constexpr double kMaxGeomSize = 2e5;
/// [rad] Angles (a pose's yaw, a box's yaw and pitch) within one turn either way.
constexpr double kMaxAngle = 2 * M_PI;
/// [mcd] a lamp's intensity, [mcd/cm^2] the ambient light: at most 1e9 (the shipped phototaxis
/// lamp is 5e5 mcd); 1e308 overflowed the light sensors' sums to infinity.
constexpr double kMaxLightIntensity = 1e9;
/// [Hz, simulated time] The slowest sampling rate a sensor channel takes: one message per 100 s.
constexpr double kMinSamplingHz = 0.01;
/// A robot name's length (it becomes ROS namespaces, TF frames and file names).
constexpr std::size_t kMaxRobotNameLength = 64;
/// [s] A scenario's duration (simulated).
constexpr double kMaxDuration = 1e9;

/// A box's three edges [m] in [kMinGeomSize, kMaxGeomSize].
std::string boxSizeProblem(const Vec3& size);
/// One edge, radius or length [m] in [kMinGeomSize, kMaxGeomSize].
std::string geomSizeProblem(double size);
/// An angle [rad] finite and in [-kMaxAngle, kMaxAngle].
std::string angleProblem(double radians);
/// A light intensity finite and in [0, kMaxLightIntensity]; `unit` for the message ("mcd").
std::string lightIntensityProblem(double intensity, const char* unit);
/// A sampling rate [Hz] finite and >= kMinSamplingHz (the step rate caps it from above).
std::string samplingRateProblem(double hz);

}  // namespace sbot
