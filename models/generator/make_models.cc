// make_models: writes the shipped models (models.h) as COLLADA files into models/, or into the
// directory given. Not run by the build; run it after changing a model and commit the files:
//   ninja -C build make_models && build/bin/make_models
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"
#include "models.h"

int main(int argc, char** argv) {
  if (argc > 2 || (argc == 2 && (std::string(argv[1]) == "--help" || argv[1][0] == '-'))) {
    std::fprintf(stderr,
                 "Usage: make_models [DIR]\n  writes the shipped models to DIR (default %s)\n",
                 CALIPER_MODELS_DIR);
    return argc == 2 && std::string(argv[1]) == "--help" ? 0 : 2;
  }
  const std::string dir = argc == 2 ? argv[1] : CALIPER_MODELS_DIR;
  int failures = 0;
  for (const caliper::models::Model& model : caliper::models::AllModels()) {
    const std::string path = dir + "/" + model.file;
    try {
      const auto problems = caliper::sgal::Validate(model.scene);
      for (const auto& p : problems)
        std::fprintf(stderr, "%s: %s\n", model.file.c_str(), p.c_str());
      if (!problems.empty()) {
        ++failures;
        continue;
      }
      caliper::collada::Export(model.scene, path);
      // read it back: a file the importer warns about is not shipped silently
      std::vector<std::string> warnings;
      caliper::collada::Import(path, &warnings);
      for (const auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
      std::printf("%s: %zu bodies, %zu constraints, %zu tendons, %zu actuators\n", path.c_str(),
                  model.scene.bodies.size(), model.scene.constraints.size(),
                  model.scene.tendons.size(), model.scene.actuators.size());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), e.what());
      ++failures;
    }
  }
  return failures == 0 ? 0 : 1;
}
