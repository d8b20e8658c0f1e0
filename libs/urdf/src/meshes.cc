#include "meshes.h"

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <libxml/parser.h>
#include <libxml/tree.h>

#include <assimp/Importer.hpp>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "caliper/urdf/importer.h"

namespace caliper::urdf {

namespace fs = std::filesystem;

namespace {

// The <name> a package.xml gives its package; "" when it has none or cannot be read.
std::string PackageName(const fs::path& manifest) {
  std::error_code ec;
  if (!fs::is_regular_file(manifest, ec)) return "";
  xmlDocPtr doc = xmlReadFile(manifest.c_str(), nullptr,
                              XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
  if (doc == nullptr) return "";
  std::string name;
  const xmlNode* root = xmlDocGetRootElement(doc);
  for (const xmlNode* c = root != nullptr ? root->children : nullptr; c != nullptr; c = c->next) {
    if (c->type != XML_ELEMENT_NODE || std::strcmp(reinterpret_cast<const char*>(c->name), "name"))
      continue;
    xmlChar* text = xmlNodeGetContent(c);
    if (text != nullptr) name = reinterpret_cast<const char*>(text);
    xmlFree(text);
    break;
  }
  xmlFreeDoc(doc);
  const size_t b = name.find_first_not_of(" \t\r\n");
  const size_t e = name.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : name.substr(b, e - b + 1);
}

// Every package in or below `dir` by its name, as ROS finds packages: a folder whose package.xml
// names it (not looking inside a package for another). Walked once per folder of the package
// path, whatever number of packages a URDF names; bounded, as a package path may name a large
// workspace.
std::multimap<std::string, std::string> PackagesIn(const fs::path& dir) {
  std::multimap<std::string, std::string> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  if (const std::string own = PackageName(dir / "package.xml"); !own.empty()) {
    out.emplace(own, dir.string());
    return out;
  }
  constexpr int kMaxDepth = 6;
  constexpr size_t kMaxEntries = 100000;
  size_t looked = 0;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
  for (; !ec && it != end && looked < kMaxEntries; it.increment(ec), ++looked) {
    std::error_code type_ec;
    if (!it->is_directory(type_ec) || it.depth() >= kMaxDepth) {
      if (it->is_directory(type_ec)) it.disable_recursion_pending();
      continue;
    }
    const std::string leaf = it->path().filename().string();
    if (!leaf.empty() && leaf[0] == '.') {  // .git and the like
      it.disable_recursion_pending();
      continue;
    }
    std::error_code manifest_ec;
    if (!fs::is_regular_file(it->path() / "package.xml", manifest_ec)) continue;
    it.disable_recursion_pending();  // a package: not searched further inside
    if (const std::string name = PackageName(it->path() / "package.xml"); !name.empty())
      out.emplace(name, it->path().string());
  }
  return out;
}

void SplitInto(const char* list, std::vector<std::string>* out) {
  if (list == nullptr) return;
  const std::string s(list);
  size_t start = 0;
  while (start <= s.size()) {
    const size_t end = std::min(s.find(':', start), s.size());
    if (end > start) out->push_back(s.substr(start, end - start));
    start = end + 1;
  }
}

}  // namespace

std::vector<std::string> PackagePathFromEnvironment() {
  std::vector<std::string> out;
  SplitInto(std::getenv("CALIPER_PACKAGE_PATH"), &out);
  SplitInto(std::getenv("ROS_PACKAGE_PATH"), &out);
  return out;
}

std::string ResolveMesh(const std::string& reference, const std::string& urdf_path,
                        const std::vector<std::string>& package_path,
                        std::vector<std::string>* tried) {
  internal::PackageFinder finder;
  finder.SetPath(package_path);
  return finder.Resolve(reference, urdf_path, tried);
}

namespace internal {

std::string PackageFinder::Resolve(const std::string& reference, const std::string& urdf_path,
                                   std::vector<std::string>* tried) {
  std::vector<std::string> ignored;
  if (tried == nullptr) tried = &ignored;
  std::error_code ec;
  const fs::path base = fs::path(urdf_path).parent_path();
  auto found = [&](const fs::path& p) {
    tried->push_back(p.string());
    return fs::is_regular_file(p, ec);
  };
  const std::string package_scheme = "package://";
  const std::string file_scheme = "file://";
  if (reference.compare(0, package_scheme.size(), package_scheme) == 0) {
    const std::string rest = reference.substr(package_scheme.size());
    const size_t slash = rest.find('/');
    const std::string name = rest.substr(0, slash);
    const std::string inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
    if (name.empty() || inside.empty()) {
      tried->push_back("(not a package reference: package://NAME/PATH)");
      return "";
    }
    for (const auto& dir : path_) {
      auto known = index_.find(dir);
      if (known == index_.end()) known = index_.emplace(dir, PackagesIn(dir)).first;
      // a folder called NAME directly in the folder of the path, then those package.xml names
      std::vector<fs::path> packages;
      if (fs::is_directory(fs::path(dir) / name, ec)) packages.push_back(fs::path(dir) / name);
      const auto [first, last] = known->second.equal_range(name);
      for (auto p = first; p != last; ++p)
        if (fs::path(p->second) != fs::path(dir) / name) packages.push_back(p->second);
      if (packages.empty()) tried->push_back("(no package '" + name + "' in or below " + dir + ")");
      for (const auto& package : packages)
        if (found(package / inside)) return (package / inside).string();
    }
    if (path_.empty())
      tried->push_back("(no package path: $CALIPER_PACKAGE_PATH and $ROS_PACKAGE_PATH are empty)");
    // the folders above the URDF: a robot kept inside its own package resolves without a path
    bool above = false;
    for (fs::path up = fs::absolute(base, ec); !up.empty(); up = up.parent_path()) {
      if (PackageName(up / "package.xml") == name) {
        above = true;
        if (found(up / inside)) return (up / inside).string();
      }
      if (up == up.parent_path()) break;
    }
    if (!above)
      tried->push_back("(no folder above " + base.string() + " is package '" + name + "')");
    return "";
  }
  fs::path p = reference;
  if (reference.compare(0, file_scheme.size(), file_scheme) == 0)
    p = reference.substr(file_scheme.size());
  if (p.is_relative()) p = base / p;
  return found(p) ? p.string() : "";
}

MeshFile MeshLoader::Load(const std::string& given, const Eigen::Vector3d& scale) {
  // one file by whatever path it was named (m/x.stl, ./m/x.stl, a link to it)
  std::error_code ec;
  fs::path canonical = fs::weakly_canonical(given, ec);
  const std::string file = ec ? given : canonical.string();
  const auto key = std::make_tuple(file, scale.x(), scale.y(), scale.z());
  if (const auto it = scaled_.find(key); it != scaled_.end()) return it->second;
  auto raw = files_.find(file);
  if (raw == files_.end()) {
    Assimp::Importer importer;
    // ROS ignores a mesh file's up axis; its unit (COLLADA <unit meter>) is applied
    importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
    // lines and points are of no use to a body
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene =
        importer.ReadFile(file, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (scene == nullptr)
      throw std::runtime_error("assimp cannot read it: " + std::string(importer.GetErrorString()));
    auto mesh = std::make_shared<sgal::Mesh>();
    MeshFile out;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* am = scene->mMeshes[m];
      const auto first = static_cast<uint32_t>(mesh->vertices.size());
      for (unsigned v = 0; v < am->mNumVertices; ++v) {
        const aiVector3D& p = am->mVertices[v];
        mesh->vertices.emplace_back(p.x, p.y, p.z);
        if (am->mNormals != nullptr)
          mesh->normals.emplace_back(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
      }
      for (unsigned f = 0; f < am->mNumFaces; ++f) {
        const aiFace& face = am->mFaces[f];
        if (face.mNumIndices != 3) continue;
        mesh->triangles.push_back(
            {first + face.mIndices[0], first + face.mIndices[1], first + face.mIndices[2]});
      }
      aiColor4D diffuse;
      if (!out.color && am->mMaterialIndex < scene->mNumMaterials &&
          scene->mMaterials[am->mMaterialIndex]->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) ==
              AI_SUCCESS)
        out.color = Eigen::Vector4f(diffuse.r, diffuse.g, diffuse.b, diffuse.a);
    }
    if (mesh->normals.size() != mesh->vertices.size()) mesh->normals.clear();
    if (mesh->triangles.empty()) throw std::runtime_error("it holds no triangles");
    for (const auto& v : mesh->vertices)
      if (!v.allFinite()) throw std::runtime_error("it holds a vertex that is not a finite number");
    out.mesh = std::move(mesh);
    raw = files_.emplace(file, std::move(out)).first;
  }
  MeshFile result = raw->second;
  if (scale != Eigen::Vector3d::Ones()) {
    auto mesh = std::make_shared<sgal::Mesh>(*result.mesh);
    const Eigen::Vector3f s = scale.cast<float>();
    for (auto& v : mesh->vertices) v = v.cwiseProduct(s);
    // normals go with the inverse transpose; a mirror turns the triangles inside out
    for (auto& n : mesh->normals) n = n.cwiseQuotient(s).normalized();
    for (const auto& v : mesh->vertices)
      if (!v.allFinite()) throw std::runtime_error("scaled, it holds a vertex beyond float range");
    if (s.prod() < 0)
      for (auto& t : mesh->triangles) std::swap(t[1], t[2]);
    result.mesh = std::move(mesh);
  }
  scaled_.emplace(key, result);
  return result;
}

}  // namespace internal
}  // namespace caliper::urdf
