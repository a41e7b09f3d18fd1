// Physical connections between s-bots: the dynamic joints a front gripper or a side arm creates when
// it grips another robot (seed 2.2.3: "a rigid joint between the gripper and the other s-bot every
// time a rigid connection between two s-bots is requested"). One ConnectionManager per World (the
// World owns it: World::connections()); the swarm graph lists robot connections from here.
//
// A connection is an ODE joint between a body of the holder (its gripper / side-arm tip) and the
// body of the held robot that was touched. Kinds:
//   FrontGripper  fixed joint (rigid: lifts another s-bot; seed 2.2.3)
//   SideArm       ball joint limited to `max_force` (weak connection, Table 2.5: 1 N): it breaks
//                 when the constraint force exceeds it (checked every step by the side arm module)
// Connections are removed when the holder releases, or when either robot leaves the World
// (World::removeRobot calls removeRobot()). Querying (list(), of()) never changes anything.
#pragma once

#include <string>
#include <vector>

#include "sbot_sim/core/detail/ode_handles.h"

namespace sbot {

class World;

struct Connection {
  enum Kind { FrontGripper = 1, SideArm = 2 };  ///< values as sbot_msgs/SwarmGraph
  std::string holder;        ///< robot that grips
  std::string held;          ///< robot that is gripped
  Kind kind = FrontGripper;
  dJointID joint = nullptr;  ///< the ODE joint (owned by the manager)
  dJointFeedback* feedback = nullptr;  ///< forces on the joint last step (owned by the manager)
  double created_at = 0;     ///< simulated time [s]
  int id = 0;                ///< unique per manager
};

class ConnectionManager {
 public:
  explicit ConnectionManager(World& world) : world_(world) {}
  ~ConnectionManager();
  ConnectionManager(const ConnectionManager&) = delete;
  ConnectionManager& operator=(const ConnectionManager&) = delete;

  /// Create a connection between `holder_body` (of robot `holder`) and `held_body` (of `held`), in
  /// their current relative pose. Returns its id. At most one connection per (holder, kind): an
  /// existing one is replaced.
  int connect(const std::string& holder, dBodyID holder_body, const std::string& held, dBodyID held_body,
              Connection::Kind kind);
  /// Remove the connection of `holder` of `kind`; false if there was none.
  bool release(const std::string& holder, Connection::Kind kind);
  bool releaseId(int id);
  /// Remove every connection `robot` takes part in (as holder or held). Call before the robot's
  /// bodies are destroyed.
  void removeRobot(const std::string& robot);
  void clear();

  const std::vector<Connection>& list() const { return connections_; }
  /// Connections where `robot` is holder or held.
  std::vector<Connection> of(const std::string& robot) const;
  /// The connection `holder` makes with `kind`, or nullptr.
  const Connection* find(const std::string& holder, Connection::Kind kind) const;
  /// The robot `holder` holds with `kind`, or "" (what FrontGripper::gripped and SideArm::gripped report).
  std::string heldBy(const std::string& holder, Connection::Kind kind) const;
  /// Force [N] transmitted by a connection last step (|f1|), 0 if unknown.
  double force(const Connection& c) const;

 private:
  void destroy(Connection& c);
  World& world_;
  std::vector<Connection> connections_;
  int next_id_ = 1;
};

}  // namespace sbot
