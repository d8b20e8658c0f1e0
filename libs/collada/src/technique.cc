#include "caliper/collada/technique.h"

#include "document.h"
#include "extension.h"
#include "import_context.h"

namespace caliper::collada {

size_t ImportTechniqueXml(const std::string& path, const std::string& element, sgal::Scene* scene,
                          std::vector<std::string>* warnings) {
  internal::Document doc;
  try {
    doc = internal::ReadPlainXml(path);
  } catch (const internal::ReadError& e) {
    throw ImportError(path + (e.line() > 0 ? ":" + std::to_string(e.line()) : "") + ": " +
                      e.what());
  }
  std::vector<const internal::Element*> techniques;
  if (doc.root->local_name() == element)
    techniques.push_back(doc.root.get());
  else
    techniques = doc.root->Children(element);
  if (techniques.empty()) return 0;
  internal::Context ctx(doc, warnings);
  ctx.scene = *scene;  // a copy: the caller's scene stays as it was when this throws
  // bodies go by their names; messages about one point at the file's element of that name (a
  // URDF <link>) where there is one
  for (const auto& body : ctx.scene.bodies) {
    const internal::Element* source = nullptr;
    for (const auto& c : doc.root->children)
      if (c->Attribute("name") == body.name && c->local_name() != element) source = c.get();
    ctx.body_source[body.name] = source;
  }
  try {
    for (const internal::Element* t : techniques) internal::ImportTechnique(ctx, *t);
    ctx.ReportRepeated();
  } catch (const ImportError&) {
    throw;
  } catch (const std::exception& e) {
    throw ImportError(path + ": " + e.what());
  }
  *scene = std::move(ctx.scene);
  return techniques.size();
}

}  // namespace caliper::collada
