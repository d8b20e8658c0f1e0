#pragma once
// COLLADA 1.5 kinematics: the joints (revolute, prismatic, with limits) that an
// <instance_kinematics_scene> binds to transform elements of visual nodes become constraints
// between the bodies those nodes belong to; <formula>s of the form a = r b + c become couplings.

#include "import_context.h"
#include "visual_scene.h"

namespace caliper::collada::internal {

/// Adds the constraints and couplings of the kinematics scenes that <scene> instantiates.
void ImportKinematics(Context& ctx, const VisualScene& visual);

}  // namespace caliper::collada::internal
