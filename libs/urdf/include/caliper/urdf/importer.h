#pragma once
// URDF robot descriptions (ROS's format) to the engine-neutral scene description, beside the
// COLLADA importer: links, joints and their limits, dynamics and mimics, inertials, visual and
// collision geometry with meshes (STL, OBJ, COLLADA) through assimp, and Caliper's own data
// (tendons, actuators, obstacles) from a <caliper> element in the robot or a side file
// `NAME.caliper.xml` next to `NAME.urdf` (docs/urdf.md).
//
// How a URDF becomes a scene:
// - each link is a body named as the link, placed where the link's frame is with every joint at
//   0; the root link is static (fixed to the world) unless Options::floating_base. A root link
//   named `world` (Gazebo's convention) is the world itself, not a body.
// - links joined by a fixed joint are merged into their parent (masses, inertias, shapes and
//   visuals combined; tendon points and obstacles on them move with them) unless
//   Options::merge_fixed_joints is false, when the fixed joint is a fixed constraint;
// - revolute and continuous joints are hinges, prismatic ones sliders, planar ones a 6-DOF
//   constraint free in the plane, floating ones no constraint at all; each keeps the joint's name,
//   its limits, and <dynamics> damping (as a joint damper) and friction (dry friction);
// - <mimic> becomes a coupling q = multiplier * q_leader + offset;
// - the inertia tensor is turned into the link frame (I = R I' R^T with R the <inertial>
//   origin's rotation); principal moments that no rigid body has are raised with a warning;
// - a link without <inertial> on a moving joint gets the default below, with a warning; one
//   merged into its parent adds nothing;
// - the robot's links do not collide with each other unless Options::self_collision (then a
//   link and its parent still do not); they collide with everything else. <gazebo> and
//   <transmission> are ignored; geometry of an unknown kind is skipped with a warning.

#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"

namespace caliper::urdf {

/// A URDF that cannot be imported. The message names the file, the line where it is known, the
/// element and what is wrong: `arm.urdf:42: link 'forearm': ...`. A collada::ImportError, so that
/// what loads either kind of file catches one exception.
class ImportError : public collada::ImportError {
 public:
  using collada::ImportError::ImportError;
};

/// What a link without <inertial> that moves on its own joint gets [kg], with a warning: small
/// enough not to change a robot's dynamics, large enough for the solver. Its inertia is that of a
/// solid sphere of radius kDefaultRadius about the link's origin.
constexpr double kDefaultMass = 0.01;    // [kg]
constexpr double kDefaultRadius = 0.01;  // [m]

struct Options {
  /// Links on fixed joints merged into their parent (true, as MuJoCo and Gazebo do), or kept as
  /// bodies held by fixed constraints.
  bool merge_fixed_joints = true;
  /// The root link free (a mobile robot) instead of fixed to the world.
  bool floating_base = false;
  /// Whether the robot's links collide with each other. Off (as in PyBullet and Gazebo) by
  /// default: URDF collision meshes often overlap where links join, and the overlap would push
  /// them apart at the first step. On, every pair collides but a link and its parent.
  bool self_collision = false;
  /// Folders to find `package://NAME/...` in; empty: $CALIPER_PACKAGE_PATH, then
  /// $ROS_PACKAGE_PATH (each a ':'-separated list). A package is a folder whose package.xml says
  /// <name>NAME</name>, or a folder named NAME, in or directly below one of them.
  std::vector<std::string> package_path;
};

/// Reads a URDF file. Problems the importer works around (a missing <inertial>, impossible
/// inertias, unknown geometry, ignored elements) are appended to `warnings` (may be null), each
/// naming the file, line and element. The scene passes sgal::Validate; everything else (malformed
/// XML, a link with two parents, a loop, a missing mesh with every place tried, a zero mass on a
/// moving link, bad Caliper data) throws ImportError: never a half-loaded scene.
sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings,
                   const Options& options = {});

/// The package search path from the environment: $CALIPER_PACKAGE_PATH's folders, then
/// $ROS_PACKAGE_PATH's.
std::vector<std::string> PackagePathFromEnvironment();

/// Where a mesh reference of a URDF points: `package://NAME/rest` through the package path,
/// `file:///abs` and `file://rel`, a path relative to the URDF's folder, or an absolute path.
/// Returns the existing file; otherwise "" and `tried` lists every place looked at.
std::string ResolveMesh(const std::string& reference, const std::string& urdf_path,
                        const std::vector<std::string>& package_path,
                        std::vector<std::string>* tried);

}  // namespace caliper::urdf
