// The out-of-line half of sbot_sim/core/detail/ode_handles.h, where ODE's types are complete.
#include "sbot_sim/core/detail/ode_handles.h"

#include <type_traits>

#include <ode/ode.h>

namespace sbot {
namespace detail {

// World::BoxedGeom keeps ODE's bounding boxes as double[6]: ODE must be built in double precision.
static_assert(std::is_same<dReal, double>::value, "the core expects ODE in double precision (dDOUBLE)");

void JointFeedbackDeleter::operator()(dJointFeedback* feedback) const { delete feedback; }

JointFeedbackPtr newJointFeedback() { return JointFeedbackPtr(new dJointFeedback{}); }

}  // namespace detail
}  // namespace sbot
