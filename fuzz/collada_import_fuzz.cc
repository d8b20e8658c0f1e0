// Fuzz target: the COLLADA importer (libxml2's pre-scan, both Collada-DOM versions, visual
// scenes, geometry, physics, kinematics and the Caliper extension) on one .dae file.
// Properties: Import either returns a scene that sgal::Validate accepts or throws ImportError
// whose message names the file; every warning names the file too. Anything else escaping, a
// sanitizer report, a hang or a leak is a finding.
#include <cstdint>
#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using caliper::fuzz::Check;
  const caliper::fuzz::InputFile input(data, size, "input.dae");
  const std::string& path = input.path();
  std::vector<std::string> warnings;
  caliper::collada::FileInfo info;
  try {
    const caliper::sgal::Scene scene = caliper::collada::Import(path, &warnings, &info);
    const auto problems = caliper::sgal::Validate(scene);
    Check(problems.empty(), "Import returned a scene that sgal::Validate rejects: " +
                                (problems.empty() ? std::string() : problems.front()));
  } catch (const caliper::collada::ImportError& e) {
    const std::string message = e.what();
    Check(message.rfind(path, 0) == 0, "an ImportError that does not start with the file: " +
                                           message.substr(0, 300));
  }
  for (const auto& w : warnings)
    Check(w.rfind(path, 0) == 0, "a warning that does not start with the file: " + w.substr(0, 300));
  return 0;
}
