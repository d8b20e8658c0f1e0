#include "caliper/urdf/model_file.h"

#include <algorithm>
#include <cctype>

#include "caliper/urdf/importer.h"

namespace caliper::model_file {

namespace {

bool EndsWith(const std::string& path, const std::string& ending) {
  if (path.size() < ending.size()) return false;
  return std::equal(ending.rbegin(), ending.rend(), path.rbegin(), [](char a, char b) {
    return a == std::tolower(static_cast<unsigned char>(b));
  });
}

}  // namespace

Format FormatOf(const std::string& path) {
  if (EndsWith(path, ".dae") || EndsWith(path, ".zae")) return Format::kCollada;
  if (EndsWith(path, ".urdf")) return Format::kUrdf;
  return Format::kUnknown;
}

const char* AcceptedEndings() { return "*.dae, *.zae or *.urdf"; }

sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings) {
  switch (FormatOf(path)) {
    case Format::kUrdf:
      return urdf::Import(path, warnings);
    case Format::kCollada:
      return collada::Import(path, warnings);
    case Format::kUnknown:
      break;
  }
  throw collada::ImportError(path + ": not a model file: Caliper loads " +
                             std::string(AcceptedEndings()));
}

}  // namespace caliper::model_file
