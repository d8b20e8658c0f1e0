#include "physics.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <set>
#include <tuple>

#include "caliper_extra.h"
#include "math3d.h"
#include "mesh_util.h"

namespace caliper::collada::internal {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

// sgal's cylinders and capsules run along z, COLLADA's along y
const Eigen::Quaterniond kZToY(Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitX()));

// The names of the degrees of freedom of a generic constraint, in sgal's order.
const char* const kDofNames[6] = {"x", "y", "z", "rx", "ry", "rz"};

// The degree of freedom an element's dof attribute names (0-5 or x, y, z, rx, ry, rz; 0 when
// absent); fails naming the element for another.
int DofSlot(const Context& ctx, const Element& e) {
  const std::string dof = e.Attribute("dof", "0");
  for (int i = 0; i < 6; ++i)
    if (dof == kDofNames[i] || dof == std::to_string(i)) return i;
  ctx.Fail(&e, "unknown degree of freedom '" + dof + "' (0-5 or x, y, z, rx, ry, rz)");
}

std::string Strip(const std::string& url) {
  return !url.empty() && url[0] == '#' ? url.substr(1) : url;
}

// The body name a node instance suggests: the exact name Caliper noted, its name, else its id.
std::string NodeName(const Element& node) {
  std::string n = CaliperName(node);
  if (n.empty()) n = node.Attribute("name");
  if (n.empty()) n = node.Attribute("id");
  if (n.empty()) n = node.Attribute("sid");
  return n;
}

// The product of the translate and rotate children of an element [m].
Eigen::Affine3d Placement(const VisualScene& visual, const Element& e) {
  Eigen::Affine3d m = Eigen::Affine3d::Identity();
  for (const auto& c : e.children) {
    const std::string_view n = c->local_name();
    if (n == "translate" || n == "rotate" || n == "matrix") m = m * visual.TransformOf(*c);
  }
  return m;
}

// A geometry placed in a body: the pose and the scale or shear its geometry has to absorb.
struct Placed {
  sgal::Pose pose;
  Eigen::Matrix3d residual = Eigen::Matrix3d::Identity();
};

Placed Place(const Eigen::Isometry3d& body_world, const Eigen::Affine3d& frame_world,
             const Eigen::Affine3d& local) {
  const Eigen::Affine3d rel = Eigen::Affine3d(body_world.inverse()) * frame_world * local;
  Eigen::Isometry3d rigid;
  Placed p;
  SplitRigid(rel, &rigid, &p.residual);
  p.pose = sgal::Pose::FromIsometry(rigid);
  return p;
}

double Volume(const sgal::Geometry& g) {
  if (const auto* b = std::get_if<sgal::Box>(&g)) return b->size.prod();
  if (const auto* s = std::get_if<sgal::Sphere>(&g))
    return 4.0 / 3.0 * kPi * std::pow(s->radius, 3);
  if (const auto* c = std::get_if<sgal::Capsule>(&g))
    return kPi * c->radius * c->radius * c->length + 4.0 / 3.0 * kPi * std::pow(c->radius, 3);
  if (const auto* c = std::get_if<sgal::Cylinder>(&g))
    return kPi * c->radius * c->radius * c->length;
  if (const auto* c = std::get_if<sgal::Cone>(&g))
    return kPi * c->radius * c->radius * c->length / 3;
  if (std::holds_alternative<sgal::Plane>(g)) return 0;
  Eigen::AlignedBox3d box;
  ExtendBounds(g, sgal::Pose(), &box);
  return box.isEmpty() ? 0 : box.volume();
}

class PhysicsReader {
 public:
  PhysicsReader(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries)
      : ctx_(ctx), visual_(visual), geometries_(geometries) {}

  size_t Read() {
    ReadMaterials();
    const Element* scene = ctx_.doc.root->Child("scene");
    if (scene == nullptr) return 0;
    bool first = true;
    for (const Element* ips : scene->Children("instance_physics_scene")) {
      const Element& ps = ctx_.Resolve(*ips, ips->Attribute("url"));
      if (ps.local_name() != "physics_scene")
        ctx_.Fail(ips, "url '" + ips->Attribute("url") + "' is not a <physics_scene>");
      ReadSceneSettings(ps, first);
      first = false;
      for (const Element* ipm : ps.Children("instance_physics_model")) ReadModelInstance(*ipm);
      if (!ps.Children("instance_force_field").empty())
        ctx_.Warn(&ps, "force fields are not supported; ignored");
    }
    return bodies_;
  }

 private:
  void ReadMaterials() {
    for (const Element* lib : ctx_.doc.root->Children("library_physics_materials"))
      for (const Element* m : lib->Children("physics_material")) MaterialOf(*m);
  }

