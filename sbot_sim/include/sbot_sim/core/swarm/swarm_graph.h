// The swarm as a connected graph (seed 2.3, eq. 2.16: <N, pos[N], dir[N], connection[N,N]>) and the
// static front-gripper links of scenario files (seed 2.2.3: Fast/Simple have no gripper model;
// "connection between two s-bots can still be achieved by creating a static joint").
//
// Connections are read from World::connections() (actuators/connections.h): the dynamic joints the
// gripper / side-arm modules create and the static links below are the same kind of record, so
// the graph, model switching (Robot::switchDescription re-attaches them) and robot removal treat
// them alike.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;

namespace swarm {

/// Values as sbot_msgs/SwarmGraph and seed SwarmGetConnectivity: 0 none, 1 front gripper, 2 side arm.
enum : std::uint8_t { kNone = 0, kFrontGripper = 1, kSideArm = 2 };

struct SwarmGraph {
  double time = 0;                    ///< [s] simulated
  std::size_t n = 0;                  ///< number of robots
  std::vector<std::string> names;     ///< in World::robots() order
  std::vector<Vec3> positions;        ///< [m] base_link, world frame
  std::vector<double> headings;       ///< [rad] base_link yaw
  std::vector<std::uint8_t> connections;  ///< n*n row-major: [i*n + j] = kind with which i grips j
  std::vector<std::uint32_t> component;   ///< connected-component id per robot (undirected), 0-based,
                                          ///< numbered in order of each component's first robot
  std::size_t components = 0;         ///< number of components

  std::uint8_t connection(std::size_t i, std::size_t j) const { return connections[i * n + j]; }
  int indexOf(const std::string& name) const;  ///< -1 if absent
};

/// Snapshot of the swarm. O(N + connections); no physics.
SwarmGraph computeSwarmGraph(World& world);

/// A static link: `holder` grips `held` with its front gripper (kind 1) or side arm (kind 2).
struct LinkSpec {
  std::string holder, held;
  std::uint8_t kind = kFrontGripper;
};

/// Parse "front_gripper" | "side_arm" (also "1" | "2"); throws ConfigError otherwise.
std::uint8_t parseLinkKind(const std::string& text, const std::string& file, const std::string& field);

/// Create a static link (seed 2.2.3): with `place`, first move `held` so that its turret ring touches
/// `holder`'s gripper_tip, on the line from the holder's turret axis through the tip (the robots are
/// then 0.147 m apart centre to centre at full size, 0.0735 m in Fast), at the holder's height and
/// keeping held's heading; then a fixed joint between the body carrying holder's gripper_tip and
/// held's turret body (SideArm: a ball joint, as the side-arm module makes). Registered in
/// World::connections(). Returns the connection id. Throws UnknownName for an unknown robot.
int createStaticLink(World& world, const LinkSpec& link, bool place = true);

/// createStaticLink for each of a scenario's `links`, in order.
void addScenarioLinks(World& world, const std::vector<LinkSpawn>& links);

/// Outer radius of a robot's turret ring [m] (largest turret collision cylinder/sphere radius).
double turretRingRadius(const World& world, const std::string& robot);

}  // namespace swarm
}  // namespace sbot
