#pragma once
// Transform helpers: COLLADA's rotations in degrees, affine node transforms split into a rigid
// pose and the scale or shear that geometry has to absorb.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <utility>

#include "caliper/sgal/scene.h"

namespace caliper::collada::internal {

/// The rotation of `degrees` about `axis` (normalised here; a zero axis gives the identity).
Eigen::Matrix3d AxisAngleDegrees(const Eigen::Vector3d& axis, double degrees);

/// (axis, degrees) of a rotation, for <rotate>.
std::pair<Eigen::Vector3d, double> ToAxisAngleDegrees(const Eigen::Quaterniond& q);

/// Splits an affine map into m = rigid * residual: `rigid` a rotation and translation, `residual`
/// the linear rest (scale, shear, mirror; the identity for a rigid m).
void SplitRigid(const Eigen::Affine3d& m, Eigen::Isometry3d* rigid, Eigen::Matrix3d* residual);

/// The rigid part of an affine map, as a pose.
sgal::Pose RigidPose(const Eigen::Affine3d& m);

/// Whether a linear map is the identity within `tolerance` (relative).
bool NearIdentity(const Eigen::Matrix3d& m, double tolerance = 1e-9);

/// The rotation that takes +z onto `axis` (normalised here).
Eigen::Quaterniond RotationZTo(const Eigen::Vector3d& axis);

/// Symmetric positive semi-definite tensor -> principal moments and the rotation whose columns are
/// the principal axes (a proper rotation: det = +1).
void PrincipalAxes(const Eigen::Matrix3d& tensor, Eigen::Vector3d* moments, Eigen::Matrix3d* axes);

}  // namespace caliper::collada::internal