  // The scene's name of a <physics_material> (read once).
  std::string MaterialOf(const Element& m) {
    const auto it = materials_.find(&m);
    if (it != materials_.end()) return it->second;
    sgal::Material mat;
    std::string name = CaliperName(m);
    if (name.empty()) name = m.Attribute("name");
    if (name.empty()) name = m.Attribute("id");
    if (name.empty()) name = m.Attribute("sid");
    if (name.empty()) name = "material";
    std::set<std::string> taken;
    for (const auto& existing : ctx_.scene.materials) taken.insert(existing.name);
    mat.name = name;
    for (int i = 2; taken.count(mat.name) > 0; ++i) mat.name = name + "_" + std::to_string(i);
    if (const Element* tc = m.Child("technique_common"); tc != nullptr) {
      const Element* dynamic = tc->Child("dynamic_friction");
      const Element* fixed = tc->Child("static_friction");
      mat.friction = ctx_.Number(dynamic != nullptr ? dynamic : fixed, mat.friction);
      mat.restitution = ctx_.Number(tc->Child("restitution"), mat.restitution);
    }
    ctx_.scene.materials.push_back(mat);
    materials_[&m] = mat.name;
    return mat.name;
  }

  // The material an element sets with <instance_physics_material> or <physics_material>; "" none.
  std::string MaterialIn(const Element* owner) {
    if (owner == nullptr) return "";
    if (const Element* im = owner->Child("instance_physics_material"); im != nullptr) {
      const Element& m = ctx_.Resolve(*im, im->Attribute("url"));
      if (m.local_name() != "physics_material")
        ctx_.Fail(im, "url '" + im->Attribute("url") + "' is not a <physics_material>");
      return MaterialOf(m);
    }
    if (const Element* m = owner->Child("physics_material"); m != nullptr) return MaterialOf(*m);
    return "";
  }

  void ReadSceneSettings(const Element& ps, bool first) {
    const Element* tc = ps.Child("technique_common");
    if (tc == nullptr) return;
    if (!first) {
      ctx_.Warn(&ps, "a second physics scene: its gravity and time step are ignored");
      return;
    }
    if (const Element* g = tc->Child("gravity"); g != nullptr)
      ctx_.scene.gravity = ctx_.up * ctx_.Vector3(*g) * ctx_.meter;
    if (const Element* dt = tc->Child("time_step"); dt != nullptr) {
      const double step = ctx_.Number(dt, 0);
      if (!(step > 0)) ctx_.Fail(dt, "time step " + FormatNumber(step) + " s must be positive");
      ctx_.scene.settings.time_step = step;
    }
  }

  // The world frame of a node element (its first instance); fails when it is not in the scene.
  int InstanceOf(const Element& referrer, const Element& node, const std::string& what) {
    const auto instances = visual_.InstancesOf(&node);
    if (instances.empty())
      ctx_.Fail(&referrer,
                what + " '" + node.Attribute("id") + "' is not part of the visual scene");
    if (instances.size() > 1)
      ctx_.Warn(&referrer, what + " '" + node.Attribute("id") + "' is instanced " +
                               std::to_string(instances.size()) + " times; the first is used");
    return instances.front();
  }

  void ReadModelInstance(const Element& ipm) {
    const Element& model = ctx_.Resolve(ipm, ipm.Attribute("url"));
    if (model.local_name() != "physics_model")
      ctx_.Fail(&ipm, "url '" + ipm.Attribute("url") + "' is not a <physics_model>");
    if (!model.Children("instance_physics_model").empty())
      ctx_.Warn(&model, "nested physics models are not supported; their bodies are ignored");
    // the frame OpenRAVE gives every rigid body of the model
    std::optional<Eigen::Affine3d> model_frame;
    if (ipm.HasAttribute("parent")) {
      const Element& parent = ctx_.Resolve(ipm, ipm.Attribute("parent"));
      model_frame = visual_.nodes()[InstanceOf(ipm, parent, "parent node")].world;
    }
    std::map<std::string, const Element*> by_sid, by_name;
    std::vector<const Element*> rigid_bodies = model.Children("rigid_body");
    for (const Element* rb : rigid_bodies) {
      if (rb->HasAttribute("sid")) by_sid.emplace(rb->Attribute("sid"), rb);
      if (rb->HasAttribute("name")) by_name.emplace(rb->Attribute("name"), rb);
    }
    auto find_body = [&](const std::string& ref) -> const Element* {
      const std::string key = Strip(ref);
      if (auto it = by_sid.find(key); it != by_sid.end()) return it->second;
      if (auto it = by_name.find(key); it != by_name.end()) return it->second;
      return nullptr;
    };
    std::map<const Element*, std::string> instanced;  // rigid body -> scene body
    std::map<std::string, BodyFrame> frames;
    for (const Element* irb : ipm.Children("instance_rigid_body")) {
      const Element* rb = nullptr;
      if (!irb->HasAttribute("body")) {
        if (rigid_bodies.size() != 1)
          ctx_.Fail(irb, "has no body attribute and physics model '" + model.Attribute("id") +
                             "' has " + std::to_string(rigid_bodies.size()) + " rigid bodies");
        rb = rigid_bodies.front();
        ctx_.WarnRepeated("instance_rigid_body without a body attribute", irb,
                          "has no body attribute (required); using the model's only rigid body");
      } else {
        rb = find_body(irb->Attribute("body"));
        if (rb == nullptr)
          ctx_.Fail(irb, "dangling reference: physics model '" + model.Attribute("id") +
                             "' has no rigid body '" + irb->Attribute("body") + "'");
      }
      if (!irb->HasAttribute("target")) ctx_.Fail(irb, "has no target node");
      const Element& target = ctx_.Resolve(*irb, irb->Attribute("target"));
      if (target.local_name() != "node")
        ctx_.Fail(irb, "target '" + irb->Attribute("target") + "' is not a <node>");
      const int instance = InstanceOf(*irb, target, "target node");
      const Eigen::Affine3d node_world = visual_.nodes()[instance].world;
      BodyFrame frame;
      frame.body_world = Eigen::Isometry3d(RigidPose(node_world).ToIsometry());
      frame.frame_world = ctx_.openrave && model_frame ? *model_frame : node_world;
      const std::string name = ReadBody(*rb, *irb, target, frame);
      ctx_.instance_body[instance] = name;
      instanced[rb] = name;
      frames[name] = frame;
      ++bodies_;
    }
    // constraints: those the instance lists, or all of the model's when it lists none
    std::set<std::string> listed;
    for (const Element* irc : ipm.Children("instance_rigid_constraint"))
      listed.insert(irc->Attribute("constraint"));
    for (const Element* rc : model.Children("rigid_constraint")) {
      if (!listed.empty() && listed.count(rc->Attribute("sid")) == 0) continue;
      ReadConstraint(*rc, find_body, instanced, frames);
    }
  }

