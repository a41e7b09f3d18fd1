#include "step_statics.h"

#include <algorithm>
#include <cmath>

namespace sbot {
namespace validation {

double pitchOnStep(const SideView& s, double h) {
  // The centre axle stands at h + r_c, the front axle at r_f: the axle line (x_f, z_f) pitched nose
  // down by p drops x_f sin p - z_f cos p, which must equal h + r_c - r_f. One root in [0, pi/2).
  const double drop = h + s.centre_radius - s.front_radius;
  const double len = std::hypot(s.front_axle_x, s.front_axle_z);
  const double phase = std::atan2(-s.front_axle_z, s.front_axle_x);  // x sin p - z cos p = len sin(p + phase)
  return std::asin(std::clamp(drop / len, -1.0, 1.0)) - phase;
}

double cornerMargin(const SideView& s, double h) {
  const double p = pitchOnStep(s, h);
  const double c = std::cos(p), sn = std::sin(p);
  const double front_x = s.front_axle_x * c + s.front_axle_z * sn;
  const double r = s.front_radius;
  const double corner_x = front_x - std::sqrt(std::max(0.0, r * r - (r - h) * (r - h)));
  const double com_x = s.com_x * c + s.com_z * sn;
  return corner_x - com_x;
}

double cornerTipHeight(const SideView& s) {
  // The margin falls as the step rises (more pitch, corner further behind the axle): scan, then bisect.
  const double top = s.front_radius;
  const int n = 400;
  double lo = 0;
  for (int i = 1; i <= n; ++i) {
    const double h = top * i / n;
    if (cornerMargin(s, h) < 0) {
      double hi = h;
      for (int k = 0; k < 50; ++k) {
        const double mid = (lo + hi) / 2;
        (cornerMargin(s, mid) < 0 ? hi : lo) = mid;
      }
      return hi;
    }
    lo = h;
  }
  return top;
}

double comXForCornerTip(SideView s, double h) {
  // cornerMargin is linear in com_x with slope -cos p: solve directly.
  s.com_x = 0;
  return cornerMargin(s, h) / std::cos(pitchOnStep(s, h));
}

double comZForCornerTip(SideView s, double h) {
  // cornerMargin is linear in com_z with slope -sin p (p > 0 on any step): solve directly.
  s.com_z = 0;
  return cornerMargin(s, h) / std::sin(pitchOnStep(s, h));
}

double frontTipSlope(const SideView& s) {
  const double ground = -s.front_axle_z + s.front_radius;  // centre axle height above the front contact
  return std::atan2(s.front_axle_x - s.com_x, s.com_z + ground);
}

}  // namespace validation
}  // namespace sbot
