#include "caliper/client/scene_transfer.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "caliper/collada/importer.h"
#include "caliper/model_file/model_file.h"
#include "caliper/rtc/client_orb.h"

namespace caliper::client {

namespace M = ::Caliper::Simulation;

namespace {

// what a file sent by content may weigh: one message, less 1 MiB for the rest of the call
void CheckFitsOneMessage(const std::string& path, size_t bytes, const std::string& what) {
  const size_t limit = static_cast<size_t>(rtc::kMaxMessageBytes) - (1u << 20);
  if (bytes > limit)
    throw std::runtime_error(path + " is " + std::to_string(bytes >> 20) + " MiB: " + what +
                             " travel in one CORBA message of at most " +
                             std::to_string(limit >> 20) + " MiB");
}

}  // namespace

std::string ReadScene(const std::string& path, std::vector<std::string>* warnings) {
  // ImportError and ExportError (std::runtime_error) name the file
  const std::string bytes = model_file::ContentToSend(path, warnings).bytes;
  CheckFitsOneMessage(path, bytes.size(), "scenes");
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

OpenedReplay OpenReplay(M::Model_ptr model, const std::string& file, bool local,
                        bool force_content) {
  OpenedReplay opened;
  std::error_code ec;
  const std::string path = std::filesystem::absolute(file, ec).string();
  if (!force_content && !std::filesystem::exists(path, ec)) {
    // not a file of this host: the Model's own, a relative name starting from its write
    // directory, as `recording start NAME` names them (also on another host)
    std::string for_model = file;
    M::FileAccess_var files = model->file_access();
    if (std::filesystem::path(file).is_relative() && *files->write_dir.in() != '\0')
      for_model = std::string(files->write_dir.in()) + "/" + file;
    M::ReplayStatus_var s = model->open_replay(for_model.c_str());
    opened.status = s.in();
    return opened;
  }
  bool by_path = local && !force_content;
  if (by_path) {
    // the Model reads recordings below its read directories and its write directory
    M::FileAccess_var files = model->file_access();
    std::vector<std::string> dirs;
    for (CORBA::ULong i = 0; i < files->read_dirs.length(); ++i)
      dirs.push_back(files->read_dirs[i].in());
    if (*files->write_dir.in() != '\0') dirs.push_back(files->write_dir.in());
    by_path = core::ConfinedPaths(dirs, "", "", true).Allows(path, core::ConfinedPaths::Access::kRead);
  }
  if (by_path) {
    M::ReplayStatus_var s = model->open_replay(path.c_str());
    opened.status = s.in();
    return opened;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read it: " + std::strerror(errno));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error(path + ": cannot read it: " + std::strerror(errno));
  CheckFitsOneMessage(path, bytes.size(), "recordings sent by content");
  opened.by_content = true;
  M::ReplayStatus_var s = model->open_replay_data(
      std::filesystem::path(path).filename().string().c_str(), ToOctets(bytes));
  opened.status = s.in();
  return opened;
}

}  // namespace caliper::client