  struct BodyFrame {
    Eigen::Isometry3d body_world = Eigen::Isometry3d::Identity();  // the body's pose
    Eigen::Affine3d frame_world = Eigen::Affine3d::Identity();     // where its data is given
  };

  std::string ReadBody(const Element& rb, const Element& irb, const Element& node,
                       const BodyFrame& frame) {
    const Element* tc = rb.Child("technique_common");
    const Element* over = irb.Child("technique_common");
    auto get = [&](const char* child) -> const Element* {
      if (over != nullptr)
        if (const Element* e = over->Child(child); e != nullptr) return e;
      return tc == nullptr ? nullptr : tc->Child(child);
    };
    sgal::Body body;
    std::vector<std::string> aliases{node.Attribute("id"), node.Attribute("name"),
                                     rb.Attribute("sid"), rb.Attribute("name")};
    body.name = ctx_.UniqueBodyName(NodeName(node).empty() ? rb.Attribute("name") : NodeName(node));
    body.pose = sgal::Pose::FromIsometry(frame.body_world);
    const bool dynamic = ctx_.Bool(get("dynamic"), true);
    body.type = dynamic ? sgal::BodyType::kDynamic : sgal::BodyType::kStatic;
    for (const Element* t : CaliperTechniques(irb))
      for (const auto& c : t->children) {
        if (c->local_name() == "kinematic") {
          if (ctx_.Bool(c.get(), true)) body.type = sgal::BodyType::kKinematic;
        } else {
          ctx_.Warn(c.get(), "unknown element <" + std::string(c->local_name()) +
                                 "> in a rigid body instance's Caliper technique");
        }
      }
    if (over != nullptr) {
      if (const Element* v = over->Child("velocity"); v != nullptr)
        body.linear_velocity = ctx_.up * ctx_.Vector3(*v) * ctx_.meter;
      if (const Element* w = over->Child("angular_velocity"); w != nullptr)
        body.angular_velocity = ctx_.up * ctx_.Vector3(*w) * kDegree;
    }
    const std::string body_material =
        MaterialIn(over != nullptr && (over->Child("instance_physics_material") ||
                                       over->Child("physics_material"))
                       ? over
                       : tc);

    // shapes, and what they say about the mass
    const Element* shape_owner = over != nullptr && over->Child("shape") != nullptr ? over : tc;
    double shape_mass = 0, shape_volume_mass = 0;
    bool shape_mass_known = false;
    if (shape_owner != nullptr) {
      for (const Element* s : shape_owner->Children("shape")) {
        const size_t before = body.shapes.size();
        ReadShape(*s, frame, body_material, &body);
        double volume = 0;
        for (size_t k = before; k < body.shapes.size(); ++k)
          volume += Volume(body.shapes[k].geometry);
        if (const Element* m = s->Child("mass"); m != nullptr) {
          shape_mass += ctx_.Number(m, 0);
          shape_mass_known = true;
        } else if (const Element* d = s->Child("density"); d != nullptr) {
          shape_volume_mass += ctx_.Number(d, 0) / std::pow(ctx_.meter, 3) * volume;
          shape_mass_known = true;
        }
      }
    }

    // mass and its frame
    const Element* mass = get("mass");
    const Element* mass_frame = get("mass_frame");
    const Element* inertia = get("inertia");
    if (mass != nullptr) {
      body.inertia.mass = ctx_.Number(mass, 1);
    } else if (shape_mass_known) {
      body.inertia.mass = shape_mass + shape_volume_mass;
    } else if (dynamic) {
      body.inertia.mass = 1;
      ctx_.WarnRepeated("rigid bodies without mass", &rb,
                        "no mass, neither on the body nor on its shapes; 1 kg assumed");
    }
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    if (mass_frame != nullptr) {
      const Placed p = Place(frame.body_world, frame.frame_world, Placement(visual_, *mass_frame));
      body.inertia.com = p.pose.position;
      axes = p.pose.orientation.toRotationMatrix();
    } else if (ctx_.openrave) {
      body.inertia.com =
          Place(frame.body_world, frame.frame_world, Eigen::Affine3d::Identity()).pose.position;
    }
    if (inertia != nullptr) {
      Eigen::Vector3d d = ctx_.Vector3(*inertia) * ctx_.meter * ctx_.meter;
      if (dynamic) d = Physical(d, *inertia);
      body.inertia.tensor = axes * d.asDiagonal() * axes.transpose();
    } else if (dynamic) {
      body.inertia.tensor = InertiaFromShapes(body, rb);
    }
    std::string name = body.name;
    ctx_.AddBody(std::move(body), &rb, aliases);
    return name;
  }

