#pragma once
// Geometry helpers shared by the importer and the exporter: triangle meshes of the primitive
// shapes, linear maps applied to a geometry, bounds.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>

#include "caliper/sgal/scene.h"

namespace caliper::collada::internal {

/// A triangle mesh of a geometry: primitives tessellated (a plane as a 10 m square), meshes as
/// they are.
std::shared_ptr<const sgal::Mesh> Tessellate(const sgal::Geometry& geometry);

/// The geometry under a linear map `m` (scale, shear, mirror) of its own frame. Primitives stay
/// primitives where the map keeps their kind (a box under an axis-aligned scale, a sphere under a
/// uniform one, ...); otherwise they become a convex hull of their tessellation and
/// `*approximated` is set. Meshes are transformed (normals too).
sgal::Geometry ApplyLinear(const sgal::Geometry& geometry, const Eigen::Matrix3d& m,
                           bool* approximated);

/// Grows `box` by a geometry placed at `pose`; false for a plane (unbounded).
bool ExtendBounds(const sgal::Geometry& geometry, const sgal::Pose& pose, Eigen::AlignedBox3d* box);

}  // namespace caliper::collada::internal
