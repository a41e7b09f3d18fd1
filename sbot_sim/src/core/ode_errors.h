// ODE's error, debug and message handlers (core-internal; ode/ode.h stays out of the public headers).
//
// ODE reports a broken internal invariant (a zero-length normal in dxNormalize3, a locked space, a
// bad mass) through dError / dDebug, whose default handlers abort(): the simulator died with signal 6
// and nothing said which robot or body. installOdeHandlers() replaces them: the handler prints what
// ODE said together with what the world was doing (the step, and the robot, body and geom of the
// collision pair or the solver phase in progress) and ends the process with exit status 1 (a failure
// during the work; tools' exit statuses: sbot_sim/tools/cli_args.h).
//
// Why exit rather than throw: libode is C++ built with unwind tables, and a C++ exception thrown
// from the handler does propagate through dSpaceCollide / dSpaceCollide2 to the caller. But ODE then
// leaves the spaces it was colliding locked, and tearing the world down afterwards fails ODE's
// "Invalid operation for locked space in ~dxSpace()" check inside a destructor, which ends in
// std::terminate and abort() again (measured with Debian's libode 0.16.2). ODE's dError must not
// return and dDebug aborts if its handler does, so no handler can resume the step either. Ending the
// process from the handler, after flushing what was printed, is the one way that never reaches
// abort(). Input is validated at load time (scenario boxes, URDF shapes: input_limits.h) so that
// these checks do not fire in the first place; the handler is the net below that.
//
// dMessage (informational, the step goes on) is printed with the same context, rate-limited.
#pragma once

#include <ode/ode.h>

namespace sbot {

class World;

/// Install the three handlers (idempotent; call after dInitODE2).
void installOdeHandlers();

/// What the world on this thread is doing, for a message from ODE. A World::step sets it up for its
/// duration (OdeStepScope); the collision callback notes each pair it collides; the solver phase is
/// noted before dWorldQuickStep / dWorldStep.
class OdeStepScope {
 public:
  explicit OdeStepScope(const World& world);
  ~OdeStepScope();
  OdeStepScope(const OdeStepScope&) = delete;
  OdeStepScope& operator=(const OdeStepScope&) = delete;
};
/// The pair of geoms being collided now (null, null: none).
void noteOdePair(dGeomID a, dGeomID b);
/// The phase of the step now, e.g. "the solver (dWorldQuickStep)" (a string literal).
void noteOdePhase(const char* phase);

}  // namespace sbot