  // Principal moments that no rigid body has (the largest above the sum of the other two, as
  // in some vendor files: the PUMA's, the PR2's) come back with the two smaller ones raised
  // in proportion until the sum reaches the largest, and a warning. Non-positive moments stay:
  // validation rejects them.
  Eigen::Vector3d Physical(const Eigen::Vector3d& d, const Element& where) {
    int big = 0;
    d.maxCoeff(&big);
    const double rest = d.sum() - d[big];
    // the tolerance sgal::Validate allows
    if (!(d.minCoeff() > 0) || rest >= d[big] * (1 - 1e-6)) return d;
    Eigen::Vector3d fixed = d;
    for (int i = 0; i < 3; ++i)
      if (i != big) fixed[i] = d[i] * d[big] / rest;
    ctx_.Warn(&where,
              "principal moments " + FormatNumbers(d.data(), 3) +
                  " kg m^2 violate the triangle inequality (no rigid body has them); raised to " +
                  FormatNumbers(fixed.data(), 3));
    return fixed;
  }

  // A solid box over the shapes' bounds, about the centre of mass.
  Eigen::Matrix3d InertiaFromShapes(const sgal::Body& body, const Element& rb) {
    Eigen::AlignedBox3d box;
    for (const auto& s : body.shapes) ExtendBounds(s.geometry, s.pose, &box);
    const double m = body.inertia.mass;
    if (box.isEmpty() || !(box.sizes().maxCoeff() > 0)) {
      ctx_.Warn(&rb, "no inertia and no bounded shape to estimate it from; " +
                         FormatNumber(m * 1e-3) + " kg m^2 about each axis assumed");
      return Eigen::Matrix3d::Identity() * m * 1e-3;
    }
    ctx_.WarnRepeated("rigid bodies without inertia", &rb,
                      "no inertia; estimated as a solid box over its shapes");
    const Eigen::Vector3d e = box.sizes().cwiseMax(1e-3 * box.sizes().maxCoeff());
    Eigen::Matrix3d tensor =
        Eigen::Vector3d(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(),
                        e.x() * e.x() + e.y() * e.y())
            .asDiagonal();
    tensor *= m / 12.0;
    const Eigen::Vector3d d = box.center() - body.inertia.com;
    tensor += m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
    return tensor;
  }

  // A 32-bit collision filter word.
  uint32_t Bits(const Element& e) {
    const double v = ctx_.Number(&e, 0);
    if (!(v >= 0) || v > 4294967295.0 || v != std::floor(v))
      ctx_.Fail(&e, "collision bits " + e.Trimmed() + " are not a 32-bit unsigned integer");
    return static_cast<uint32_t>(v);
  }

