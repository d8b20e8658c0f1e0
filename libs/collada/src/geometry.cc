#include "geometry.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "caliper_extra.h"

namespace caliper::collada::internal {

namespace {

// One corner of a polygon: indices into the positions and the normals (-1 when none).
struct Corner {
  int64_t position = 0;
  int64_t normal = -1;
};

// Triangles of one material, as corners.
struct Group {
  std::string material;
  std::vector<std::array<Corner, 3>> triangles;
};

// A <source> read through its accessor.
struct SourceData {
  const std::vector<double>* values = nullptr;
  size_t stride = 1;
  size_t offset = 0;
  size_t count = 0;
};

struct Input {
  std::string semantic;
  size_t offset = 0;
  const Element* source = nullptr;
};

double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

bool InTriangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const Eigen::Vector2d& c) {
  const double d1 = Cross2(b - a, p - a), d2 = Cross2(c - b, p - b), d3 = Cross2(a - c, p - c);
  return d1 >= 0 && d2 >= 0 && d3 >= 0;
}

// Triangulates a polygon: a fan when it is convex, ear clipping otherwise. Returns false when
// ear clipping found no ear (a self-intersecting or degenerate polygon): the rest is fanned.
bool Triangulate(const std::vector<Corner>& poly, const std::vector<Eigen::Vector3d>& positions,
                 std::vector<std::array<Corner, 3>>* out) {
  const size_t n = poly.size();
  if (n < 3) return true;
  if (n == 3) {
    out->push_back({poly[0], poly[1], poly[2]});
    return true;
  }
  auto fan = [&](const std::vector<size_t>& idx) {
    for (size_t i = 1; i + 1 < idx.size(); ++i)
      out->push_back({poly[idx[0]], poly[idx[i]], poly[idx[i + 1]]});
  };
  std::vector<size_t> idx(n);
  for (size_t i = 0; i < n; ++i) idx[i] = i;
  // Newell normal, then a projection on the plane most orthogonal to it
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = positions[poly[i].position];
    const Eigen::Vector3d& b = positions[poly[(i + 1) % n].position];
    normal += Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                              (a.x() - b.x()) * (a.y() + b.y()));
  }
  if (!(normal.norm() > 0)) {
    fan(idx);
    return true;
  }
  int drop = 0;
  normal.cwiseAbs().maxCoeff(&drop);
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  const double sign = normal[drop] > 0 ? 1.0 : -1.0;
  std::vector<Eigen::Vector2d> p(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& q = positions[poly[i].position];
    p[i] = Eigen::Vector2d(q[u], sign * q[v]);  // counter-clockwise seen along the normal
  }
  bool convex = true;
  for (size_t i = 0; i < n && convex; ++i)
    convex = Cross2(p[(i + 1) % n] - p[i], p[(i + 2) % n] - p[(i + 1) % n]) >= -1e-12;
  if (convex) {
    fan(idx);
    return true;
  }
  while (idx.size() > 3) {
    bool clipped = false;
    for (size_t k = 0; k < idx.size(); ++k) {
      const size_t a = idx[(k + idx.size() - 1) % idx.size()], b = idx[k],
                   c = idx[(k + 1) % idx.size()];
      if (Cross2(p[b] - p[a], p[c] - p[b]) <= 1e-15) continue;  // reflex or flat corner
      bool empty = true;
      // a polygon with a hole bridged in repeats the bridge's corners: those do not block
      auto corner = [&](size_t m) { return p[m] == p[a] || p[m] == p[b] || p[m] == p[c]; };
      for (size_t m : idx)
        if (m != a && m != b && m != c && !corner(m) && InTriangle(p[m], p[a], p[b], p[c])) {
          empty = false;
          break;
        }
      if (!empty) continue;
      out->push_back({poly[a], poly[b], poly[c]});
      idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
      break;
    }
    if (!clipped) {
      fan(idx);
      return false;
    }
  }
  out->push_back({poly[idx[0]], poly[idx[1]], poly[idx[2]]});
  return true;
}

std::string Fragment(const std::string& url) {
  return url.empty() || url[0] != '#' ? url : url.substr(1);
}

