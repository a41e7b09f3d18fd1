#include "sbot_sim/core/actuators/connections.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>

#include "sbot_sim/core/world.h"

namespace sbot {

ConnectionManager::~ConnectionManager() { clear(); }

void ConnectionManager::destroy(Connection& c) {
  if (c.joint) {
    // The robots it joined may be asleep (Robot::asleep): a held robot let go must fall.
    for (int i = 0; i < 2; ++i)
      if (dBodyID b = dJointGetBody(c.joint, i)) dBodyEnable(b);
    dJointDestroy(c.joint);
  }
  delete c.feedback;
  c.joint = nullptr;
  c.feedback = nullptr;
}

int ConnectionManager::connect(const std::string& holder, dBodyID holder_body, const std::string& held,
                               dBodyID held_body, Connection::Kind kind) {
  release(holder, kind);
  Connection c;
  c.holder = holder;
  c.held = held;
  c.kind = kind;
  c.created_at = world_.time();
  c.id = next_id_++;
  if (kind == Connection::FrontGripper) {
    c.joint = dJointCreateFixed(world_.odeWorld(), nullptr);
    dJointAttach(c.joint, holder_body, held_body);
    dJointSetFixed(c.joint);
  } else {
    // Weak side-arm link: a ball joint at the holder body's position (the arm tip).
    c.joint = dJointCreateBall(world_.odeWorld(), nullptr);
    dJointAttach(c.joint, holder_body, held_body);
    const dReal* p = dBodyGetPosition(holder_body);
    dJointSetBallAnchor(c.joint, p[0], p[1], p[2]);
  }
  dBodyEnable(holder_body);  // both robots back into the solve (Robot::wakeIfDisturbed)
  dBodyEnable(held_body);
  c.feedback = new dJointFeedback{};
  dJointSetFeedback(c.joint, c.feedback);
  connections_.push_back(c);
  return c.id;
}

bool ConnectionManager::release(const std::string& holder, Connection::Kind kind) {
  auto it = std::find_if(connections_.begin(), connections_.end(),
                         [&](const Connection& c) { return c.holder == holder && c.kind == kind; });
  if (it == connections_.end()) return false;
  destroy(*it);
  connections_.erase(it);
  return true;
}

bool ConnectionManager::releaseId(int id) {
  auto it = std::find_if(connections_.begin(), connections_.end(), [&](const Connection& c) { return c.id == id; });
  if (it == connections_.end()) return false;
  destroy(*it);
  connections_.erase(it);
  return true;
}

void ConnectionManager::removeRobot(const std::string& robot) {
  for (auto it = connections_.begin(); it != connections_.end();) {
    if (it->holder == robot || it->held == robot) {
      destroy(*it);
      it = connections_.erase(it);
    } else {
      ++it;
    }
  }
}

void ConnectionManager::clear() {
  for (auto& c : connections_) destroy(c);
  connections_.clear();
}

std::vector<Connection> ConnectionManager::of(const std::string& robot) const {
  std::vector<Connection> out;
  for (const auto& c : connections_)
    if (c.holder == robot || c.held == robot) out.push_back(c);
  return out;
}

const Connection* ConnectionManager::find(const std::string& holder, Connection::Kind kind) const {
  for (const auto& c : connections_)
    if (c.holder == holder && c.kind == kind) return &c;
  return nullptr;
}

std::string ConnectionManager::heldBy(const std::string& holder, Connection::Kind kind) const {
  const Connection* c = find(holder, kind);
  return c ? c->held : std::string();
}

double ConnectionManager::force(const Connection& c) const {
  if (!c.feedback) return 0;
  const dReal* f = c.feedback->f1;
  return std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
}

}  // namespace sbot