  void ReadShape(const Element& s, const BodyFrame& frame, const std::string& body_material,
                 sgal::Body* body) {
    sgal::Shape shape;
    shape.material = MaterialIn(&s);
    if (shape.material.empty()) shape.material = body_material;
    Eigen::Affine3d local = Placement(visual_, s);
    bool along_y = false;
    std::optional<sgal::Geometry> geometry;
    auto radius_of = [&](const Element* r, const char* what) {
      if (r == nullptr) ctx_.Fail(&s, std::string("the ") + what + " has no radius");
      const auto v = ctx_.Numbers(*r);
      if (v.empty() || v.size() > 2) ctx_.Fail(r, "needs one or two radii");
      if (v.size() == 2 && std::abs(v[0] - v[1]) > 1e-12 * std::max(std::abs(v[0]), std::abs(v[1])))
        ctx_.Warn(r, "an elliptic cross-section is not supported; the larger radius is used");
      return std::max(v.front(), v.back()) * ctx_.meter;
    };
    for (const auto& c : s.children) {
      const std::string_view kind = c->local_name();
      if (kind == "box") {
        const Element* h = c->Child("half_extents");
        if (h == nullptr) {
          ctx_.Warn(c.get(),
                    "box without <half_extents> (the DOM drops misspelt children); shape ignored");
          continue;
        }
        geometry = sgal::Box{ctx_.Vector3(*h) * 2 * ctx_.meter};
      } else if (kind == "sphere") {
        geometry = sgal::Sphere{ctx_.Number(c->Child("radius"), 1) * ctx_.meter};
      } else if (kind == "cylinder") {
        geometry = sgal::Cylinder{radius_of(c->Child("radius"), "cylinder"),
                                  ctx_.Number(c->Child("height"), 1) * ctx_.meter};
        along_y = true;
      } else if (kind == "capsule") {
        geometry = sgal::Capsule{radius_of(c->Child("radius"), "capsule"),
                                 ctx_.Number(c->Child("height"), 1) * ctx_.meter};
        along_y = true;
      } else if (kind == "tapered_cylinder" || kind == "tapered_capsule") {
        const double r1 = radius_of(c->Child("radius1"), "tapered shape");
        const double r2 = radius_of(c->Child("radius2"), "tapered shape");
        const double h = ctx_.Number(c->Child("height"), 1) * ctx_.meter;
        along_y = true;
        if (kind == "tapered_cylinder" && (r1 == 0 || r2 == 0)) {
          // radius1 is at +height/2, where sgal's cone has its apex: turn it over otherwise
          geometry = sgal::Cone{std::max(r1, r2), h};
          if (r2 == 0)
            local = local * Eigen::Affine3d(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()));
        } else {
          ctx_.Warn(c.get(), std::string(kind) + " is approximated by a " +
                                 (kind == "tapered_capsule" ? "capsule" : "cylinder") +
                                 " of the larger radius");
          if (kind == "tapered_capsule")
            geometry = sgal::Capsule{std::max(r1, r2), h};
          else
            geometry = sgal::Cylinder{std::max(r1, r2), h};
        }
      } else if (kind == "plane") {
        const Element* eq = c->Child("equation");
        if (eq == nullptr) ctx_.Fail(c.get(), "plane without <equation>");
        const auto v = ctx_.Numbers(*eq, 4);
        const Eigen::Vector3d n(v[0], v[1], v[2]);
        if (!(n.norm() > 0)) ctx_.Fail(eq, "plane normal is zero");
        // a x + b y + c z + d = 0  ->  n.x = -d / |n|
        geometry = sgal::Plane{n.normalized(), -v[3] / n.norm() * ctx_.meter};
      } else if (kind == "instance_geometry") {
        const Element& g = ctx_.Resolve(*c, c->Attribute("url"));
        if (g.local_name() != "geometry")
          ctx_.Fail(c.get(), "url '" + c->Attribute("url") + "' is not a <geometry>");
        const GeometryData& data = geometries_.Get(g);
        if (data.primitive) {
          geometry = *data.primitive;
        } else if (!data.usable) {
          ctx_.Warn(c.get(),
                    "geometry '" + g.Attribute("id") + "' has no usable mesh; shape ignored");
          continue;
        } else if (data.convex) {
          geometry = sgal::ConvexHull{data.all};
        } else {
          geometry = sgal::TriangleMesh{data.all};
        }
        shape.name = g.Attribute("id");
      }
    }
    bool placeholder = false;
    for (const Element* t : CaliperTechniques(s))
      for (const auto& c : t->children) {
        const std::string_view n = c->local_name();
        if (n == "name") {
          shape.name = c->text;
        } else if (n == "group") {
          shape.group = Bits(*c);
        } else if (n == "mask") {
          shape.mask = Bits(*c);
        } else if (n == "placeholder") {
          placeholder = true;
        } else {
          ctx_.Warn(c.get(),
                    "unknown element <" + std::string(n) + "> in a shape's Caliper technique");
        }
      }
    if (placeholder || !geometry) return;
    if (along_y) local = local * Eigen::Affine3d(kZToY);
    const Placed p = Place(frame.body_world, frame.frame_world, local);
    bool approximated = false;
    shape.geometry = ApplyLinear(*geometry, p.residual, &approximated);
    if (approximated)
      ctx_.Warn(&s, "a " + std::string(sgal::GeometryName(*geometry)) +
                        " under a non-uniform scale or shear became a convex hull");
    shape.pose = p.pose;
    body->shapes.push_back(std::move(shape));
  }

  // each side of a constraint: its body ("" for the world) and its frame in that body
  struct Side {
    std::string body;
    sgal::Pose frame;  // in the body (world frame for the world)
    bool present = false;
  };

  // limits: [min, max] per degree of freedom; min > max is free, min == max locked
  struct DofLimits {
    double lower[6] = {0, 0, 0, 0, 0, 0};
    double upper[6] = {0, 0, 0, 0, 0, 0};
    bool locked(int i) const {
      return std::abs(upper[i] - lower[i]) <= 1e-12 * (1 + std::abs(lower[i]));
    }
    bool free(int i) const { return lower[i] > upper[i]; }
  };

  using FindBody = std::function<const Element*(const std::string&)>;

  void ReadConstraint(const Element& rc, const FindBody& find_body,
                      const std::map<const Element*, std::string>& instanced,
                      const std::map<std::string, BodyFrame>& frames) {
    sgal::Constraint c;
    c.name = ConstraintName(rc);
    Side ref = ReadSide(rc.Child("ref_attachment"), find_body, instanced, frames);
    Side att = ReadSide(rc.Child("attachment"), find_body, instanced, frames);
    if (!ref.present && !att.present)
      ctx_.Fail(&rc, "has neither <ref_attachment> nor <attachment>");
    // a missing side is the world, where the other side's frame is at the start
    if (!ref.present) ref.frame = WorldFrame(att);
    if (!att.present) att.frame = WorldFrame(ref);
    if (ref.body.empty() && att.body.empty()) ctx_.Fail(&rc, "attaches no rigid body");
    const Element* tc = rc.Child("technique_common");
    if (tc != nullptr && !ctx_.Bool(tc->Child("enabled"), true)) {
      ctx_.Warn(&rc, "is disabled; not imported");
      return;
    }
    c.collide_connected = tc != nullptr && ctx_.Bool(tc->Child("interpenetrate"), false);
    const DofLimits limits = ReadLimits(tc);
    // springs: one linear and one angular law for all the free degrees of freedom
    sgal::JointSpring linear, angular;
    ReadSprings(tc, &linear, &angular);
    // frames: ref_attachment is the reference (sgal's a); the constraint acts on attachment (b)
    Side a = ref, b = att;
    bool flipped = false;
    if (a.body.empty()) {
      // the reference is the world: sgal needs body_a, so the sides swap and the joint
      // coordinate (b relative to a) changes sign
      std::swap(a, b);
      flipped = true;
    }
    c.body_a = a.body;
    c.body_b = b.body;
    c.frame_a = a.frame;
    c.frame_b = b.frame;
    const bool kind_given = ReadConstraintExtra(ctx_, rc, &c);
    int dof = -1;
    if (!kind_given) {
      dof = ChooseKind(limits, &c);
    } else if (c.kind == sgal::ConstraintKind::kHinge) {
      dof = 5;
    } else if (c.kind == sgal::ConstraintKind::kSlider) {
      dof = 2;
    }
    SetLimitsAndSprings(limits, dof, flipped, linear, angular, &c);
    ctx_.constraint_source[c.name] = &rc;
    ctx_.scene.constraints.push_back(std::move(c));
  }

  // a constraint's name, unique among those read so far
  std::string ConstraintName(const Element& rc) const {
    std::string name = CaliperName(rc);
    if (name.empty()) name = rc.Attribute("name");
    if (name.empty()) name = rc.Attribute("sid");
    if (name.empty()) name = "constraint";
    for (int i = 2; ctx_.constraint_source.count(name) > 0; ++i)
      name = (rc.Attribute("name").empty() ? rc.Attribute("sid") : rc.Attribute("name")) + "_" +
             std::to_string(i);
    return name;
  }

  // the side an <attachment> or <ref_attachment> (nullptr: absent) gives
  Side ReadSide(const Element* a, const FindBody& find_body,
                const std::map<const Element*, std::string>& instanced,
                const std::map<std::string, BodyFrame>& frames) const {
    Side s;
    if (a == nullptr) return s;
    s.present = true;
    const Eigen::Affine3d local = Placement(visual_, *a);
    const std::string ref = a->Attribute("rigid_body");
    if (ref.empty()) {
      s.frame = RigidPose(visual_.Root() * local);
      return s;
    }
    const Element* rb = find_body(ref);
    if (rb == nullptr)
      ctx_.Fail(a, "dangling reference: no rigid body '" + ref + "' in the physics model");
    const auto it = instanced.find(rb);
    if (it == instanced.end())
      ctx_.Fail(a, "rigid body '" + ref + "' is not instantiated in the physics scene");
    s.body = it->second;
    const BodyFrame& f = frames.at(s.body);
    s.frame = Place(f.body_world, f.frame_world, local).pose;
    return s;
  }

  // the frame of the world side of a constraint: where the other side's frame is at the start
  sgal::Pose WorldFrame(const Side& other) const {
    if (other.body.empty()) return other.frame;
    return ctx_.scene.bodies[ctx_.scene.BodyIndex(other.body)].pose * other.frame;
  }

  // the <limits> of a constraint's <technique_common> (nullptr: none), in SI units
  DofLimits ReadLimits(const Element* tc) const {
    DofLimits limits;
    const Element* e = tc == nullptr ? nullptr : tc->Child("limits");
    if (e == nullptr) return limits;
    auto read = [&](const char* group, int first, double scale) {
      const Element* g = e->Child(group);
      if (g == nullptr) return;
      if (const Element* mn = g->Child("min"); mn != nullptr) {
        const Eigen::Vector3d v = ctx_.Vector3(*mn);
        for (int i = 0; i < 3; ++i) limits.lower[first + i] = v[i] * scale;
      }
      if (const Element* mx = g->Child("max"); mx != nullptr) {
        const Eigen::Vector3d v = ctx_.Vector3(*mx);
        for (int i = 0; i < 3; ++i) limits.upper[first + i] = v[i] * scale;
      }
    };
    read("linear", 0, ctx_.meter);
    read("swing_cone_and_twist", 3, kDegree);
    return limits;
  }

  // the <spring> of a constraint's <technique_common> (nullptr: none), in SI units
  void ReadSprings(const Element* tc, sgal::JointSpring* linear, sgal::JointSpring* angular) const {
    const Element* spring = tc == nullptr ? nullptr : tc->Child("spring");
    if (spring == nullptr) return;
    if (const Element* l = spring->Child("linear"); l != nullptr) {
      linear->stiffness = ctx_.Number(l->Child("stiffness"), 0) / ctx_.meter;
      linear->damping = ctx_.Number(l->Child("damping"), 0) / ctx_.meter;
      linear->rest = ctx_.Number(l->Child("target_value"), 0) * ctx_.meter;
    }
    if (const Element* a = spring->Child("angular"); a != nullptr) {
      // torque per degree in document units -> N m/rad
      angular->stiffness = ctx_.Number(a->Child("stiffness"), 0) * ctx_.meter / kDegree;
      angular->damping = ctx_.Number(a->Child("damping"), 0) * ctx_.meter / kDegree;
      angular->rest = ctx_.Number(a->Child("target_value"), 0) * kDegree;
    }
  }

  // The kind the limits make of a constraint whose Caliper extra named none; hinges and sliders
  // have their frames turned so that z is the open axis. Returns the open degree of freedom of a
  // hinge or a slider, -1 for the other kinds.
  static int ChooseKind(const DofLimits& limits, sgal::Constraint* c) {
    std::vector<int> open_linear, open_angular;
    bool offset_lock = false;
    for (int i = 0; i < 6; ++i) {
      if (!limits.locked(i))
        (i < 3 ? open_linear : open_angular).push_back(i);
      else if (std::abs(limits.lower[i]) > 1e-12)
        offset_lock = true;
    }
    int dof = -1;
    if (offset_lock) {
      c->kind = sgal::ConstraintKind::kGeneric6Dof;
    } else if (open_linear.empty() && open_angular.empty()) {
      c->kind = sgal::ConstraintKind::kFixed;
    } else if (open_linear.empty() && open_angular.size() == 1) {
      c->kind = sgal::ConstraintKind::kHinge;
      dof = open_angular[0];
    } else if (open_angular.empty() && open_linear.size() == 1) {
      c->kind = sgal::ConstraintKind::kSlider;
      dof = open_linear[0];
    } else if (open_linear.empty() && open_angular.size() == 3 && limits.free(3) &&
               limits.free(4) && limits.free(5)) {
      c->kind = sgal::ConstraintKind::kBall;
    } else {
      c->kind = sgal::ConstraintKind::kGeneric6Dof;
    }
    // hinges and sliders act along z: turn both frames so that z is the open axis
    if (dof >= 0) {
      Eigen::Quaterniond turn = Eigen::Quaterniond::Identity();
      const int axis = dof % 3;
      if (axis == 0) turn = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY());
      if (axis == 1) turn = Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitX());
      c->frame_a.orientation = (c->frame_a.orientation * turn).normalized();
      c->frame_b.orientation = (c->frame_b.orientation * turn).normalized();
    }
    return dof;
  }

  // The limits of the constraint's kind (those of `dof` for a hinge or a slider), and the spring
  // laws unless its Caliper extra gave springs; `flipped`: the sides were swapped.
  static void SetLimitsAndSprings(const DofLimits& limits, int dof, bool flipped,
                                  const sgal::JointSpring& linear, const sgal::JointSpring& angular,
                                  sgal::Constraint* c) {
    auto set = [&](int slot, int i) {
      double lo = limits.lower[i], hi = limits.upper[i];
      if (lo <= hi && flipped) std::tie(lo, hi) = std::make_pair(-hi, -lo);
      c->limits[slot].lower = lo;
      c->limits[slot].upper = hi;
    };
    const bool springs_given =
        std::any_of(c->springs.begin(), c->springs.end(), [](const sgal::JointSpring& s) {
          return s.stiffness != 0 || s.damping != 0 || s.rest != 0;
        });
    auto spring = [&](int slot, const sgal::JointSpring& law) {
      if (springs_given) return;
      c->springs[slot] = law;
      if (flipped) c->springs[slot].rest = -law.rest;
    };
    if (c->kind == sgal::ConstraintKind::kHinge || c->kind == sgal::ConstraintKind::kSlider) {
      set(0, dof);
      spring(0, c->kind == sgal::ConstraintKind::kHinge ? angular : linear);
    } else if (c->kind == sgal::ConstraintKind::kGeneric6Dof) {
      for (int i = 0; i < 6; ++i) {
        set(i, i);
        if (!limits.locked(i)) spring(i, i < 3 ? linear : angular);
      }
    }
  }

  Context& ctx_;
  const VisualScene& visual_;
  GeometryLibrary& geometries_;
  std::map<const Element*, std::string> materials_;
  size_t bodies_ = 0;
};