// Reads the primitive a Caliper exporter noted about a tessellated geometry into `data`.
void ReadCaliperPrimitive(Context& ctx, const Element& geometry, GeometryData* data) {
  for (const Element* technique : CaliperTechniques(geometry)) {
    for (const auto& c : technique->children) {
      if (c->local_name() != "primitive") {
        ctx.Warn(c.get(), "unknown element <" + std::string(c->local_name()) +
                              "> in a geometry's Caliper technique");
        continue;
      }
      const std::string kind = c->Attribute("kind");
      const auto v = ctx.Numbers(*c);
      auto need = [&](size_t k) {
        if (v.size() != k)
          ctx.Fail(c.get(), "a " + kind + " needs " + std::to_string(k) + " numbers");
      };
      const double s = ctx.meter;
      if (kind == "box") {
        need(3);
        data->primitive = sgal::Box{Eigen::Vector3d(v[0], v[1], v[2]) * s};
      } else if (kind == "sphere") {
        need(1);
        data->primitive = sgal::Sphere{v[0] * s};
      } else if (kind == "capsule") {
        need(2);
        data->primitive = sgal::Capsule{v[0] * s, v[1] * s};
      } else if (kind == "cylinder") {
        need(2);
        data->primitive = sgal::Cylinder{v[0] * s, v[1] * s};
      } else if (kind == "cone") {
        need(2);
        data->primitive = sgal::Cone{v[0] * s, v[1] * s};
      } else if (kind == "plane") {
        need(4);
        data->primitive = sgal::Plane{Eigen::Vector3d(v[0], v[1], v[2]).normalized(), v[3] * s};
      } else {
        ctx.Fail(c.get(), "unknown primitive kind '" + kind +
                              "' (box, sphere, capsule, cylinder, cone, plane)");
      }
    }
  }
}

// The 3D vectors a <source> holds, times `scale`.
std::vector<Eigen::Vector3d> Vectors(const SourceData& d, double scale) {
  std::vector<Eigen::Vector3d> out(d.count);
  for (size_t i = 0; i < d.count; ++i) {
    const double* v = d.values->data() + d.offset + i * d.stride;
    out[i] = Eigen::Vector3d(v[0], v[1], v[2]) * scale;
  }
  return out;
}

// The triangles of a mesh, one group per primitive element, over its positions.
struct MeshTriangles {
  std::vector<Eigen::Vector3d> positions;       // [m]
  std::vector<Eigen::Vector3d> vertex_normals;  // one per position, or none
  std::vector<Group> groups;                    // one per primitive element
  // the normals each group's corners index (nullptr: none of its own)
  std::vector<const std::vector<Eigen::Vector3d>*> group_normals;
  std::map<const Element*, std::vector<Eigen::Vector3d>> normal_sources;  // by <source>
};

// Reads the triangles of a <mesh> or <convex_mesh>: its <vertices>, then each primitive element
// (<triangles>, <polylist>, <polygons>, <tristrips>, <trifans>).
class MeshReader {
 public:
  MeshReader(Context& ctx, const Element& mesh, const Element& vertices, MeshTriangles* out)
      : ctx_(ctx), mesh_(mesh), vertices_(vertices), out_(*out) {}

  void Read() {
    ReadVertices();
    for (const auto& prim : mesh_.children) {
      const std::string_view kind = prim->local_name();
      if (kind != "triangles" && kind != "polylist" && kind != "polygons" && kind != "tristrips" &&
          kind != "trifans")
        continue;
      ReadPrimitive(*prim);
    }
    if (failed_polygons_ > 0)
      ctx_.Warn(&mesh_,
                std::to_string(failed_polygons_) +
                    " polygon(s) could not be ear-clipped (self-intersecting?) and were fanned");
    if (holes_ > 0)
      ctx_.Warn(&mesh_,
                std::to_string(holes_) + " polygon hole(s) ignored: the outer outlines are filled");
  }

 private:
  // where a primitive element's index tuples hold what
  struct Layout {
    size_t stride = 0;                                      // indices per corner
    size_t vertex_offset = 0;                               // of the VERTEX input
    size_t normal_offset = 0;                               // of the NORMAL input
    const std::vector<Eigen::Vector3d>* normals = nullptr;  // of the NORMAL input, if any
  };

