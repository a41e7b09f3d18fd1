#include "sbot_sim/core/rest.h"

#include <ode/ode.h>

namespace sbot {
namespace {

Vec3 positionOf(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  return Vec3(p[0], p[1], p[2]);
}

Quat orientationOf(dBodyID b) {
  const dReal* q = dBodyGetQuaternion(b);
  return Quat(q[0], q[1], q[2], q[3]);
}

}  // namespace

void RestWatch::start(const std::vector<dBodyID>& bodies, double now_s) {
  started_ = true;
  since_s_ = now_s;
  positions_.clear();
  orientations_.clear();
  masses_.clear();
  total_mass_ = 0;
  samples_ = 0;
  load_sum_ = 0;
  force_sum_ = Vec3::Zero();
  for (dBodyID b : bodies) {
    positions_.push_back(positionOf(b));
    orientations_.push_back(orientationOf(b));
    dMass m;
    dBodyGetMass(b, &m);
    masses_.push_back(m.mass);
    total_mass_ += m.mass;
  }
}

bool RestWatch::stoodStill(const std::vector<dBodyID>& bodies, double now_s, const RestConfig& config) {
  if (!started_ || bodies.size() != positions_.size()) {
    start(bodies, now_s);
    return false;
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const bool heavy = masses_[i] >= config.heavy_fraction * total_mass_;
    if ((positionOf(bodies[i]) - positions_[i]).norm() > config.max_shift_m ||
        (heavy && orientationOf(bodies[i]).angularDistance(orientations_[i]) > config.max_turn_rad)) {
      last_move_s_ = now_s;
      start(bodies, now_s);
      return false;
    }
  }
  return now_s - since_s_ >= config.window_s - 1e-9;
}

}  // namespace sbot
