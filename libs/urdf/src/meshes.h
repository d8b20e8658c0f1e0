#pragma once
// Mesh files of a URDF: where a reference points (package://, file://, relative paths) and their
// triangles through assimp, each file read once per import.

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::urdf::internal {

/// A mesh file read through assimp: every triangle of every mesh in it, in the file's root frame
/// (node transforms and a COLLADA file's <unit> applied; its <up_axis> ignored, as ROS does),
/// and the first material's diffuse colour when it has one.
struct MeshFile {
  std::shared_ptr<const sgal::Mesh> mesh;
  std::optional<Eigen::Vector4f> color;
};

/// Finds `package://` references' packages in a package path (urdf::ResolveMesh's rules), each
/// folder of the path walked once per import, however many packages the URDF names.
class PackageFinder {
 public:
  void SetPath(std::vector<std::string> path) { path_ = std::move(path); }
  /// As urdf::ResolveMesh with this finder's path.
  std::string Resolve(const std::string& reference, const std::string& urdf_path,
                      std::vector<std::string>* tried);

 private:
  std::vector<std::string> path_;
  // each folder of the path walked once: package name -> its folders
  std::map<std::string, std::multimap<std::string, std::string>> index_;
};

class MeshLoader {
 public:
  /// The mesh of `file` scaled by `scale` (per axis; a mirroring scale turns the triangles). Reads
  /// each file once. Throws std::runtime_error with assimp's reason when it cannot be read or has
  /// no triangles.
  MeshFile Load(const std::string& file, const Eigen::Vector3d& scale);
  /// How many files were read (tests: each file once per scene).
  size_t files_read() const { return files_.size(); }

 private:
  std::map<std::string, MeshFile> files_;
  std::map<std::tuple<std::string, double, double, double>, MeshFile> scaled_;
};

}  // namespace caliper::urdf::internal