  // a <source> read through its accessor (each read once)
  const SourceData& Source(const Element& from, const std::string& url) {
    const Element& s = ctx_.Resolve(from, url);
    const auto found = sources_.find(&s);
    if (found != sources_.end()) return found->second;
    SourceData d;
    const Element* array = s.Child("float_array");
    if (s.local_name() != "source" || array == nullptr)
      ctx_.Fail(&from, "'" + url + "' is not a <source> with a <float_array>");
    if (!array->numeric) {
      auto& a = const_cast<Element&>(*array);
      a.numbers = ctx_.Numbers(*array);
      a.numeric = true;
    }
    d.values = &array->numbers;
    d.count = array->numbers.size();
    if (const Element* tc = s.Child("technique_common"); tc != nullptr) {
      if (const Element* acc = tc->Child("accessor"); acc != nullptr) {
        d.stride = ctx_.Count(*acc, "stride", 1);
        d.offset = ctx_.Count(*acc, "offset", 0);
        d.count = ctx_.Count(*acc, "count", 0);
        if (d.stride == 0) d.stride = 1;
      }
    }
    if (d.stride < 3 && d.count > 0)
      ctx_.Fail(&s,
                "an accessor of stride " + std::to_string(d.stride) + " cannot hold 3D vectors");
    if (d.count > d.values->size() || d.offset > d.values->size() ||
        (d.count > 0 && d.offset + (d.count - 1) * d.stride + 3 > d.values->size()))
      ctx_.Fail(&s, "its accessor reads " + std::to_string(d.count) + " vectors past the end of " +
                        std::to_string(d.values->size()) + " values");
    return sources_[&s] = d;
  }

  // positions and per-vertex normals from <vertices>
  void ReadVertices() {
    for (const Element* in : vertices_.Children("input")) {
      const std::string semantic = in->Attribute("semantic");
      if (semantic == "POSITION")
        out_.positions = Vectors(Source(*in, in->Attribute("source")), ctx_.meter);
      else if (semantic == "NORMAL")
        out_.vertex_normals = Vectors(Source(*in, in->Attribute("source")), 1.0);
    }
    if (!out_.vertex_normals.empty() && out_.vertex_normals.size() != out_.positions.size())
      out_.vertex_normals.clear();
  }

  // the inputs of a primitive element; its normals read on first use
  Layout ReadLayout(const Element& prim) {
    std::vector<Input> inputs;
    Layout layout;
    const Input* vertex_input = nullptr;
    const Input* normal_input = nullptr;
    for (const Element* in : prim.Children("input")) {
      Input input;
      input.semantic = in->Attribute("semantic");
      input.offset = ctx_.Count(*in, "offset", 0);
      input.source = in;
      layout.stride = std::max(layout.stride, input.offset + 1);
      inputs.push_back(input);
    }
    for (const auto& in : inputs) {
      if (in.semantic == "VERTEX") vertex_input = &in;
      if (in.semantic == "NORMAL" && normal_input == nullptr) normal_input = &in;
    }
    if (vertex_input == nullptr) ctx_.Fail(&prim, "has no VERTEX input");
    layout.vertex_offset = vertex_input->offset;
    if (Fragment(vertex_input->source->Attribute("source")) != vertices_.Attribute("id"))
      ctx_.Resolve(*vertex_input->source, vertex_input->source->Attribute("source"));
    if (normal_input != nullptr) {
      layout.normal_offset = normal_input->offset;
      const Element& s =
          ctx_.Resolve(*normal_input->source, normal_input->source->Attribute("source"));
      auto found = out_.normal_sources.find(&s);
      if (found == out_.normal_sources.end())
        found = out_.normal_sources
                    .emplace(&s, Vectors(Source(*normal_input->source,
                                                normal_input->source->Attribute("source")),
                                         1.0))
                    .first;
      layout.normals = &found->second;
    }
    return layout;
  }

