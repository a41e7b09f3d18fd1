// The ODE handles the core's public headers name, as opaque pointers: the World and Robot keep
// their bodies, joints and geoms in them, and the core's own modules (actuators, sensors, model
// switching) pass them around. The engine's functions and types are not declared here: only the
// core's .cpp files include <ode/ode.h>, so a tool that includes world.h or robot.h can reach ODE
// only through World's and Robot's methods. These declarations are ODE's own (ode/common.h,
// ode/collision.h), so they name the same types wherever both are seen.
#pragma once

#include <memory>

struct dxWorld;
struct dxSpace;
struct dxBody;
struct dxGeom;
struct dxJoint;
struct dxJointGroup;
struct dxHeightfieldData;
typedef struct dxWorld* dWorldID;
typedef struct dxSpace* dSpaceID;
typedef struct dxBody* dBodyID;
typedef struct dxGeom* dGeomID;
typedef struct dxJoint* dJointID;
typedef struct dxJointGroup* dJointGroupID;
typedef struct dxHeightfieldData* dHeightfieldDataID;
/// ODE's record of the forces a joint applied in the last step (filled in by the solver).
struct dJointFeedback;
/// ODE's contact surface (friction, softness, slip) that contact effects adjust.
struct dSurfaceParameters;

namespace sbot {
namespace detail {

/// Frees a dJointFeedback of newJointFeedback() (defined where ODE is seen: ode_handles.cpp).
struct JointFeedbackDeleter {
  void operator()(dJointFeedback* feedback) const;
};
using JointFeedbackPtr = std::unique_ptr<dJointFeedback, JointFeedbackDeleter>;
/// A zeroed feedback record, for dJointSetFeedback.
JointFeedbackPtr newJointFeedback();

}  // namespace detail
}  // namespace sbot
