#include "caliper/collada/exporter.h"

#include <cctype>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <set>

#include "caliper_extra.h"
#include "document.h"
#include "dom_paths.h"
#include "extension.h"
#include "math3d.h"
#include "mesh_util.h"

namespace caliper::collada {

namespace {

using internal::AddCaliperTechnique;
using internal::Element;
using internal::FormatNumber;
using internal::FormatNumbers;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

// sgal's cylinders and capsules run along z, COLLADA's along y
const Eigen::Quaterniond kYFromZ(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()));

const char* const kDofNames[6] = {"x", "y", "z", "rx", "ry", "rz"};

std::string Vector(const Eigen::Vector3d& v) { return FormatNumbers(v.data(), 3); }

// Unique XML ids (xs:ID, an NCName) made from scene names.
class Ids {
 public:
  std::string Make(const std::string& name) {
    std::string id;
    for (char c : name) {
      const bool ok =
          std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
      id += ok ? c : '_';
    }
    if (id.empty() || !(std::isalpha(static_cast<unsigned char>(id[0])) || id[0] == '_'))
      id = "_" + id;
    std::string unique = id;
    for (int i = 2; !used_.insert(unique).second; ++i) unique = id + "_" + std::to_string(i);
    return unique;
  }

 private:
  std::set<std::string> used_;
};

// An xs:token: no line breaks or tabs, no leading, trailing or repeated blanks.
std::string Token(const std::string& s) {
  std::string out;
  for (char c : s) {
    const char d = (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
    if (d == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += d;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// Keeps a name that Collada-DOM would cut in a Caliper technique of `owner`.
void NoteName(Element* owner, const std::string& name) {
  if (!internal::DomKeepsName(name)) AddCaliperTechnique(owner)->Add("name", name);
}

void AddPose(Element* e, const sgal::Pose& pose) {
  e->Add("translate", Vector(pose.position));
  const auto [axis, degrees] = internal::ToAxisAngleDegrees(pose.orientation);
  const double r[4] = {axis.x(), axis.y(), axis.z(), degrees};
  e->Add("rotate", FormatNumbers(r, 4));
}

std::string Now() {
  const std::time_t t = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buffer;
}

class Writer {
 public:
  explicit Writer(const sgal::Scene& scene)
      : scene_(scene), root_(std::make_unique<Element>("COLLADA")) {}

  std::unique_ptr<Element> Write() {
    WriteAsset();
    effects_ = root_->Add("library_effects");
    materials_ = root_->Add("library_materials");
    geometries_ = root_->Add("library_geometries");
    Element* visual_scenes = root_->Add("library_visual_scenes");
    Element* physics_materials = root_->Add("library_physics_materials");
    Element* physics_models = root_->Add("library_physics_models");
    Element* physics_scenes = root_->Add("library_physics_scenes");

    for (const auto& m : scene_.materials) {
      Element* pm = physics_materials->Add("physics_material");
      const std::string id = ids_.Make(m.name);
      material_ids_[m.name] = id;
      pm->Set("id", id)->Set("name", Token(m.name));
      Element* tc = pm->Add("technique_common");
      tc->Add("dynamic_friction", FormatNumber(m.friction));
      tc->Add("restitution", FormatNumber(m.restitution));
      tc->Add("static_friction", FormatNumber(m.friction));
      NoteName(pm, m.name);
    }
    // ids of bodies first: constraints and the physics scene refer to them
    for (const auto& b : scene_.bodies) body_ids_[b.name] = ids_.Make(b.name);

    Element* vs = visual_scenes->Add("visual_scene");
    vs->Set("id", ids_.Make("visual_scene"))
        ->Set("name", Token(scene_.name.empty() ? "scene" : scene_.name));
    Element* model = physics_models->Add("physics_model");
    const std::string model_id = ids_.Make("physics_model");
    model->Set("id", model_id);
    Element* ps = physics_scenes->Add("physics_scene");
    ps->Set("id", ids_.Make("physics_scene"));
    Element* ipm = ps->Add("instance_physics_model");
    ipm->Set("url", "#" + model_id);

    for (const auto& b : scene_.bodies) {
      WriteNode(b, vs);
      WriteRigidBody(b, model);
      Element* irb = ipm->Add("instance_rigid_body");
      irb->Set("body", body_ids_[b.name])->Set("target", "#" + body_ids_[b.name]);
      Element* tc = irb->Add("technique_common");
      if (b.angular_velocity != Eigen::Vector3d::Zero())
        tc->Add("angular_velocity", Vector(b.angular_velocity / kDegree));
      if (b.linear_velocity != Eigen::Vector3d::Zero())
        tc->Add("velocity", Vector(b.linear_velocity));
      if (b.type == sgal::BodyType::kKinematic) AddCaliperTechnique(irb)->Add("kinematic", "true");
    }
    std::set<std::string> constraint_sids;
    for (const auto& c : scene_.constraints) {
      const std::string sid = ids_.Make(c.name);
      WriteConstraint(c, sid, model);
      ipm->Add("instance_rigid_constraint")->Set("constraint", sid);
    }
    Element* tc = ps->Add("technique_common");
    tc->Add("gravity", Vector(scene_.gravity));
    tc->Add("time_step", FormatNumber(scene_.settings.time_step));

    Element* s = root_->Add("scene");
    s->Add("instance_physics_scene")->Set("url", "#" + ps->Attribute("id"));
    s->Add("instance_visual_scene")->Set("url", "#" + vs->Attribute("id"));
    internal::ExportExtension(scene_, AddCaliperTechnique(root_.get()));
    // the schema wants no empty libraries
    auto& children = root_->children;
    for (auto it = children.begin(); it != children.end();)
      it = (*it)->local_name().rfind("library_", 0) == 0 && (*it)->children.empty()
               ? children.erase(it)
               : it + 1;
    return std::move(root_);
  }

 private:
  void WriteAsset() {
    Element* asset = root_->Add("asset");
    Element* contributor = asset->Add("contributor");
    contributor->Add("authoring_tool", "Caliper COLLADA exporter");
    const std::string now = Now();
    asset->Add("created", now);
    asset->Add("modified", now);
    asset->Add("unit")->Set("meter", "1")->Set("name", "meter");
    asset->Add("up_axis", "Z_UP");
  }

  // The id of a material (and effect) of this colour.
  std::string ColorMaterial(const Eigen::Vector4f& rgba) {
    const std::array<float, 4> key{rgba[0], rgba[1], rgba[2], rgba[3]};
    const auto it = color_ids_.find(key);
    if (it != color_ids_.end()) return it->second;
    const std::string effect_id = ids_.Make("effect");
    Element* effect = effects_->Add("effect");
    effect->Set("id", effect_id);
    Element* technique = effect->Add("profile_COMMON")->Add("technique");
    technique->Set("sid", "common");
    const double c[4] = {rgba[0], rgba[1], rgba[2], rgba[3]};
    technique->Add("phong")->Add("diffuse")->Add("color", FormatNumbers(c, 4));
    const std::string id = ids_.Make("material");
    Element* material = materials_->Add("material");
    material->Set("id", id);
    material->Add("instance_effect")->Set("url", "#" + effect_id);
    return color_ids_[key] = id;
  }

  // <source>, <vertices> and <triangles> of a mesh under `mesh`.
  void WriteMeshData(const std::string& id, const sgal::Mesh& m, Element* mesh) {
    auto source = [&](const std::string& sid, const std::vector<Eigen::Vector3f>& v) {
      Element* s = mesh->Add("source");
      s->Set("id", sid);
      Element* array = s->Add("float_array");
      array->Set("id", sid + "-array")->Set("count", std::to_string(3 * v.size()));
      array->numbers.reserve(3 * v.size());
      for (const auto& p : v)
        for (int k = 0; k < 3; ++k) array->numbers.push_back(p[k]);
      array->numeric = true;
      Element* accessor = s->Add("technique_common")->Add("accessor");
      accessor->Set("source", "#" + sid + "-array")
          ->Set("count", std::to_string(v.size()))
          ->Set("stride", "3");
      for (const char* axis : {"X", "Y", "Z"})
        accessor->Add("param")->Set("name", axis)->Set("type", "float");
    };
    source(id + "-positions", m.vertices);
    const bool normals = !m.normals.empty() && m.normals.size() == m.vertices.size();
    if (normals) source(id + "-normals", m.normals);
    Element* vertices = mesh->Add("vertices");
    vertices->Set("id", id + "-vertices");
    vertices->Add("input")->Set("semantic", "POSITION")->Set("source", "#" + id + "-positions");
    if (normals)
      vertices->Add("input")->Set("semantic", "NORMAL")->Set("source", "#" + id + "-normals");
    if (m.triangles.empty()) return;
    Element* triangles = mesh->Add("triangles");
    triangles->Set("count", std::to_string(m.triangles.size()))->Set("material", "material");
    triangles->Add("input")
        ->Set("semantic", "VERTEX")
        ->Set("source", "#" + id + "-vertices")
        ->Set("offset", "0");
    Element* p = triangles->Add("p");
    p->numbers.reserve(3 * m.triangles.size());
    for (const auto& t : m.triangles)
      for (uint32_t i : t) p->numbers.push_back(i);
    p->numeric = true;
  }

  // A <geometry> holding a mesh (or a convex mesh) of `m`; one per mesh and kind.
  std::string MeshGeometry(const std::shared_ptr<const sgal::Mesh>& m, bool convex,
                           const std::string& name) {
    const auto key = std::make_pair(m.get(), convex);
    if (const auto it = mesh_ids_.find(key); it != mesh_ids_.end()) return it->second;
    const std::string id = ids_.Make(name.empty() ? "geometry" : name);
    Element* g = geometries_->Add("geometry");
    g->Set("id", id);
    if (!name.empty()) g->Set("name", Token(name));
    const auto plain = mesh_ids_.find(std::make_pair(m.get(), false));
    if (convex && plain != mesh_ids_.end()) {
      g->Add("convex_mesh")->Set("convex_hull_of", "#" + plain->second);
    } else {
      WriteMeshData(id, *m, g->Add(convex ? "convex_mesh" : "mesh"));
    }
    return mesh_ids_[key] = id;
  }

  // A tessellated primitive, with the exact one in a Caliper technique.
  std::string PrimitiveGeometry(const sgal::Geometry& geometry, bool convex,
                                const std::string& name) {
    const std::string id = ids_.Make(name.empty() ? sgal::GeometryName(geometry) : name);
    Element* g = geometries_->Add("geometry");
    g->Set("id", id);
    WriteMeshData(id, *internal::Tessellate(geometry), g->Add(convex ? "convex_mesh" : "mesh"));
    std::string numbers;
    if (const auto* b = std::get_if<sgal::Box>(&geometry)) numbers = Vector(b->size);
    if (const auto* s = std::get_if<sgal::Sphere>(&geometry)) numbers = FormatNumber(s->radius);
    if (const auto* c = std::get_if<sgal::Capsule>(&geometry))
      numbers = FormatNumber(c->radius) + " " + FormatNumber(c->length);
    if (const auto* c = std::get_if<sgal::Cylinder>(&geometry))
      numbers = FormatNumber(c->radius) + " " + FormatNumber(c->length);
    if (const auto* c = std::get_if<sgal::Cone>(&geometry))
      numbers = FormatNumber(c->radius) + " " + FormatNumber(c->length);
    if (const auto* p = std::get_if<sgal::Plane>(&geometry))
      numbers = Vector(p->normal) + " " + FormatNumber(p->offset);
    AddCaliperTechnique(g)->Add("primitive", numbers)->Set("kind", sgal::GeometryName(geometry));
    return id;
  }

  std::string VisualGeometry(const sgal::Visual& v) {
    if (const auto* t = std::get_if<sgal::TriangleMesh>(&v.geometry); t != nullptr && t->mesh)
      return MeshGeometry(t->mesh, false, v.name);
    if (const auto* h = std::get_if<sgal::ConvexHull>(&v.geometry); h != nullptr && h->mesh)
      return MeshGeometry(h->mesh, false, v.name);
    return PrimitiveGeometry(v.geometry, false, v.name);
  }

  void WriteNode(const sgal::Body& b, Element* parent) {
    const std::string& id = body_ids_[b.name];
    Element* node = parent->Add("node");
    node->Set("id", id)->Set("name", Token(b.name))->Set("sid", id);
    AddPose(node, b.pose);
    for (size_t i = 0; i < b.visuals.size(); ++i) {
      const sgal::Visual& v = b.visuals[i];
      const std::string geometry = VisualGeometry(v);
      Element* child = node->Add("node");
      child->Set("id", ids_.Make(id + "-visual" + std::to_string(i)));
      AddPose(child, v.pose);
      Element* ig = child->Add("instance_geometry");
      ig->Set("url", "#" + geometry);
      ig->Add("bind_material")
          ->Add("technique_common")
          ->Add("instance_material")
          ->Set("symbol", "material")
          ->Set("target", "#" + ColorMaterial(v.color));
    }
    NoteName(node, b.name);
  }

  void WriteShape(const sgal::Shape& s, Element* tc) {
    Element* shape = tc->Add("shape");
    if (!s.material.empty() && material_ids_.count(s.material) > 0)
      shape->Add("instance_physics_material")->Set("url", "#" + material_ids_[s.material]);
    sgal::Pose pose = s.pose;
    std::visit(
        [&](const auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, sgal::Box>) {
            shape->Add("box")->Add("half_extents", Vector(g.size / 2));
          } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
            shape->Add("sphere")->Add("radius", FormatNumber(g.radius));
          } else if constexpr (std::is_same_v<T, sgal::Cylinder> ||
                               std::is_same_v<T, sgal::Capsule>) {
            Element* e = shape->Add(std::is_same_v<T, sgal::Cylinder> ? "cylinder" : "capsule");
            e->Add("height", FormatNumber(g.length));
            e->Add("radius", FormatNumber(g.radius) + " " + FormatNumber(g.radius));
            pose.orientation = (pose.orientation * kYFromZ).normalized();
          } else if constexpr (std::is_same_v<T, sgal::Plane>) {
            const double eq[4] = {g.normal.x(), g.normal.y(), g.normal.z(), -g.offset};
            shape->Add("plane")->Add("equation", FormatNumbers(eq, 4));
          } else if constexpr (std::is_same_v<T, sgal::Cone>) {
            // COLLADA 1.5 has no cone (1.4's tapered_cylinder is gone)
            shape->Add("instance_geometry")->Set("url", "#" + PrimitiveGeometry(g, true, s.name));
          } else if constexpr (std::is_same_v<T, sgal::ConvexHull>) {
            shape->Add("instance_geometry")
                ->Set("url", "#" + MeshGeometry(g.mesh ? g.mesh : std::make_shared<sgal::Mesh>(),
                                                true, s.name));
          } else {
            shape->Add("instance_geometry")
                ->Set("url", "#" + MeshGeometry(g.mesh ? g.mesh : std::make_shared<sgal::Mesh>(),
                                                false, s.name));
          }
        },
        s.geometry);
    AddPose(shape, pose);
    const sgal::Shape defaults;
    if (!s.name.empty() || s.group != defaults.group || s.mask != defaults.mask) {
      Element* t = AddCaliperTechnique(shape);
      if (!s.name.empty()) t->Add("name", s.name);
      if (s.group != defaults.group) t->Add("group", std::to_string(s.group));
      if (s.mask != defaults.mask) t->Add("mask", std::to_string(s.mask));
    }
  }

  void WriteRigidBody(const sgal::Body& b, Element* model) {
    Element* rb = model->Add("rigid_body");
    rb->Set("sid", body_ids_[b.name])->Set("name", Token(b.name));
    Element* tc = rb->Add("technique_common");
    tc->Add("dynamic", b.type == sgal::BodyType::kDynamic ? "true" : "false");
    tc->Add("mass", FormatNumber(b.inertia.mass));
    Eigen::Vector3d moments;
    Eigen::Matrix3d axes;
    internal::PrincipalAxes(b.inertia.tensor, &moments, &axes);
    Element* frame = tc->Add("mass_frame");
    sgal::Pose mass_frame;
    mass_frame.position = b.inertia.com;
    mass_frame.orientation = Eigen::Quaterniond(axes).normalized();
    AddPose(frame, mass_frame);
    tc->Add("inertia", Vector(moments));
    for (const auto& s : b.shapes) WriteShape(s, tc);
    if (b.shapes.empty()) {
      // the schema wants a shape: a tiny sphere that the importer drops again
      Element* shape = tc->Add("shape");
      shape->Add("sphere")->Add("radius", "0.001");
      AddCaliperTechnique(shape)->Add("placeholder", "true");
    }
  }

  void WriteConstraint(const sgal::Constraint& c, const std::string& sid, Element* model) {
    Element* rc = model->Add("rigid_constraint");
    rc->Set("sid", sid)->Set("name", Token(c.name));
    Element* ref = rc->Add("ref_attachment");
    ref->Set("rigid_body", body_ids_[c.body_a]);
    AddPose(ref, c.frame_a);
    Element* att = rc->Add("attachment");
    if (!c.body_b.empty()) att->Set("rigid_body", body_ids_[c.body_b]);
    AddPose(att, c.frame_b);
    Element* tc = rc->Add("technique_common");
    tc->Add("enabled", "true");
    tc->Add("interpenetrate", c.collide_connected ? "true" : "false");
    // [min, max] per degree of freedom: locked (0, 0) unless the kind opens it; free is min > max
    double lower[6] = {0, 0, 0, 0, 0, 0}, upper[6] = {0, 0, 0, 0, 0, 0};
    auto open = [&](int dof, const sgal::Limit& l) {
      if (l.enabled()) {
        lower[dof] = l.lower;
        upper[dof] = l.upper;
      } else {
        lower[dof] = dof < 3 ? 1 : kDegree;
        upper[dof] = -lower[dof];
      }
    };
    const sgal::Limit free_limit;
    switch (c.kind) {
      case sgal::ConstraintKind::kHinge:
        open(5, c.limits[0]);
        break;
      case sgal::ConstraintKind::kSlider:
        open(2, c.limits[0]);
        break;
      case sgal::ConstraintKind::kBall:
        for (int i = 3; i < 6; ++i) open(i, free_limit);
        break;
      case sgal::ConstraintKind::kFixed:
        break;
      case sgal::ConstraintKind::kGeneric6Dof:
        for (int i = 0; i < 6; ++i) open(i, c.limits[i]);
        break;
    }
    Element* limits = tc->Add("limits");
    Element* swing = limits->Add("swing_cone_and_twist");
    const double amin[3] = {lower[3] / kDegree, lower[4] / kDegree, lower[5] / kDegree};
    const double amax[3] = {upper[3] / kDegree, upper[4] / kDegree, upper[5] / kDegree};
    swing->Add("min", FormatNumbers(amin, 3));
    swing->Add("max", FormatNumbers(amax, 3));
    Element* linear = limits->Add("linear");
    linear->Add("min", FormatNumbers(lower, 3));
    linear->Add("max", FormatNumbers(upper, 3));
    const sgal::JointSpring& s0 = c.springs[0];
    const bool one_dof =
        c.kind == sgal::ConstraintKind::kHinge || c.kind == sgal::ConstraintKind::kSlider;
    if (one_dof && (s0.stiffness != 0 || s0.damping != 0 || s0.rest != 0)) {
      Element* spring = tc->Add("spring");
      if (c.kind == sgal::ConstraintKind::kHinge) {
        Element* a = spring->Add("angular");
        a->Add("stiffness", FormatNumber(s0.stiffness * kDegree));
        a->Add("damping", FormatNumber(s0.damping * kDegree));
        a->Add("target_value", FormatNumber(s0.rest / kDegree));
      } else {
        Element* l = spring->Add("linear");
        l->Add("stiffness", FormatNumber(s0.stiffness));
        l->Add("damping", FormatNumber(s0.damping));
        l->Add("target_value", FormatNumber(s0.rest));
      }
    }
    Element* t = AddCaliperTechnique(rc);
    static const char* const kKinds[] = {"hinge", "slider", "ball", "fixed", "generic_6dof"};
    t->Add("kind", kKinds[static_cast<int>(c.kind)]);
    if (!internal::DomKeepsName(c.name)) t->Add("name", c.name);
    if (!one_dof)
      for (int i = 0; i < 6; ++i) {
        const auto& s = c.springs[i];
        if (s.stiffness == 0 && s.damping == 0 && s.rest == 0) continue;
        const double v[3] = {s.stiffness, s.damping, s.rest};
        t->Add("spring", FormatNumbers(v, 3))->Set("dof", kDofNames[i]);
      }
    // dry friction has no COLLADA element: N or N m per degree of freedom (a hinge's or slider's
    // one without dof)
    for (int i = 0; i < (one_dof ? 1 : 6); ++i) {
      if (c.friction[i] == 0) continue;
      Element* f = t->Add("friction", FormatNumber(c.friction[i]));
      if (!one_dof) f->Set("dof", kDofNames[i]);
    }
  }

  const sgal::Scene& scene_;
  std::unique_ptr<Element> root_;
  Element* effects_ = nullptr;
  Element* materials_ = nullptr;
  Element* geometries_ = nullptr;
  Ids ids_;
  std::map<std::string, std::string> body_ids_;
  std::map<std::string, std::string> material_ids_;
  std::map<std::array<float, 4>, std::string> color_ids_;
  std::map<std::pair<const sgal::Mesh*, bool>, std::string> mesh_ids_;
};

}  // namespace

void Export(const sgal::Scene& scene, const std::string& path) {
  // a file Import would reject is not written
  const auto problems = sgal::Validate(scene);
  if (!problems.empty()) {
    std::string message = path + ": the scene is not sound:";
    for (const auto& p : problems) message += "\n  " + p;
    throw ExportError(message);
  }
  try {
    internal::CheckDomPath(path);
  } catch (const std::exception& e) {
    throw ExportError(path + ": " + e.what());
  }
  {
    std::ofstream probe(path, std::ios::app);
    if (!probe) throw ExportError(path + ": cannot create the file");
  }
  std::unique_ptr<Element> root;
  try {
    root = Writer(scene).Write();
  } catch (const std::exception& e) {
    throw ExportError(path + ": " + e.what());
  }
  try {
    internal::WriteDocument150(*root, path);
  } catch (const std::exception& e) {
    throw ExportError(e.what());
  }
}

}  // namespace caliper::collada
