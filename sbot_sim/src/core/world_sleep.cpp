// World's sleeping and waking: robots at rest leave the solve (in groups, when joined), and a
// sleeper is woken, before the terrain is collided, when a joint or a contact ties it to an awake
// body (docs/model.md, "Sleeping at rest").
#include "sbot_sim/core/world.h"

#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "world_internal.h"

namespace sbot {

// ODE itself enables, during the step, every disabled body that a joint (a robot-robot contact just
// made, a gripper or side-arm connection, a static link) ties to an enabled one. A robot woken that
// way would be solved without the terrain contacts its sleep skipped, and drop for a step; so wake
// those robots here, before the terrain is collided, until no sleeper is jointed to an awake body
// (a chain of held robots wakes link by link). The robot-robot pass skipped pairs of sleepers
// (handlePair): a robot woken here is collided with the robots that slept then, and a sleeper it
// touches wakes in turn, as the skipped contact would have woken it.
void World::wakeSleepersJointedToAwakeBodies() {
  const std::size_t n = robots_.size();
  std::vector<char> slept_in_pass(n), collided_again(n, 0);
  bool any_asleep = false;
  for (std::size_t i = 0; i < n; ++i) {
    slept_in_pass[i] = robots_[i]->asleep();
    any_asleep = any_asleep || slept_in_pass[i];
  }
  if (!any_asleep) return;  // a swarm that drives
  bool woke = true;
  while (woke) {
    woke = false;
    for (std::size_t i = 0; i < n; ++i) {
      Robot& r = *robots_[i];
      if (!r.asleep() || !jointedToAnEnabledBody(r)) continue;
      r.wakeByTouch();
      joinHeldBackContactsOf(r);
      for (std::size_t k = 0; k < n; ++k)  // a pair is collided once: skip robots already done
        if (k != i && slept_in_pass[k] && !collided_again[k]) collideRobots(r, *robots_[k]);
      collided_again[i] = 1;
      woke = true;
    }
  }
}

namespace {

/// The body that `joint` ties `body` to (null for the static world).
dBodyID otherBody(dJointID joint, dBodyID body) {
  return dJointGetBody(joint, 0) == body ? dJointGetBody(joint, 1) : dJointGetBody(joint, 0);
}

}  // namespace

bool World::jointedToAnEnabledBody(const Robot& robot) const {
  for (dBodyID b : robot.bodies()) {
    for (int i = 0, n = dBodyGetNumJoints(b); i < n; ++i) {
      const dJointID j = dBodyGetJoint(b, i);
      if (!dJointIsEnabled(j)) continue;  // ODE walks enabled joints only
      const dBodyID other = otherBody(j, b);
      if (other && dBodyIsEnabled(other)) return true;  // a sleeper's own bodies are all disabled
    }
  }
  return false;
}

void World::releaseHeldBackContacts() {
  if (held_back_.empty()) return;
  // Pushed: robots that are not standing, and every awake robot in contact with a pushed one.
  std::unordered_set<const Robot*> pushed;
  for (const auto& r : robots_)
    if (!r->asleep() && !r->standing()) pushed.insert(r.get());
  for (bool grew = !pushed.empty(); grew;) {
    grew = false;
    for (const auto& [a, b] : awake_touches_)
      if (pushed.count(a) != pushed.count(b)) grew = pushed.insert(pushed.count(a) ? b : a).second || grew;
  }
  for (const HeldBackContact& h : held_back_)
    if (pushed.count(h.standing)) dJointAttach(h.joint, h.body_a, h.body_b);  // wakes its sleeper below
}

void World::joinHeldBackContactsOf(const Robot& sleeper) {
  for (const HeldBackContact& h : held_back_)
    if (h.sleeper == &sleeper) dJointAttach(h.joint, h.body_a, h.body_b);
}

// Robots joined by a connection or a static link fall asleep together: a sleeper jointed to an
// awake robot is woken (above), so joined robots that became ready at different steps woke each
// other for ever (20 standing chains of 5: 95 of 100 asleep at the end, RTM 60 against 158).
void World::sleepRestingGroups() {
  const int n = static_cast<int>(robots_.size());
  std::vector<int> group(n);
  bool any_ready = false;
  for (int i = 0; i < n; ++i) {
    group[i] = i;
    any_ready = any_ready || robots_[i]->restReady();
  }
  if (!any_ready) return;
  auto find = [&](int i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  std::unordered_map<const Robot*, int> index;
  for (int i = 0; i < n; ++i) index[robots_[i].get()] = i;
  // The step's contacts are gone by now: the joints left between robots are connections and links.
  for (int i = 0; i < n; ++i) {
    for (dBodyID body : robots_[i]->bodies()) {
      for (int j = 0, nj = dBodyGetNumJoints(body); j < nj; ++j) {
        const dBodyID other = otherBody(dBodyGetJoint(body, j), body);
        const Robot* joined = other ? static_cast<const Robot*>(dBodyGetData(other)) : nullptr;
        if (joined && joined != robots_[i].get()) group[find(i)] = find(index.at(joined));
      }
    }
  }
  std::vector<char> moving(n, 0);  // a group with an awake robot that is not ready stays awake
  for (int i = 0; i < n; ++i)
    if (!robots_[i]->asleep() && !robots_[i]->restReady()) moving[find(i)] = 1;
  for (int i = 0; i < n; ++i)
    if (robots_[i]->restReady() && !moving[find(i)]) robots_[i]->sleepAtRest();
}

void World::wakeAll() {
  for (auto& r : robots_)
    if (r->asleep()) r->wake();
}

}  // namespace sbot
