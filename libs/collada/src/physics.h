#pragma once
// Physics: <physics_scene> (gravity, time step), <physics_model> rigid bodies (mass, mass frame,
// inertia, shapes, materials) bound to visual nodes, <rigid_constraint> with limits and springs;
// bodies made up for files without physics; the visuals of every node.

#include "geometry.h"
#include "import_context.h"
#include "visual_scene.h"

namespace caliper::collada::internal {

/// Reads the physics scenes that <scene> instantiates into ctx.scene (materials, gravity, time
/// step, bodies, constraints). Returns the number of rigid bodies.
size_t ImportPhysics(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries);

/// A file without rigid bodies: one static body per node instance that draws geometry, its
/// meshes as collision shapes.
void MakeStaticBodies(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries);

/// Gives each body the visuals of the nodes it moves: its own node's and those of descendants
/// without a body of their own. Geometry of a node that no body moves gets a static body.
void AttachVisuals(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries);

/// Reads the <extra type="caliper"> of a rigid constraint (kind, springs of each degree of
/// freedom) into `c`; returns whether it named the kind.
bool ReadConstraintExtra(Context& ctx, const Element& owner, sgal::Constraint* c);

}  // namespace caliper::collada::internal
