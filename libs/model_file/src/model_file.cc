#include "caliper/model_file/model_file.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <set>

#include "caliper/collada/exporter.h"
#include "caliper/core/scratch_directory.h"
#include "caliper/urdf/importer.h"

namespace caliper::model_file {

namespace {

bool EndsWith(const std::string& path, const std::string& ending) {
  if (path.size() < ending.size()) return false;
  return std::equal(ending.rbegin(), ending.rend(), path.rbegin(), [](char a, char b) {
    return a == std::tolower(static_cast<unsigned char>(b));
  });
}

namespace fs = std::filesystem;

[[noreturn]] void Unknown(const std::string& path) {
  throw collada::ImportError(path + ": not a model file: Caliper loads " +
                             std::string(AcceptedEndings()));
}

// every <mesh filename="..."> below `n`, wherever it is: a superset of what urdfdom reads
// (links' visual and collision geometry), so that a check over these misses none of them
void MeshReferences(const xmlNode* n, std::vector<std::string>* out) {
  for (const xmlNode* c = n; c != nullptr; c = c->next) {
    if (c->type != XML_ELEMENT_NODE) continue;
    if (std::strcmp(reinterpret_cast<const char*>(c->name), "mesh") == 0) {
      xmlChar* v = xmlGetProp(c, reinterpret_cast<const xmlChar*>("filename"));
      if (v != nullptr) out->push_back(reinterpret_cast<const char*>(v));
      xmlFree(v);
    }
    MeshReferences(c->children, out);
  }
}

std::string ReadBytes(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw collada::ImportError(path + " cannot be read: no such file");
  if (!fs::is_regular_file(path, ec))
    throw collada::ImportError(path + " cannot be read: not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw collada::ImportError(path + " cannot be read: " + std::strerror(errno));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw collada::ImportError(path + " cannot be read: " + std::strerror(errno));
  return bytes;
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
  Unknown(path);
}

std::vector<std::string> FilesRead(const std::string& path) {
  if (FormatOf(path) != Format::kUrdf) return {};
  std::unique_ptr<xmlParserCtxt, decltype(&xmlFreeParserCtxt)> context(xmlNewParserCtxt(),
                                                                       &xmlFreeParserCtxt);
  if (!context) throw collada::ImportError(path + ": out of memory reading it");
  std::unique_ptr<xmlDoc, decltype(&xmlFreeDoc)> doc(
      xmlCtxtReadFile(context.get(), path.c_str(), nullptr,
                      XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING),
      &xmlFreeDoc);
  if (!doc) {
    const xmlError* e = xmlCtxtGetLastError(context.get());
    std::string why = e != nullptr && e->message != nullptr ? e->message : "not XML\n";
    if (!why.empty() && why.back() == '\n') why.pop_back();
    throw collada::ImportError(path + ":" + std::to_string(e != nullptr ? e->line : 0) +
                               ": malformed XML: " + why);
  }
  std::vector<std::string> references;
  MeshReferences(xmlDocGetRootElement(doc.get()), &references);
  const std::vector<std::string> package_path = urdf::PackagePathFromEnvironment();
  std::vector<std::string> out;
  std::set<std::string> seen;
  auto add = [&](const fs::path& file) {
    std::error_code ec;
    const std::string absolute = fs::absolute(file, ec).lexically_normal().string();
    if (seen.insert(absolute).second) out.push_back(absolute);
  };
  for (const auto& reference : references) {
    const std::string file = urdf::ResolveMesh(reference, path, package_path, nullptr);
    if (!file.empty()) add(file);
  }
  // the side file, where the importer looks for it
  const fs::path side =
      fs::path(path).parent_path() / (fs::path(path).stem().string() + ".caliper.xml");
  std::error_code ec;
  if (fs::exists(fs::symlink_status(side, ec))) add(side);
  return out;
}

Content ContentToSend(const std::string& path, std::vector<std::string>* warnings) {
  switch (FormatOf(path)) {
    case Format::kCollada:
      return {fs::path(path).filename().string(), ReadBytes(path)};
    case Format::kUrdf: {
      const sgal::Scene scene = urdf::Import(path, warnings);
      const std::string name = fs::path(path).stem().string() + ".dae";
      std::optional<core::ScratchDirectory> scratch;
      try {
        scratch.emplace("caliper-urdf");
      } catch (const std::runtime_error& e) {
        throw collada::ExportError(e.what());
      }
      const std::string file = scratch->path() + "/scene.dae";
      collada::Export(scene, file);
      return {name, ReadBytes(file)};
    }
    case Format::kUnknown:
      break;
  }
  Unknown(path);
}

}  // namespace caliper::model_file