// The visuals of one node's geometry, placed in a body.
void AddGeometry(Context& ctx, GeometryLibrary& geometries, const NodeInstance& inst,
                 const Eigen::Isometry3d& body_world, sgal::Body* body, bool with_visuals,
                 bool with_shapes) {
  const Eigen::Affine3d rel = Eigen::Affine3d(body_world.inverse()) * inst.world;
  Eigen::Isometry3d rigid;
  Eigen::Matrix3d residual;
  SplitRigid(rel, &rigid, &residual);
  const sgal::Pose pose = sgal::Pose::FromIsometry(rigid);
  for (const NodeGeometry& g : inst.geometry) {
    const GeometryData& data = geometries.Get(*g.geometry);
    const std::string name = g.geometry->Attribute("id");
    bool approximated = false;
    if (with_visuals && data.primitive) {
      sgal::Visual v;
      v.name = name;
      v.geometry = ApplyLinear(*data.primitive, residual, &approximated);
      v.pose = pose;
      std::string symbol;
      if (!data.parts.empty()) symbol = data.parts.front().material;
      v.color = BoundColor(ctx, *g.instance, symbol);
      body->visuals.push_back(std::move(v));
    } else if (with_visuals) {
      for (const MeshPart& part : data.parts) {
        sgal::Visual v;
        v.name = name;
        v.geometry = ApplyLinear(sgal::TriangleMesh{part.mesh}, residual, &approximated);
        v.pose = pose;
        v.color = BoundColor(ctx, *g.instance, part.material);
        body->visuals.push_back(std::move(v));
      }
    }
    if (with_shapes && (data.usable || data.primitive)) {
      sgal::Shape s;
      s.name = name;
      if (data.primitive)
        s.geometry = ApplyLinear(*data.primitive, residual, &approximated);
      else if (data.convex)
        s.geometry = ApplyLinear(sgal::ConvexHull{data.all}, residual, &approximated);
      else
        s.geometry = ApplyLinear(sgal::TriangleMesh{data.all}, residual, &approximated);
      s.pose = pose;
      body->shapes.push_back(std::move(s));
    }
  }
}

}  // namespace

