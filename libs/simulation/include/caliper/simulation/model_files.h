#pragma once
// Which files the Model's clients may name by path: load_scene reads only below the model search
// path and the write directory, save_scene writes only below the write directory. Clients with
// files elsewhere (or on other hosts) send and fetch scenes by content.
//
// Configuration:
//   model.read_dirs   directories load_scene reads from, separated by ':' (the project's models/)
//   model.write_dir   the directory save_scene writes into ('' = $CALIPER_FILES_DIR, which the
//                     launcher sets to the session's files/ directory, away from the session
//                     log and the naming service's data; without it no path is writable)
//   model.confine_scene  model.scene too must lead below model.read_dirs (set by a manager for
//                     the Models it starts, whose scene a client chose)
// Relative paths start from the first read directory (load_scene) or the write directory.
// A URDF's meshes (and its side file NAME.caliper.xml) must lie below model.read_dirs too: a
// robot that names a mesh elsewhere is refused as a whole, before anything is read.

#include <string>
#include <vector>

#include "caliper/core/config.h"
#include "caliper/core/confined_path.h"

namespace caliper::simulation {

struct ModelFiles {
  core::ConfinedPaths read;   ///< model.read_dirs, then the write directory
  core::ConfinedPaths write;  ///< the write directory alone (none when unset)

  /// The resolved path of a scene a client named (read.Resolve), once every other file that
  /// importing it reads (a URDF's meshes and side file: model_file::FilesRead) lies below the
  /// same directories. Throws core::PathRefused naming the scene and the file refused, or
  /// collada::ImportError when the URDF is no well-formed XML.
  std::string ResolveScene(const std::string& path) const;

  static std::vector<core::ConfigKey> ConfigKeys();
  /// The directories that `config` (and $CALIPER_FILES_DIR) give.
  static ModelFiles FromConfig(const core::Config& config);
};

}  // namespace caliper::simulation
