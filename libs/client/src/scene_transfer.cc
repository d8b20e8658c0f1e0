#include "caliper/client/scene_transfer.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "caliper/collada/importer.h"
#include "caliper/model_file/model_file.h"
#include "caliper/rtc/client_orb.h"

namespace caliper::client {

namespace M = ::Caliper::Simulation;

std::string ReadScene(const std::string& path, std::vector<std::string>* warnings) {
  // ImportError and ExportError (std::runtime_error) name the file
  const std::string bytes = model_file::ContentToSend(path, warnings).bytes;
  const size_t limit = static_cast<size_t>(rtc::kMaxMessageBytes) - (1u << 20);
  if (bytes.size() > limit)
    throw std::runtime_error(path + " is " + std::to_string(bytes.size() >> 20) +
                             " MiB: scenes travel in one CORBA message of at most " +
                             std::to_string(limit >> 20) + " MiB");
  return bytes;
}

std::string SceneFileName(const std::string& path) {
  if (model_file::FormatOf(path) == model_file::Format::kUrdf)
    return std::filesystem::path(path).stem().string() + ".dae";
  return std::filesystem::path(path).filename().string();
}

M::Octets ToOctets(const std::string& bytes) {
  M::Octets out(static_cast<CORBA::ULong>(bytes.size()));
  out.length(static_cast<CORBA::ULong>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(out.get_buffer()));
  return out;
}

bool ModelTakesPath(M::Model_ptr model, const std::string& path,
                    core::ConfinedPaths::Access access) {
  M::FileAccess_var files = model->file_access();
  std::vector<std::string> dirs;
  if (access == core::ConfinedPaths::Access::kRead) {
    for (CORBA::ULong i = 0; i < files->read_dirs.length(); ++i)
      dirs.push_back(files->read_dirs[i].in());
  } else if (*files->write_dir.in() != '\0') {
    dirs.push_back(files->write_dir.in());
  }
  // the Model's COLLADA library reads names as URIs: it refuses '#', '?' and '%'
  const core::ConfinedPaths confined(dirs, "", "", true);
  if (!confined.Allows(path, access)) return false;
  if (access == core::ConfinedPaths::Access::kWrite) return true;
  // a URDF whose meshes lie elsewhere the Model refuses as a whole: convert and send it here
  std::vector<std::string> others;
  try {
    others = model_file::FilesRead(path);
  } catch (const collada::ImportError&) {
    return true;  // not XML: the Model reports it, naming the file
  }
  for (const auto& file : others)
    if (!confined.Allows(file, access)) return false;
  return true;
}

bool SendsByContent(M::Model_ptr model, const std::string& path, bool local, bool force_content,
                    core::ConfinedPaths::Access access) {
  return force_content || !local || !ModelTakesPath(model, path, access);
}

SentScene LoadScene(M::Model_ptr model, const std::string& path, bool by_content) {
  SentScene sent;
  sent.by_content = by_content;
  if (!by_content) {
    sent.file_name = std::filesystem::path(path).filename().string();
    model->load_scene(path.c_str());
    return sent;
  }
  // by content a Model takes COLLADA: a URDF is imported here and sent converted (NAME.dae)
  const std::string bytes = ReadScene(path, &sent.warnings);
  sent.file_name = SceneFileName(path);
  model->load_scene_data(sent.file_name.c_str(), ToOctets(bytes));
  return sent;
}

}  // namespace caliper::client