bool ReadConstraintExtra(Context& ctx, const Element& owner, sgal::Constraint* c) {
  bool kind_given = false;
  for (const Element* t : CaliperTechniques(owner)) {
    for (const auto& e : t->children) {
      const std::string_view n = e->local_name();
      if (n == "kind") {
        const std::string k = e->Trimmed();
        if (k == "hinge")
          c->kind = sgal::ConstraintKind::kHinge;
        else if (k == "slider")
          c->kind = sgal::ConstraintKind::kSlider;
        else if (k == "ball")
          c->kind = sgal::ConstraintKind::kBall;
        else if (k == "fixed")
          c->kind = sgal::ConstraintKind::kFixed;
        else if (k == "generic_6dof")
          c->kind = sgal::ConstraintKind::kGeneric6Dof;
        else
          ctx.Fail(e.get(), "unknown constraint kind '" + k +
                                "' (hinge, slider, ball, fixed, generic_6dof)");
        kind_given = true;
      } else if (n == "name") {
        // read with the constraint's name
      } else if (n == "spring") {
        const int slot = DofSlot(ctx, *e);
        const auto v = ctx.Numbers(*e, 3);
        c->springs[slot] = sgal::JointSpring{v[0], v[1], v[2]};
      } else if (n == "friction") {
        const int slot = DofSlot(ctx, *e);
        const double friction = ctx.Numbers(*e, 1)[0];
        if (!(friction >= 0) || !std::isfinite(friction))
          ctx.Fail(e.get(), "joint friction " + e->Trimmed() +
                                " (N or N m) must be finite and not negative");
        c->friction[slot] = friction;
      } else {
        ctx.Warn(e.get(),
                 "unknown element <" + std::string(n) + "> in a constraint's Caliper technique");
      }
    }
  }
  return kind_given;
}

