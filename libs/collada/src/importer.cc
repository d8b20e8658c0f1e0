#include "caliper/collada/importer.h"

#include <cmath>

#include "document.h"
#include "extension.h"
#include "geometry.h"
#include "import_context.h"
#include "kinematics.h"
#include "physics.h"
#include "visual_scene.h"

namespace caliper::collada {

namespace {

using internal::Context;
using internal::Element;

constexpr double kPi = 3.14159265358979323846;

// <asset>: the unit, the up axis, and who wrote the file.
void ReadAsset(Context& ctx, FileInfo* info) {
  const Element* asset = ctx.doc.root->Child("asset");
  if (asset == nullptr) return;
  if (const Element* unit = asset->Child("unit"); unit != nullptr) {
    info->unit_name = unit->Attribute("name");
    // trust meter, not name: files say name="centimeter" with meter="1"
    const std::string meter = unit->Attribute("meter", "1");
    std::vector<double> v;
    std::string bad;
    if (!internal::ParseNumbers(meter, &v, &bad) || v.size() != 1 || !(v[0] > 0) ||
        !std::isfinite(v[0]))
      ctx.Fail(unit, "meter=\"" + meter + "\" is not a positive number");
    ctx.meter = v[0];
  }
  const Element* up = asset->Child("up_axis");
  const std::string axis = up == nullptr ? "Y_UP" : up->Trimmed();
  info->meter = ctx.meter;
  info->up_axis = axis;
  if (axis == "Y_UP") {
    ctx.up = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  } else if (axis == "X_UP") {
    ctx.up = Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  } else if (axis != "Z_UP") {
    ctx.Fail(up, "unknown up axis '" + axis + "' (X_UP, Y_UP or Z_UP)");
  }
  // round off the rotation's cos(90 deg) residue
  ctx.up = ctx.up.unaryExpr([](double x) { return std::abs(x) < 1e-15 ? 0.0 : x; });
  for (const Element* contributor : asset->Children("contributor")) {
    const Element* tool = contributor->Child("authoring_tool");
    if (tool != nullptr && info->authoring_tool.empty()) info->authoring_tool = tool->Trimmed();
    if (tool != nullptr && tool->text.find("OpenRAVE") != std::string::npos) ctx.openrave = true;
  }
}

// The visual scene <scene> instantiates; the first of the library when it names none.
const Element* VisualSceneOf(Context& ctx) {
  const Element* scene = ctx.doc.root->Child("scene");
  if (scene != nullptr) {
    const auto instances = scene->Children("instance_visual_scene");
    if (!instances.empty()) {
      const Element& vs = ctx.Resolve(*instances.front(), instances.front()->Attribute("url"));
      if (vs.local_name() != "visual_scene")
        ctx.Fail(instances.front(),
                 "url '" + instances.front()->Attribute("url") + "' is not a <visual_scene>");
      return &vs;
    }
  }
  for (const Element* lib : ctx.doc.root->Children("library_visual_scenes"))
    if (const Element* vs = lib->Child("visual_scene"); vs != nullptr) {
      ctx.Warn(vs, "<scene> instantiates no visual scene; using the library's first");
      return vs;
    }
  return nullptr;
}

// sgal::Validate's findings, each named after the element it came from.
void CheckScene(const Context& ctx) {
  const auto problems = sgal::Validate(ctx.scene);
  if (problems.empty()) return;
  // a finding starts "KIND 'NAME'": split with plain string functions (std::regex recurses per
  // character and a name of 100 KB from a file would overflow the stack)
  const std::pair<const char*, const std::map<std::string, const Element*>*> kinds[] = {
      {"body", &ctx.body_source},         {"constraint", &ctx.constraint_source},
      {"obstacle", &ctx.obstacle_source}, {"tendon", &ctx.tendon_source},
      {"actuator", &ctx.actuator_source}};
  std::string message;
  for (const auto& p : problems) {
    const Element* source = nullptr;
    for (const auto& [kind, map] : kinds) {
      const std::string prefix = std::string(kind) + " '";
      if (p.compare(0, prefix.size(), prefix) != 0) continue;
      const size_t end = p.find('\'', prefix.size());
      if (end == std::string::npos) break;
      const auto it = map->find(p.substr(prefix.size(), end - prefix.size()));
      if (it != map->end()) source = it->second;
      break;
    }
    message += (message.empty() ? "" : "\n") + ctx.Where(source) + ": " + p;
  }
  throw ImportError(message);
}

std::string Stem(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

}  // namespace

sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings) {
  return Import(path, warnings, nullptr);
}

sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings, FileInfo* info) {
  FileInfo ignored;
  if (info == nullptr) info = &ignored;
  *info = FileInfo{};
  info->up_axis = "Y_UP";
  internal::Document doc;
  try {
    doc = internal::ReadDocument(path);
  } catch (const internal::ReadError& e) {
    throw ImportError(path + (e.line() > 0 ? ":" + std::to_string(e.line()) : "") + ": " +
                      e.what());
  } catch (const std::exception& e) {
    throw ImportError(path + ": " + e.what());
  }
  info->version = doc.declared_version.empty() ? doc.version : doc.declared_version;
  info->zipped = doc.zipped;
  Context ctx(doc, warnings);
  try {
    for (const auto& w : doc.dom_warnings) ctx.Warn(nullptr, "Collada-DOM: " + w);
    ReadAsset(ctx, info);
    ctx.scene.source = path;
    ctx.scene.name = Stem(path);
    internal::VisualScene visual(&ctx);
    internal::GeometryLibrary geometries(&ctx);
    if (const Element* vs = VisualSceneOf(ctx); vs != nullptr) {
      visual.Build(*vs);
      if (vs->HasAttribute("name")) ctx.scene.name = vs->Attribute("name");
    } else {
      ctx.Warn(nullptr, "no visual scene: the scene has no bodies");
    }
    const size_t rigid_bodies = internal::ImportPhysics(ctx, visual, geometries);
    if (rigid_bodies == 0) {
      size_t drawn = 0;
      for (const auto& n : visual.nodes()) drawn += n.geometry.empty() ? 0 : 1;
      if (drawn > 0) {
        ctx.Warn(nullptr, "no rigid bodies: " + std::to_string(drawn) +
                              " static bodies made from the nodes with geometry");
        internal::MakeStaticBodies(ctx, visual, geometries);
      }
    }
    internal::AttachVisuals(ctx, visual, geometries);
    internal::ImportKinematics(ctx, visual);
    internal::ImportExtension(ctx);
    ctx.ReportRepeated();
    CheckScene(ctx);
  } catch (const ImportError&) {
    throw;
  } catch (const std::exception& e) {
    throw ImportError(path + ": " + e.what());
  }
  return std::move(ctx.scene);
}

}  // namespace caliper::collada