  // corner `k` of the index tuples `p`
  Corner CornerAt(const Element& prim, const Layout& layout, const std::vector<double>& p,
                  size_t k) const {
    Corner c;
    const size_t base = k * layout.stride;
    const double vi = p[base + layout.vertex_offset];
    if (!(vi >= 0) || vi >= static_cast<double>(out_.positions.size()))
      ctx_.Fail(&prim, "vertex index " + FormatNumber(vi) + " out of range (" +
                           std::to_string(out_.positions.size()) + " positions)");
    c.position = static_cast<int64_t>(vi);
    if (layout.normals != nullptr) {
      const double ni = p[base + layout.normal_offset];
      c.normal = ni >= 0 && ni < static_cast<double>(layout.normals->size())
                     ? static_cast<int64_t>(ni)
                     : -1;
    } else if (!out_.vertex_normals.empty()) {
      c.normal = c.position;
    }
    return c;
  }

  // the corners of a <p>
  std::vector<Corner> CornersOf(const Element& prim, const Layout& layout, const Element& p) const {
    std::vector<double> values = p.numeric ? p.numbers : ctx_.Numbers(p);
    if (values.size() % layout.stride != 0)
      ctx_.Fail(&p, std::to_string(values.size()) + " indices is not a multiple of the " +
                        std::to_string(layout.stride) + " inputs");
    std::vector<Corner> corners;
    corners.reserve(values.size() / layout.stride);
    for (size_t k = 0; k < values.size() / layout.stride; ++k)
      corners.push_back(CornerAt(prim, layout, values, k));
    return corners;
  }

  void AddPolygon(const std::vector<Corner>& poly, Group* group) {
    if (!Triangulate(poly, out_.positions, &group->triangles)) ++failed_polygons_;
  }

  // one primitive element as a group of triangles
  void ReadPrimitive(const Element& prim) {
    const std::string_view kind = prim.local_name();
    const Layout layout = ReadLayout(prim);
    Group group;
    group.material = prim.Attribute("material");
    if (kind == "triangles") {
      if (const Element* p = prim.Child("p"); p != nullptr) {
        const auto corners = CornersOf(prim, layout, *p);
        for (size_t i = 0; i + 2 < corners.size(); i += 3)
          group.triangles.push_back({corners[i], corners[i + 1], corners[i + 2]});
      }
    } else if (kind == "polylist") {
      ReadPolylist(prim, layout, &group);
    } else if (kind == "polygons") {
      for (const auto& c : prim.children) {
        if (c->local_name() == "p") {
          AddPolygon(CornersOf(prim, layout, *c), &group);
        } else if (c->local_name() == "ph") {
          if (const Element* p = c->Child("p"); p != nullptr)
            AddPolygon(CornersOf(prim, layout, *p), &group);
          holes_ += c->Children("h").size();
        }
      }
    } else {
      const bool strip = kind == "tristrips";
      for (const Element* p : prim.Children("p")) {
        const auto corners = CornersOf(prim, layout, *p);
        for (size_t i = 2; i < corners.size(); ++i) {
          if (!strip)
            group.triangles.push_back({corners[0], corners[i - 1], corners[i]});
          else if (i % 2 == 0)
            group.triangles.push_back({corners[i - 2], corners[i - 1], corners[i]});
          else
            group.triangles.push_back({corners[i - 1], corners[i - 2], corners[i]});
        }
      }
    }
    out_.groups.push_back(std::move(group));
    out_.group_normals.push_back(layout.normals);
  }

  // a <polylist>: its <p> cut into polygons by <vcount>
  void ReadPolylist(const Element& prim, const Layout& layout, Group* group) {
    const Element* p = prim.Child("p");
    const Element* vcount = prim.Child("vcount");
    if (p == nullptr || vcount == nullptr) return;
    const auto corners = CornersOf(prim, layout, *p);
    const std::vector<double> counts = vcount->numeric ? vcount->numbers : ctx_.Numbers(*vcount);
    size_t at = 0;
    for (double c : counts) {
      if (!(c >= 0) || c > static_cast<double>(corners.size()))
        ctx_.Fail(vcount, "corner count " + FormatNumber(c) + " is out of range");
      const size_t k = static_cast<size_t>(c);
      if (at + k > corners.size())
        ctx_.Fail(vcount, "counts " + std::to_string(at + k) + " corners, <p> has " +
                              std::to_string(corners.size()));
      AddPolygon(std::vector<Corner>(corners.begin() + static_cast<std::ptrdiff_t>(at),
                                     corners.begin() + static_cast<std::ptrdiff_t>(at + k)),
                 group);
      at += k;
    }
  }

