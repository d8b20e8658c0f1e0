// Fuzz target: the URDF importer through the entry point every loader uses (model_file::Import:
// liburdfdom, libxml2's reading of lines and of what urdfdom accepts silently, assimp's meshes,
// the Caliper technique in the URDF and in its side file), and the conversion a client sends by
// content (model_file::ContentToSend: the robot exported as COLLADA), read back.
// Input: the URDF, then optionally a line `@@` and an STL mesh, a line `@@` and an OBJ mesh, a
// line `@@` and the side file NAME.caliper.xml. The URDF names the meshes "FUZZ-mesh.stl" and
// "FUZZ-mesh.obj" (`FUZZ-` is replaced by this process's file prefix, relative to the URDF's
// folder); a part that is absent is no file at all.
// Properties: Import either returns a scene that sgal::Validate accepts or throws ImportError
// whose message starts with one of the input files; every warning too. An imported robot
// converts to COLLADA, which imports back with as many bodies, constraints, tendons and
// actuators. Anything else escaping, a sanitizer report, a hang or a leak is a finding.
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"
#include "caliper/model_file/model_file.h"
#include "fuzz_input.h"

namespace {

using caliper::fuzz::Check;
using caliper::fuzz::InputFile;

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

std::unique_ptr<InputFile> Part(const std::vector<std::string>& parts, size_t i,
                                const std::string& name) {
  if (i >= parts.size()) return nullptr;
  return std::make_unique<InputFile>(reinterpret_cast<const uint8_t*>(parts[i].data()),
                                     parts[i].size(), name);
}

bool StartsWithOneOf(const std::string& message, const std::vector<std::string>& paths) {
  for (const auto& p : paths)
    if (!p.empty() && message.rfind(p, 0) == 0) return true;
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool environment_set = [] {
    // the COLLADA conversion goes through a temporary directory: in memory, as the inputs are
    if (access("/dev/shm", W_OK) == 0) setenv("TMPDIR", "/dev/shm", 0);
    // no package path: a package:// mesh resolves only in the folders above the input
    setenv("CALIPER_PACKAGE_PATH", "", 1);
    setenv("ROS_PACKAGE_PATH", "", 1);
    return true;
  }();
  (void)environment_set;
  const std::vector<std::string> parts = caliper::fuzz::Parts(data, size, 4);
  const auto stl = Part(parts, 1, "mesh.stl");
  const auto obj = Part(parts, 2, "mesh.obj");
  const auto side = Part(parts, 3, "input.caliper.xml");
  // the prefix of this process's files (fuzz_input.h), as the URDF names the meshes
  const std::string prefix = "caliper-fuzz-" + std::to_string(getpid()) + "-";
  const std::string urdf_text = Replace(parts[0], "FUZZ-", prefix);
  const InputFile urdf(reinterpret_cast<const uint8_t*>(urdf_text.data()), urdf_text.size(),
                       "input.urdf");
  const std::string& path = urdf.path();
  const std::vector<std::string> files = {path, stl ? stl->path() : "", obj ? obj->path() : "",
                                          side ? side->path() : ""};

  std::vector<std::string> warnings;
  caliper::sgal::Scene scene;
  bool imported = false;
  try {
    scene = caliper::model_file::Import(path, &warnings);
    imported = true;
  } catch (const caliper::collada::ImportError& e) {
    Check(StartsWithOneOf(e.what(), files),
          "an ImportError that does not start with an input file: " +
              std::string(e.what()).substr(0, 300));
  }
  for (const auto& w : warnings)
    Check(StartsWithOneOf(w, files),
          "a warning that does not start with an input file: " + w.substr(0, 300));
  if (!imported) return 0;
  const auto problems = caliper::sgal::Validate(scene);
  Check(problems.empty(), "Import returned a scene that sgal::Validate rejects: " +
                              (problems.empty() ? std::string() : problems.front()));

  // what a client sends by content for it, read back as a Model would
  caliper::model_file::Content content;
  try {
    content = caliper::model_file::ContentToSend(path, nullptr);
  } catch (const std::exception& e) {
    Check(false, std::string("an imported robot did not convert to COLLADA: ") + e.what());
  }
  const InputFile dae(reinterpret_cast<const uint8_t*>(content.bytes.data()), content.bytes.size(),
                      "converted.dae");
  caliper::sgal::Scene back;
  try {
    back = caliper::collada::Import(dae.path(), nullptr);
  } catch (const caliper::collada::ImportError& e) {
    Check(false, std::string("the COLLADA conversion does not import: ") + e.what());
  }
  Check(back.bodies.size() == scene.bodies.size(), "the conversion has another number of bodies");
  Check(back.constraints.size() == scene.constraints.size(),
        "the conversion has another number of constraints");
  Check(back.tendons.size() == scene.tendons.size(),
        "the conversion has another number of tendons");
  Check(back.actuators.size() == scene.actuators.size(),
        "the conversion has another number of actuators");
  return 0;
}
