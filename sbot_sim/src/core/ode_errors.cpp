#include "ode_errors.h"

#include <unistd.h>

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sbot_sim/core/geom_info.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/world.h"

namespace sbot {
namespace {

struct OdeContext {
  const World* world = nullptr;
  const char* phase = nullptr;
  dGeomID a = nullptr, b = nullptr;
};
thread_local OdeContext g_context;

/// "robot 'sbot_0' body 'base_link' (geom of link 'left_wheel')", "box 'step'", "the ground plane".
std::string describeGeom(dGeomID g) {
  if (!g) return "?";
  if (dGeomIsSpace(g)) {
    const auto* robot = static_cast<const Robot*>(dGeomGetData(g));
    return robot ? "robot '" + robot->name() + "' (its space)" : "a space";
  }
  const auto* info = static_cast<const GeomInfo*>(dGeomGetData(g));
  if (!info) return "a geom without owner";
  if (!info->robot) return "terrain '" + info->link + "'";
  std::string text = "robot '" + info->robot->name() + "' link '" + info->link + "'";
  // The body the geom moves with: its index among the robot's bodies names it in a bug report.
  if (dBodyID body = dGeomGetBody(g)) {
    const dReal* p = dBodyGetPosition(body);
    char where[96];
    std::snprintf(where, sizeof where, " (body at %.4g, %.4g, %.4g m)", p[0], p[1], p[2]);
    text += where;
  }
  return text;
}

std::string context() {
  const OdeContext& c = g_context;
  if (!c.world) return "outside a world step (building or changing a world)";
  std::string text = "at step " + std::to_string(c.world->stepCount() + 1) + " (t = " +
                     std::to_string(c.world->time()) + " s)";
  if (c.a || c.b) text += ", colliding " + describeGeom(c.a) + " with " + describeGeom(c.b);
  else if (c.phase) text += std::string(", in ") + c.phase;
  return text;
}

[[noreturn]] void fatal(const char* kind, int num, const char* msg, va_list ap) {
  char what[512];
  std::vsnprintf(what, sizeof what, msg, ap);
  std::fflush(stdout);  // rows or logs printed so far go out before the message
  std::fprintf(stderr, "ODE %s (%d) %s: %s; ending the run (exit status 1)\n", kind, num, context().c_str(), what);
  std::fflush(stderr);
  std::_Exit(1);
}

void odeError(int num, const char* msg, va_list ap) { fatal("error", num, msg, ap); }
void odeDebug(int num, const char* msg, va_list ap) { fatal("internal check failed", num, msg, ap); }

void odeMessage(int num, const char* msg, va_list ap) {
  static std::atomic<long> count{0};
  const long n = ++count;
  if (n > 10 && n % 1000 != 0) return;
  std::fprintf(stderr, "ODE message %d (%ld so far) %s: ", num, n, context().c_str());
  std::vfprintf(stderr, msg, ap);
  std::fprintf(stderr, "\n");
}

}  // namespace

void installOdeHandlers() {
  dSetErrorHandler(&odeError);
  dSetDebugHandler(&odeDebug);
  dSetMessageHandler(&odeMessage);
}

OdeStepScope::OdeStepScope(const World& world) { g_context = OdeContext{&world, nullptr, nullptr, nullptr}; }
OdeStepScope::~OdeStepScope() { g_context = OdeContext{}; }

void noteOdePair(dGeomID a, dGeomID b) {
  g_context.a = a;
  g_context.b = b;
}

void noteOdePhase(const char* phase) {
  g_context.phase = phase;
  g_context.a = g_context.b = nullptr;
}

}  // namespace sbot
