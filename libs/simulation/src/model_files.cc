#include "caliper/simulation/model_files.h"

#include <cstdlib>

#include "caliper/model_file/model_file.h"

namespace caliper::simulation {

std::vector<core::ConfigKey> ModelFiles::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  return {
      {"model.read_dirs", Type::kString, std::string(CALIPER_SOURCE_DIR) + "/models",
       "directories load_scene reads scenes from, separated by ':' (relative paths start from the "
       "first; the write directory is readable too; other files are sent by content)"},
      {"model.write_dir", Type::kString, "",
       "the directory save_scene writes into ('' = $CALIPER_FILES_DIR, the session's files/ "
       "directory when the launcher started the Model; unset = none: clients fetch "
       "export_scene)"},
      {"model.confine_scene", Type::kBool, "false",
       "model.scene too must lead below model.read_dirs (a manager sets it for the Models it "
       "starts: there a client chose the scene)"},
  };
}

std::string ModelFiles::ResolveScene(const std::string& path) const {
  const std::string scene = read.Resolve(path, core::ConfinedPaths::Access::kRead).string();
  // the meshes are checked as the scene is (links followed, `..` taken physically); the importer
  // then reads them by the references in the file: whoever can change links in a read directory
  // between the check and the read could still lead it elsewhere, a client over CORBA cannot
  for (const std::string& file : model_file::FilesRead(scene)) {
    try {
      read.Resolve(file, core::ConfinedPaths::Access::kRead);
    } catch (const core::PathRefused& e) {
      throw core::PathRefused(scene + " reads another file, which is refused: " + e.what());
    }
  }
  return scene;
}

ModelFiles ModelFiles::FromConfig(const core::Config& config) {
  std::string write_dir = config.GetString("model.write_dir");
  const char* files = std::getenv("CALIPER_FILES_DIR");
  if (write_dir.empty() && files != nullptr) write_dir = files;
  std::vector<std::string> read_dirs = core::SplitSearchPath(config.GetString("model.read_dirs"));
  if (!write_dir.empty()) read_dirs.push_back(write_dir);
  return ModelFiles{core::ConfinedPaths(read_dirs, "model.read_dirs, model.write_dir",
                                        "the Model reads scenes", true),
                    core::ConfinedPaths(write_dir.empty() ? std::vector<std::string>{}
                                                          : std::vector<std::string>{write_dir},
                                        "model.write_dir", "the Model writes scenes", true)};
}

}  // namespace caliper::simulation