size_t ImportPhysics(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries) {
  return PhysicsReader(ctx, visual, geometries).Read();
}

void MakeStaticBodies(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries) {
  const auto& nodes = visual.nodes();
  for (size_t i = 0; i < nodes.size(); ++i) {
    const NodeInstance& inst = nodes[i];
    if (inst.geometry.empty()) continue;
    sgal::Body body;
    body.name = ctx.UniqueBodyName(NodeName(*inst.node).empty() ? "node" : NodeName(*inst.node));
    body.type = sgal::BodyType::kStatic;
    body.pose = RigidPose(inst.world);
    AddGeometry(ctx, geometries, inst, body.pose.ToIsometry(), &body, false, true);
    ctx.instance_body[static_cast<int>(i)] = body.name;
    ctx.AddBody(std::move(body), inst.node,
                {inst.node->Attribute("id"), inst.node->Attribute("name")});
  }
}

void AttachVisuals(Context& ctx, const VisualScene& visual, GeometryLibrary& geometries) {
  const auto& nodes = visual.nodes();
  for (size_t i = 0; i < nodes.size(); ++i) {
    const NodeInstance& inst = nodes[i];
    if (inst.geometry.empty()) continue;
    std::string body;
    for (int k = static_cast<int>(i); k >= 0 && body.empty(); k = nodes[k].parent) {
      const auto it = ctx.instance_body.find(k);
      if (it != ctx.instance_body.end()) body = it->second;
    }
    if (body.empty()) {
      // geometry no rigid body moves: scenery, drawn on a static body without collision
      sgal::Body b;
      b.name = ctx.UniqueBodyName(NodeName(*inst.node).empty() ? "node" : NodeName(*inst.node));
      b.type = sgal::BodyType::kStatic;
      b.pose = RigidPose(inst.world);
      ctx.instance_body[static_cast<int>(i)] = b.name;
      body = b.name;
      ctx.AddBody(std::move(b), inst.node,
                  {inst.node->Attribute("id"), inst.node->Attribute("name")});
    }
    sgal::Body& target = ctx.scene.bodies[ctx.scene.BodyIndex(body)];
    AddGeometry(ctx, geometries, inst, target.pose.ToIsometry(), &target, true, false);
  }
}

}  // namespace caliper::collada::internal
