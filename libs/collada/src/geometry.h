#pragma once
// <geometry> to triangle meshes: <mesh> and <convex_mesh> with triangles, polylist, polygons
// (convex ones fanned, concave ones ear-clipped), tristrips and trifans; and the diffuse colours
// that bound materials give them.

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"
#include "document.h"
#include "import_context.h"

namespace caliper::collada::internal {

/// The triangles of one material of a geometry, for drawing.
struct MeshPart {
  std::string material;                    // the primitive's material symbol ("" when none)
  std::shared_ptr<const sgal::Mesh> mesh;  // with per-vertex normals when the file has them
};

/// A geometry as the scene uses it. Positions are in metres (the document's unit applied).
struct GeometryData {
  bool usable = false;  // false for what we do not read (splines, B-reps, empty meshes)
  bool convex = false;  // a <convex_mesh>
  std::shared_ptr<const sgal::Mesh> all;    // every triangle over the positions (collision)
  std::vector<MeshPart> parts;              // by material (drawing)
  std::optional<sgal::Geometry> primitive;  // the exact primitive a Caliper exporter noted
};

/// The geometries of a document, each read once.
class GeometryLibrary {
 public:
  explicit GeometryLibrary(Context* context) : ctx_(*context) {}

  /// The data of a <geometry> element (read on first use).
  const GeometryData& Get(const Element& geometry);

 private:
  GeometryData Read(const Element& geometry);
  Context& ctx_;
  std::map<const Element*, GeometryData> cache_;
};

/// The diffuse colour (RGBA) that an <instance_geometry> or <instance_controller> binds to a
/// material symbol; grey when nothing is bound or the effect has no colour.
Eigen::Vector4f BoundColor(Context& ctx, const Element& instance, const std::string& symbol);

}  // namespace caliper::collada::internal
