#include "sbot_sim/core/input_limits.h"

#include <sstream>

namespace sbot {
namespace {

std::string outside(double v, double lo, double hi, const char* unit) {
  std::ostringstream m;
  m << "must be in [" << lo << ", " << hi << "] " << unit << ", found " << v;
  return m.str();
}

}  // namespace

std::string geomSizeProblem(double size) {
  if (std::isfinite(size) && size >= kMinGeomSize && size <= kMaxGeomSize) return "";
  return outside(size, kMinGeomSize, kMaxGeomSize, "m") + " (thinner geometry is degenerate for ODE's collision tests)";
}

std::string boxSizeProblem(const Vec3& size) {
  for (int k = 0; k < 3; ++k)
    if (const std::string p = geomSizeProblem(size[k]); !p.empty()) return "every edge " + p;
  return "";
}

std::string angleProblem(double radians) {
  if (std::isfinite(radians) && std::abs(radians) <= kMaxAngle) return "";
  return outside(radians, -kMaxAngle, kMaxAngle, "rad") + " (one turn either way)";
}

std::string lightIntensityProblem(double intensity, const char* unit) {
  if (std::isfinite(intensity) && intensity >= 0 && intensity <= kMaxLightIntensity) return "";
  return outside(intensity, 0, kMaxLightIntensity, unit);
}

std::string samplingRateProblem(double hz) {
  if (std::isfinite(hz) && hz >= kMinSamplingHz) return "";
  std::ostringstream m;
  m << "must be finite and >= " << kMinSamplingHz << " Hz, found " << hz;
  return m.str();
}

}  // namespace sbot
