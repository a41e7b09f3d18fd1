// A robot link held by name, for code that reads the same links every step (sensors).
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include "sbot_sim/core/types.h"

namespace sbot {

class Robot;

/// A link named once and looked up lazily: Robot::linkPose(const LinkRef&) resolves the name only
/// when the robot was (re)built since the last call (a level switch or a turret weld rebuilds it).
/// Sensors read their links every step; the name lookup was ~2 % of a Medium step.
class LinkRef {
 public:
  LinkRef() = default;
  explicit LinkRef(std::string name) : name_(std::move(name)) {}
  const std::string& name() const { return name_; }

 private:
  friend class Robot;
  std::string name_;
  mutable std::uint64_t build_ = 0;  ///< the Robot::build_id_ it was resolved in (0: never)
  mutable int body_ = -1;
  mutable Pose body_T_link_;
};

}  // namespace sbot
