#pragma once
// MuJoCo 2.2.2's own reading of a URDF file, as an independent reference for Caliper's importer.
//
// How MuJoCo 2.2.2 reads URDF (its src/xml/xml_urdf.cc, checked on this machine):
// - Compiler options come from an optional <mujoco><compiler .../></mujoco> inside <robot>; for
// URDF
//   the defaults are strippath="true" (mesh file names lose their folders and are looked up in
//   meshdir, else beside the file), discardvisual="true" (<visual> geometry is dropped, so a robot
//   with COLLADA visuals and STL collisions still loads) and fusestatic="true" (a link joined by a
//   fixed joint becomes part of its parent body; the root link, which has no joint, is fused into
//   MuJoCo's world body and its mass leaves the model's body masses).
// - It knows nothing of package://: with strippath only the base name is kept. MakeCopy() below
//   rewrites every mesh file name to an absolute path and sets strippath="false".
// - Meshes: STL and OBJ only. A COLLADA (.dae) mesh that is kept is refused with
//   "Unknown mesh file type: <file>".
// - A link named "world" is MuJoCo's world body, not a body of its own.
// - <mimic> is ignored: the follower is an independent joint. Callers set its position.
// - Joint limits become ranges (continuous joints are unlimited); <dynamics> becomes damping and
//   frictionloss; the root is fixed to the world (no free joint) with mj_loadXML.
// - An inertia that breaks the triangle inequality (A + B >= C) is refused with "inertia must
//   satisfy A + B >= C; use 'balanceinertia' to fix" unless balanceinertia="true", which changes
//   only the inertia diagonal, never masses or frames.
// - A link without <inertial> gets its mass from its collision geometry (inertiafromgeom="auto",
//   density 1000 kg/m^3).

#include <Eigen/Core>
#include <map>
#include <memory>
#include <string>
#include <vector>

struct mjModel_;
struct mjData_;

namespace caliper::testing {

/// The <compiler> attributes MakeCopy() writes (MuJoCo's names; see the comment above).
struct MujocoCompiler {
  bool fusestatic = false;  // false: every URDF link but "world" stays a MuJoCo body
  bool balanceinertia = false;
  bool discardvisual = true;
};

/// One joint of the URDF file as liburdfdom reads it (not as Caliper or MuJoCo do).
struct UrdfJoint {
  std::string name;
  std::string type;    // revolute, continuous, prismatic, fixed, floating, planar
  std::string parent;  // link
  std::string child;   // link
  double lower = 0;    // [rad] or [m]; continuous: -pi
  double upper = 0;    // [rad] or [m]; continuous: +pi
  std::string mimic;   // leader joint, "" when none
  double multiplier = 1;
  double offset = 0;  // [rad] or [m]
};

/// The joints of a URDF file in file order, read with liburdfdom. Throws std::runtime_error
/// naming the file when it does not parse.
std::vector<UrdfJoint> ReadUrdfJoints(const std::string& urdf_path);

/// `count` seeded random configurations: every moving joint that is not a mimic follower
/// uniform within its limits (continuous in [-pi, pi]), then every follower
/// multiplier * leader + offset (chains of followers resolved).
std::vector<std::map<std::string, double>> RandomConfigurations(
    const std::vector<UrdfJoint>& joints, int count, unsigned seed);

/// A URDF file compiled by MuJoCo from a readable copy in a temporary folder (removed again).
class MujocoUrdf {
 public:
  /// Writes the copy (mesh file names absolute: package://NAME/... is looked up as NAME/... in
  /// each of `package_dirs`, relative names beside the URDF; a <mujoco><compiler/> element
  /// added), loads it with mj_loadXML and deletes the copy. The source file is never written.
  /// Throws std::runtime_error with MuJoCo's own error text when MuJoCo refuses the file.
  MujocoUrdf(const std::string& urdf_path, const std::vector<std::string>& package_dirs,
             const MujocoCompiler& compiler = {});
  ~MujocoUrdf();
  MujocoUrdf(const MujocoUrdf&) = delete;
  MujocoUrdf& operator=(const MujocoUrdf&) = delete;

  int body_count() const;                       // without MuJoCo's world body
  int joint_count() const;                      // MuJoCo joints (hinges and slides here)
  double total_mass() const;                    // sum of body masses, world excluded [kg]
  std::vector<std::string> body_names() const;  // without the world body
  std::vector<std::string> joint_names() const;
  double body_mass(const std::string& body) const;  // [kg]; throws std::out_of_range

  /// World position of every body's frame (the URDF link frame) after mj_kinematics with the
  /// given joint positions [rad or m]; joints not given stay at zero. Throws
  /// std::out_of_range naming an unknown joint.
  std::map<std::string, Eigen::Vector3d> BodyPositions(
      const std::map<std::string, double>& joint_positions);

 private:
  mjModel_* model_ = nullptr;
  mjData_* data_ = nullptr;
};

/// The text MuJoCo gives when it refuses `urdf_path` (the copy made as above), "" when it loads.
std::string MujocoLoadError(const std::string& urdf_path,
                            const std::vector<std::string>& package_dirs,
                            const MujocoCompiler& compiler = {});

}  // namespace caliper::testing