  Context& ctx_;
  const Element& mesh_;
  const Element& vertices_;
  MeshTriangles& out_;
  std::map<const Element*, SourceData> sources_;
  size_t failed_polygons_ = 0;
  size_t holes_ = 0;
};

// Drops the degenerate triangles of the groups and those at positions that are not finite (with
// a warning on `mesh`); returns every triangle left over all the positions.
std::shared_ptr<sgal::Mesh> KeepFiniteTriangles(Context& ctx, const Element& mesh,
                                                MeshTriangles* tris) {
  const std::vector<Eigen::Vector3d>& positions = tris->positions;
  size_t dropped = 0;
  auto finite = [&](const std::array<Corner, 3>& t) {
    for (const auto& c : t)
      if (!positions[c.position].allFinite()) return false;
    return true;
  };
  auto all = std::make_shared<sgal::Mesh>();
  all->vertices.reserve(positions.size());
  for (const auto& p : positions) all->vertices.push_back(p.cast<float>());
  for (auto& g : tris->groups) {
    std::vector<std::array<Corner, 3>> kept;
    kept.reserve(g.triangles.size());
    for (const auto& t : g.triangles) {
      if (!finite(t)) {
        ++dropped;
        continue;
      }
      if (t[0].position == t[1].position || t[1].position == t[2].position ||
          t[0].position == t[2].position)
        continue;  // degenerate
      kept.push_back(t);
      all->triangles.push_back({static_cast<uint32_t>(t[0].position),
                                static_cast<uint32_t>(t[1].position),
                                static_cast<uint32_t>(t[2].position)});
    }
    g.triangles = std::move(kept);
  }
  if (dropped > 0)
    ctx.Warn(&mesh, std::to_string(dropped) + " triangle(s) with non-finite positions dropped");
  return all;
}

// A group's own mesh: one vertex per (position, normal) pair it uses.
std::shared_ptr<sgal::Mesh> PartMesh(const Group& g, const std::vector<Eigen::Vector3d>& positions,
                                     const std::vector<Eigen::Vector3d>* normals) {
  auto part = std::make_shared<sgal::Mesh>();
  std::unordered_map<uint64_t, uint32_t> index;
  const uint64_t nn = normals == nullptr ? 1 : normals->size() + 1;
  for (const auto& t : g.triangles) {
    std::array<uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const Corner& c = t[k];
      const int64_t ni = normals == nullptr ? -1 : c.normal;
      const uint64_t key = static_cast<uint64_t>(c.position) * nn + static_cast<uint64_t>(ni + 1);
      auto [it, inserted] = index.emplace(key, static_cast<uint32_t>(part->vertices.size()));
      if (inserted) {
        part->vertices.push_back(positions[c.position].cast<float>());
        if (normals != nullptr) {
          Eigen::Vector3d n = ni >= 0 ? (*normals)[ni] : Eigen::Vector3d::Zero();
          if (n.norm() > 0) n.normalize();
          part->normals.push_back(n.cast<float>());
        }
      }
      tri[k] = it->second;
    }
    part->triangles.push_back(tri);
  }
  return part;
}

// The parts to draw, by material: the whole mesh `all` for a single group without normals.
std::vector<MeshPart> PartsByMaterial(const MeshTriangles& tris,
                                      const std::shared_ptr<const sgal::Mesh>& all) {
  std::vector<MeshPart> parts;
  for (size_t gi = 0; gi < tris.groups.size(); ++gi) {
    const Group& g = tris.groups[gi];
    if (g.triangles.empty()) continue;
    const std::vector<Eigen::Vector3d>* normals =
        tris.group_normals[gi] != nullptr ? tris.group_normals[gi]
        : tris.vertex_normals.empty()     ? nullptr
                                          : &tris.vertex_normals;
    if (normals == nullptr && tris.groups.size() == 1) {
      parts.push_back({g.material, all});
      continue;
    }
    parts.push_back({g.material, PartMesh(g, tris.positions, normals)});
  }
  return parts;
}

}  // namespace

const GeometryData& GeometryLibrary::Get(const Element& geometry) {
  const auto it = cache_.find(&geometry);
  if (it != cache_.end()) return it->second;
  // a placeholder first: convex_hull_of cycles end here
  cache_[&geometry] = GeometryData{};
  GeometryData data = Read(geometry);
  return cache_[&geometry] = std::move(data);
}

GeometryData GeometryLibrary::Read(const Element& geometry) {
  GeometryData data;
  // what a Caliper exporter noted about a tessellated primitive
  ReadCaliperPrimitive(ctx_, geometry, &data);
  const Element* mesh = geometry.Child("mesh");
  const Element* convex = geometry.Child("convex_mesh");
  if (convex != nullptr && convex->HasAttribute("convex_hull_of")) {
    const Element& of = ctx_.Resolve(*convex, convex->Attribute("convex_hull_of"));
    if (of.local_name() != "geometry")
      ctx_.Fail(convex, "convex_hull_of '" + convex->Attribute("convex_hull_of") + "' is a <" +
                            std::string(of.local_name()) + ">, not a <geometry>");
    data = Get(of);
    data.convex = true;
    return data;
  }
  if (mesh == nullptr) mesh = convex;
  if (mesh == nullptr) {
    std::string kind = geometry.children.empty()
                           ? "nothing"
                           : "<" + std::string(geometry.children[0]->local_name()) + ">";
    ctx_.Warn(&geometry,
              "holds " + kind + "; only <mesh> and <convex_mesh> are read, so it is not shown");
    return data;
  }
  data.convex = mesh == convex;

  const Element* vertices = mesh->Child("vertices");
  if (vertices == nullptr) {
    ctx_.Warn(mesh, "has no <vertices>; not shown");
    return data;
  }
  MeshTriangles tris;
  MeshReader(ctx_, *mesh, *vertices, &tris).Read();

  // positions that are not finite take their triangles with them
  std::shared_ptr<sgal::Mesh> all = KeepFiniteTriangles(ctx_, *mesh, &tris);
  data.all = all;
  data.usable = !all->vertices.empty() && (data.convex || !all->triangles.empty());
  data.parts = PartsByMaterial(tris, all);
  return data;
}

Eigen::Vector4f BoundColor(Context& ctx, const Element& instance, const std::string& symbol) {
  const Eigen::Vector4f grey(0.7f, 0.7f, 0.7f, 1.0f);
  const Element* bind = instance.Child("bind_material");
  const Element* tc = bind == nullptr ? nullptr : bind->Child("technique_common");
  if (tc == nullptr) return grey;
  const Element* material = nullptr;
  for (const Element* im : tc->Children("instance_material"))
    if (im->Attribute("symbol") == symbol || symbol.empty()) {
      material = ctx.TryResolve(im->Attribute("target"));
      break;
    }
  if (material == nullptr) return grey;
  const Element* ie = material->Child("instance_effect");
  const Element* effect = ie == nullptr ? nullptr : ctx.TryResolve(ie->Attribute("url"));
  const Element* profile = effect == nullptr ? nullptr : effect->Child("profile_COMMON");
  const Element* technique = profile == nullptr ? nullptr : profile->Child("technique");
  if (technique == nullptr) return grey;
  for (const auto& shading : technique->children) {
    for (const char* channel : {"diffuse", "emission"}) {
      const Element* c = shading->Child(channel);
      const Element* color = c == nullptr ? nullptr : c->Child("color");
      if (color == nullptr) continue;
      std::vector<double> v;
      std::string bad;
      if (!ParseNumbers(color->text, &v, &bad) || v.size() < 3) continue;
      Eigen::Vector4f rgba(static_cast<float>(v[0]), static_cast<float>(v[1]),
                           static_cast<float>(v[2]),
                           v.size() > 3 ? static_cast<float>(v[3]) : 1.0f);
      return rgba.cwiseMax(0.0f).cwiseMin(1.0f);
    }
  }
  return grey;
}

}  // namespace caliper::collada::internal
