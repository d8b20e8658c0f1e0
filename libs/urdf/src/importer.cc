#include "caliper/urdf/importer.h"

#include <console_bridge/console.h>
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>

#include "caliper/collada/technique.h"
#include "meshes.h"

namespace caliper::urdf {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// What libxml2 reads in the file: the lines of links and joints for messages, and what urdfdom
// accepts silently (a link with two parents, a loop, geometry it drops).

struct JointFacts {
  std::string name, type, parent, child;
  int line = 0;
};

struct GeometryFacts {
  std::string link, owner;  // the link; "visual" or "collision"
  std::string kind;         // the geometry element's name ("" when it has none)
  int line = 0;
};

struct XmlFacts {
  std::string root_element;
  int root_line = 0;
  std::map<std::string, int> link_lines;
  std::vector<JointFacts> joints;
  std::vector<GeometryFacts> geometries;
  std::optional<bool> merge_fixed_joints;  // <caliper fixed_joints="merge|keep">
  std::optional<bool> floating_base;       // <caliper base="fixed|floating">
  std::optional<bool> self_collision;      // <caliper self_collision="true|false">
};

const char* Chars(const xmlChar* s) { return reinterpret_cast<const char*>(s); }

bool Named(const xmlNode* n, const char* name) {
  return n->type == XML_ELEMENT_NODE && std::strcmp(Chars(n->name), name) == 0;
}

std::string AttributeOf(const xmlNode* n, const char* name) {
  xmlChar* v = xmlGetProp(n, reinterpret_cast<const xmlChar*>(name));
  std::string out = v == nullptr ? "" : Chars(v);
  xmlFree(v);
  return out;
}

const xmlNode* ChildNamed(const xmlNode* n, const char* name) {
  for (const xmlNode* c = n->children; c != nullptr; c = c->next)
    if (Named(c, name)) return c;
  return nullptr;
}

int LineOf(const xmlNode* n) { return static_cast<int>(xmlGetLineNo(n)); }

// console_bridge's messages (urdfdom reports through it) kept for the error, not printed.
class Capture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages.push_back(text);
  }
  std::vector<std::string> messages;
};

// console_bridge's handler is global: one urdfdom parse at a time
std::mutex urdfdom_mutex;

Eigen::Vector3d ToEigen(const ::urdf::Vector3& v) { return {v.x, v.y, v.z}; }

sgal::Pose ToPose(const ::urdf::Pose& p) {
  sgal::Pose out;
  out.position = ToEigen(p.position);
  out.orientation = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  out.orientation.normalize();
  return out;
}

std::string Number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

std::string Numbers(const Eigen::Vector3d& v) {
  return Number(v.x()) + " " + Number(v.y()) + " " + Number(v.z());
}

// A rotation that takes z to `axis` (unit): the frame a hinge or slider of sgal turns about.
Eigen::Quaterniond ZTo(const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).normalized();
}

// Mass properties in one frame: mass [kg], centre of mass [m], tensor about it [kg m^2].
struct MassProperties {
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d tensor = Eigen::Matrix3d::Zero();
};

Eigen::Matrix3d Shift(double mass, const Eigen::Vector3d& d) {
  return mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
}

// What a link gets that needs a mass and has none: kDefaultMass as a solid sphere of
// kDefaultRadius about the link's origin.
MassProperties DefaultMass() {
  MassProperties m;
  m.mass = kDefaultMass;
  m.tensor = Eigen::Matrix3d::Identity() * 0.4 * kDefaultMass * kDefaultRadius * kDefaultRadius;
  return m;
}

// Two bodies' mass properties as one (both in the same frame).
MassProperties Combine(const MassProperties& a, const MassProperties& b) {
  MassProperties out;
  out.mass = a.mass + b.mass;
  if (!(out.mass > 0)) return out;
  out.com = (a.mass * a.com + b.mass * b.com) / out.mass;
  out.tensor =
      a.tensor + Shift(a.mass, a.com - out.com) + b.tensor + Shift(b.mass, b.com - out.com);
  return out;
}

// The collision group of a robot's shapes when its links do not collide with each other.
constexpr uint32_t kRobotGroup = 1u << 1;

class Importer {
 public:
  Importer(std::string path, std::vector<std::string>* warnings, Options options)
      : path_(std::move(path)), warnings_(warnings), options_(std::move(options)) {}

  sgal::Scene Run() {
    ReadFacts();
    if (facts_.merge_fixed_joints) options_.merge_fixed_joints = *facts_.merge_fixed_joints;
    if (facts_.floating_base) options_.floating_base = *facts_.floating_base;
    if (facts_.self_collision) options_.self_collision = *facts_.self_collision;
    if (options_.package_path.empty()) options_.package_path = PackagePathFromEnvironment();
    packages_.SetPath(options_.package_path);
    CheckTree();
    model_ = Parse();
    for (const auto& g : facts_.geometries) CheckGeometry(g);
    scene_.name = model_->getName().empty() ? fs::path(path_).stem().string() : model_->getName();
    scene_.source = path_;
    world_is_link_ = model_->getRoot()->name == "world" && !model_->getRoot()->inertial;
    PlaceLinks(model_->getRoot(), sgal::Pose());
    for (const auto& [name, link] : model_->links_) AddLink(*link);
    for (const auto& [name, joint] : model_->joints_) AddJoint(*joint);
    for (const auto& [name, joint] : model_->joints_) AddMimic(*joint);
    ReadCaliperData();
    if (options_.merge_fixed_joints) MergeFixedJoints();
    FinishMasses();
    CheckScene();
    return std::move(scene_);
  }

 private:
  // ---- messages

  std::string WhereLink(const std::string& name) const {
    const auto it = facts_.link_lines.find(name);
    return At(it != facts_.link_lines.end() ? it->second : 0) + ": link '" + name + "'";
  }
  std::string WhereJoint(const std::string& name) const {
    return At(JointLine(name)) + ": joint '" + name + "'";
  }
  int JointLine(const std::string& name) const {
    for (const auto& j : facts_.joints)
      if (j.name == name) return j.line;
    return 0;
  }
  // `file:line` (the file alone when the line is not known)
  std::string At(int line) const { return path_ + (line > 0 ? ":" + std::to_string(line) : ""); }
  [[noreturn]] void Fail(const std::string& where, const std::string& message) const {
    throw ImportError(where + ": " + message);
  }
  void Warn(const std::string& where, const std::string& message) const {
    if (warnings_ != nullptr) warnings_->push_back(where + ": " + message);
  }

  // ---- the file as libxml2 reads it

  void ReadFacts() {
    std::error_code ec;
    if (!fs::is_regular_file(path_, ec)) Fail(path_, "no such file");
    static_assert(LIBXML_VERSION >= 20900, "xmlCtxtGetLastError");
    xmlParserCtxtPtr ctxt = xmlNewParserCtxt();
    if (ctxt == nullptr) Fail(path_, "libxml2 could not make a parser");
    xmlDocPtr doc = xmlCtxtReadFile(
        ctxt, path_.c_str(), nullptr,
        XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_BIG_LINES);
    if (doc == nullptr || ctxt->wellFormed == 0) {
      const xmlError* e = xmlCtxtGetLastError(ctxt);
      std::string why = e != nullptr && e->message != nullptr ? e->message : "not well-formed";
      while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
      const int line = e != nullptr ? e->line : 0;
      if (doc != nullptr) xmlFreeDoc(doc);
      xmlFreeParserCtxt(ctxt);
      Fail(path_ + (line > 0 ? ":" + std::to_string(line) : ""), "malformed XML: " + why);
    }
    xmlFreeParserCtxt(ctxt);
    std::unique_ptr<xmlDoc, void (*)(xmlDocPtr)> owned(doc, xmlFreeDoc);
    const xmlNode* root = xmlDocGetRootElement(doc);
    facts_.root_element = root != nullptr ? Chars(root->name) : "";
    if (root == nullptr || facts_.root_element != "robot")
      Fail(path_ + (root != nullptr ? ":" + std::to_string(LineOf(root)) : ""),
           "the root element is <" + facts_.root_element + ">, not <robot>: not a URDF");
    facts_.root_line = LineOf(root);
    for (const xmlNode* n = root->children; n != nullptr; n = n->next) {
      if (Named(n, "link")) {
        const std::string name = AttributeOf(n, "name");
        if (facts_.link_lines.count(name) > 0)
          Fail(path_ + ":" + std::to_string(LineOf(n)),
               "link '" + name + "': a second link of this name (the first is on line " +
                   std::to_string(facts_.link_lines[name]) + ")");
        facts_.link_lines[name] = LineOf(n);
        for (const xmlNode* c = n->children; c != nullptr; c = c->next) {
          if (!Named(c, "visual") && !Named(c, "collision")) continue;
          GeometryFacts g{name, Chars(c->name), "", LineOf(c)};
          if (const xmlNode* geometry = ChildNamed(c, "geometry"); geometry != nullptr) {
            g.line = LineOf(geometry);
            for (const xmlNode* k = geometry->children; k != nullptr; k = k->next)
              if (k->type == XML_ELEMENT_NODE) {
                g.kind = Chars(k->name);
                g.line = LineOf(k);
                break;
              }
          }
          facts_.geometries.push_back(g);
        }
      } else if (Named(n, "joint")) {
        JointFacts j{AttributeOf(n, "name"), AttributeOf(n, "type"), "", "", LineOf(n)};
        if (const xmlNode* p = ChildNamed(n, "parent"); p != nullptr)
          j.parent = AttributeOf(p, "link");
        if (const xmlNode* c = ChildNamed(n, "child"); c != nullptr)
          j.child = AttributeOf(c, "link");
        facts_.joints.push_back(j);
      } else if (Named(n, "caliper")) {
        ReadCaliperAttributes(n, path_);
      }
    }
    // the side file's <caliper> says the same things (a robot's URDF need not be edited)
    std::error_code side_ec;
    if (fs::is_regular_file(SidePath(), side_ec)) {
      const std::string side = SidePath().string();
      std::unique_ptr<xmlDoc, void (*)(xmlDocPtr)> side_doc(
          xmlReadFile(
              side.c_str(), nullptr,
              XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_BIG_LINES),
          xmlFreeDoc);
      // a malformed side file is reported with its line when the technique is read
      const xmlNode* side_root = side_doc ? xmlDocGetRootElement(side_doc.get()) : nullptr;
      if (side_root != nullptr && Named(side_root, "caliper"))
        ReadCaliperAttributes(side_root, side);
    }
  }

  fs::path SidePath() const {
    return fs::path(path_).parent_path() / (fs::path(path_).stem().string() + ".caliper.xml");
  }

  // base, fixed_joints and self_collision of a <caliper> element; a second element that says
  // otherwise than the first is an error
  void ReadCaliperAttributes(const xmlNode* n, const std::string& file) {
    const std::string where = file + ":" + std::to_string(LineOf(n)) + ": <caliper>";
    auto read = [&](const char* attribute, const char* yes, const char* no,
                    std::optional<bool>* into) {
      const std::string v = AttributeOf(n, attribute);
      if (v.empty()) return;
      if (v != yes && v != no)
        Fail(where, std::string(attribute) + "=\"" + v + "\": " + yes + " or " + no);
      if (*into && **into != (v == yes))
        Fail(where, std::string(attribute) + "=\"" + v + "\" where an earlier <caliper> says " +
                        (**into ? yes : no));
      *into = v == yes;
    };
    read("fixed_joints", "merge", "keep", &facts_.merge_fixed_joints);
    read("base", "floating", "fixed", &facts_.floating_base);
    read("self_collision", "true", "false", &facts_.self_collision);
  }

  // The shape of the tree, checked before urdfdom (which takes the last of two parents and
  // reports a loop only as a missing root).
  void CheckTree() {
    std::map<std::string, const JointFacts*> parent_of;
    std::set<std::string> joint_names;
    for (const auto& j : facts_.joints) {
      const std::string where = path_ + ":" + std::to_string(j.line) + ": joint '" + j.name + "'";
      if (j.name.empty())
        Fail(path_ + ":" + std::to_string(j.line) + ": joint", "has no name attribute");
      if (!joint_names.insert(j.name).second) Fail(where, "a second joint of this name");
      for (const auto& [role, link] :
           {std::pair{"parent", j.parent}, std::pair{"child", j.child}}) {
        if (link.empty()) Fail(where, std::string("has no <") + role + " link=\"...\">");
        if (facts_.link_lines.count(link) == 0)
          Fail(where, std::string(role) + " link '" + link + "' is not defined in the file");
      }
      if (j.parent == j.child) Fail(where, "joins link '" + j.child + "' to itself");
      const auto [it, fresh] = parent_of.emplace(j.child, &j);
      if (!fresh)
        Fail(WhereLink(j.child), "has two parents: joint '" + it->second->name + "' (line " +
                                     std::to_string(it->second->line) + ") and joint '" + j.name +
                                     "' (line " + std::to_string(j.line) +
                                     "); a URDF is a tree, where each link has one parent");
    }
    // every link must reach a root by its parents; a walk that comes back to itself is a loop.
    // Links known to reach a root end later walks (a deep chain stays linear).
    std::vector<std::string> roots;
    std::set<std::string> reaches_root;
    for (const auto& [link, line] : facts_.link_lines) {
      if (parent_of.count(link) == 0) {
        roots.push_back(link);
        reaches_root.insert(link);
      }
    }
    for (const auto& [link, line] : facts_.link_lines) {
      std::vector<std::string> walk;
      std::map<std::string, size_t> on_walk;
      std::string at = link;
      while (reaches_root.count(at) == 0) {
        if (const auto seen = on_walk.find(at); seen != on_walk.end()) {
          std::string loop;
          for (size_t k = seen->second; k < walk.size(); ++k)
            loop += (loop.empty() ? "" : " <- ") + walk[k] + " (joint '" +
                    parent_of[walk[k]]->name + "', line " +
                    std::to_string(parent_of[walk[k]]->line) + ")";
          Fail(WhereLink(at), "the joints form a loop: " + loop + " <- " + at);
        }
        on_walk[at] = walk.size();
        walk.push_back(at);
        at = parent_of.at(at)->parent;
      }
      reaches_root.insert(walk.begin(), walk.end());
    }
    if (facts_.link_lines.count("world") > 0 && parent_of.count("world") > 0)
      Fail(WhereLink("world"),
           "is the child of joint '" + parent_of["world"]->name +
               "': 'world' names the world (Gazebo's convention, and Caliper's data's "
               "body=\"world\"), so only a root link may be called so; rename it");
    if (facts_.link_lines.empty())
      Fail(path_ + ":" + std::to_string(facts_.root_line) + ": robot", "has no links");
    if (roots.size() > 1) {
      std::string names;
      for (const auto& r : roots)
        names += (names.empty() ? "" : ", ") + r + " (line " +
                 std::to_string(facts_.link_lines[r]) + ")";
      Fail(path_ + ":" + std::to_string(facts_.root_line) + ": robot",
           std::to_string(roots.size()) + " links have no parent joint: " + names +
               "; a URDF is one tree with one root link");
    }
  }

  std::shared_ptr<::urdf::ModelInterface> Parse() {
    std::lock_guard<std::mutex> lock(urdfdom_mutex);
    Capture capture;
    console_bridge::useOutputHandler(&capture);
    std::shared_ptr<::urdf::ModelInterface> model;
    try {
      model = ::urdf::parseURDFFile(path_);
    } catch (const std::exception& e) {
      capture.messages.push_back(e.what());
    }
    console_bridge::restorePreviousOutputHandler();
    if (!model) {
      std::string why;
      for (const auto& m : capture.messages) why += (why.empty() ? "" : "; ") + m;
      // urdfdom names the element as "Joint [NAME]" or "Link [NAME]": give its line
      std::string where = path_;
      for (const auto& j : facts_.joints)
        if (why.find("[" + j.name + "]") != std::string::npos) where = WhereJoint(j.name);
      if (where == path_)
        for (const auto& [link, line] : facts_.link_lines)
          if (why.find("[" + link + "]") != std::string::npos) where = WhereLink(link);
      Fail(where, "liburdfdom cannot read it: " + (why.empty() ? "no reason given" : why));
    }
    return model;
  }

  void CheckGeometry(const GeometryFacts& g) {
    static const std::set<std::string> known = {"box", "cylinder", "sphere", "mesh"};
    if (known.count(g.kind) > 0) return;
    Warn(path_ + ":" + std::to_string(g.line) + ": link '" + g.link + "'",
         g.kind.empty() ? "<" + g.owner + "> without geometry; skipped"
                        : "<" + g.owner + "> of unknown geometry <" + g.kind +
                              "> (box, cylinder, sphere or mesh); skipped");
  }

  // ---- links to bodies

  bool IsWorld(const std::string& link) const {
    return world_is_link_ && link == model_->getRoot()->name;
  }

  void PlaceLinks(const std::shared_ptr<const ::urdf::Link>& link, const sgal::Pose& pose) {
    link_pose_[link->name] = pose;
    for (const auto& joint : link->child_joints)
      PlaceLinks(model_->getLink(joint->child_link_name),
                 pose * ToPose(joint->parent_to_joint_origin_transform));
  }

  // Sizes no body has (zero, negative, not finite, beyond 1 km) stop the import: the engine would
  // make them into a shape of no volume or of NaN.
  void CheckSize(const std::string& link, const char* owner, const std::string& what,
                 const Eigen::Vector3d& values) {
    for (int i = 0; i < 3; ++i)
      if (!(values[i] > 0) || !(values[i] <= 1e3))
        Fail(WhereLink(link), std::string("<") + owner + "> " + what + " " + Numbers(values) +
                                  ": sizes must be positive numbers of at most 1000 m");
  }

  std::optional<sgal::Geometry> GeometryOf(const ::urdf::Geometry& g, const std::string& link,
                                           bool collision, Eigen::Vector4f* color) {
    const char* owner = collision ? "collision" : "visual";
    switch (g.type) {
      case ::urdf::Geometry::BOX: {
        sgal::Box box;
        box.size = ToEigen(static_cast<const ::urdf::Box&>(g).dim);
        CheckSize(link, owner, "box size", box.size);
        return box;
      }
      case ::urdf::Geometry::SPHERE: {
        sgal::Sphere s;
        s.radius = static_cast<const ::urdf::Sphere&>(g).radius;
        CheckSize(link, owner, "sphere radius", Eigen::Vector3d::Constant(s.radius));
        return s;
      }
      case ::urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const ::urdf::Cylinder&>(g);
        sgal::Cylinder cyl;
        cyl.radius = c.radius;
        cyl.length = c.length;
        CheckSize(link, owner, "cylinder radius, length, radius",
                  Eigen::Vector3d(c.radius, c.length, c.radius));
        return cyl;
      }
      case ::urdf::Geometry::MESH: {
        const auto& m = static_cast<const ::urdf::Mesh&>(g);
        const Eigen::Vector3d scale = ToEigen(m.scale);
        // a mirroring (negative) scale is fine; zero flattens, huge overflows the mesh's floats
        CheckSize(link, owner, "mesh scale (absolute)", scale.cwiseAbs());
        std::vector<std::string> tried;
        const std::string file = packages_.Resolve(m.filename, path_, &tried);
        if (file.empty()) {
          std::string places;
          for (const auto& t : tried) places += "\n  " + t;
          Fail(WhereLink(link),
               std::string(owner) + " mesh '" + m.filename + "' not found; tried:" + places);
        }
        internal::MeshFile mesh;
        try {
          mesh = meshes_.Load(file, scale);
        } catch (const std::exception& e) {
          Fail(WhereLink(link), "mesh " + file + ": " + e.what());
        }
        if (mesh.color && color != nullptr) *color = *mesh.color;
        if (collision) return sgal::ConvexHull{mesh.mesh};
        return sgal::TriangleMesh{mesh.mesh};
      }
    }
    return std::nullopt;
  }

  void AddLink(const ::urdf::Link& link) {
    if (IsWorld(link.name)) {
      if (!link.visual_array.empty() || !link.collision_array.empty() || link.inertial)
        Warn(WhereLink(link.name),
             "the root link 'world' is the world itself: its " +
                 std::to_string(link.visual_array.size()) + " visual(s) and " +
                 std::to_string(link.collision_array.size()) +
                 " collision(s) are not loaded (put them on a link fixed to it)");
      return;
    }
    sgal::Body body;
    body.name = link.name;
    body.pose = link_pose_.at(link.name);
    const bool root = link.name == model_->getRoot()->name;
    const auto parent = link.parent_joint;
    const bool on_world = parent && IsWorld(parent->parent_link_name);
    if ((root && !options_.floating_base) || (on_world && parent->type == ::urdf::Joint::FIXED))
      body.type = sgal::BodyType::kStatic;
    MassProperties mp;
    if (link.inertial) {
      const auto& in = *link.inertial;
      if (!std::isfinite(in.mass) || in.mass < 0)
        Fail(WhereLink(link.name), "mass " + Number(in.mass) + " kg: must be a finite number >= 0");
      const sgal::Pose frame = ToPose(in.origin);
      Eigen::Matrix3d local;
      local << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      if (!local.allFinite()) Fail(WhereLink(link.name), "an inertia that is not a finite number");
      const Eigen::Matrix3d r = frame.orientation.toRotationMatrix();
      mp.mass = in.mass;
      mp.com = frame.position;
      mp.tensor = r * Physical(local, in.mass, link.name) * r.transpose();
      has_inertial_.insert(link.name);
    }
    mass_[link.name] = mp;
    for (size_t i = 0; i < link.collision_array.size(); ++i) {
      const auto& c = *link.collision_array[i];
      if (!c.geometry) continue;
      auto geometry = GeometryOf(*c.geometry, link.name, true, nullptr);
      if (!geometry) continue;
      sgal::Shape shape;
      shape.name = c.name.empty()
                       ? link.name + "_collision" + (i > 0 ? "_" + std::to_string(i) : "")
                       : c.name;
      shape.geometry = std::move(*geometry);
      shape.pose = ToPose(c.origin);
      if (!options_.self_collision) {
        // the robot's own links pass through each other (their meshes often overlap where they
        // join); everything else they meet
        shape.group = kRobotGroup;
        shape.mask = ~kRobotGroup;
      }
      body.shapes.push_back(std::move(shape));
    }
    for (size_t i = 0; i < link.visual_array.size(); ++i) {
      const auto& v = *link.visual_array[i];
      if (!v.geometry) continue;
      sgal::Visual visual;
      auto geometry = GeometryOf(*v.geometry, link.name, false, &visual.color);
      if (!geometry) continue;
      visual.name =
          v.name.empty() ? link.name + "_visual" + (i > 0 ? "_" + std::to_string(i) : "") : v.name;
      visual.geometry = std::move(*geometry);
      visual.pose = ToPose(v.origin);
      // the URDF's material wins over the mesh file's own colour
      if (v.material && (v.material->color.r != 0 || v.material->color.g != 0 ||
                         v.material->color.b != 0 || v.material->color.a != 0))
        visual.color = Eigen::Vector4f(v.material->color.r, v.material->color.g,
                                       v.material->color.b, v.material->color.a);
      body.visuals.push_back(std::move(visual));
    }
    scene_.bodies.push_back(std::move(body));
  }

  // Principal moments no rigid body has come back raised, with a warning: non-positive ones to a
  // thousandth of the largest (a sphere's when all are), then the two smaller in proportion
  // until their sum reaches the largest (the COLLADA importer's rule).
  Eigen::Matrix3d Physical(const Eigen::Matrix3d& tensor, double mass, const std::string& link) {
    if (mass == 0 && tensor.isZero()) return tensor;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(tensor);
    Eigen::Vector3d d = eigen.eigenvalues();
    const Eigen::Vector3d given = d;
    if (d.minCoeff() < 0)
      Fail(WhereLink(link),
           "inertia with a negative principal moment (" + Numbers(d) + " kg m^2): no body has one");
    if (!(d.maxCoeff() > 0)) {
      d.setConstant(0.4 * std::max(mass, kDefaultMass) * kDefaultRadius * kDefaultRadius);
    } else {
      for (int i = 0; i < 3; ++i)
        if (!(d[i] > 0)) d[i] = 1e-3 * d.maxCoeff();
    }
    int big = 0;
    d.maxCoeff(&big);
    const double rest = d.sum() - d[big];
    if (rest < d[big] * (1 - 1e-6))
      for (int i = 0; i < 3; ++i)
        if (i != big) d[i] *= d[big] / rest;
    if (d == given) return tensor;
    Warn(WhereLink(link), "principal moments of inertia " + Numbers(given) +
                              " kg m^2 are not those of a rigid body; raised to " + Numbers(d));
    return eigen.eigenvectors() * d.asDiagonal() * eigen.eigenvectors().transpose();
  }

  // ---- joints to constraints

  void AddJoint(const ::urdf::Joint& j) {
    using J = ::urdf::Joint;
    if (j.type == J::FLOATING) return;  // a free body: no constraint
    if (j.type == J::FIXED && options_.merge_fixed_joints) return;
    if (j.type == J::FIXED && IsWorld(j.parent_link_name)) return;  // a static body already
    if (j.type == J::UNKNOWN) Fail(WhereJoint(j.name), "of unknown type");
    sgal::Constraint c;
    c.name = j.name;
    c.body_a = j.child_link_name;
    c.body_b = IsWorld(j.parent_link_name) ? "" : j.parent_link_name;
    const sgal::Pose origin = ToPose(j.parent_to_joint_origin_transform);
    Eigen::Vector3d axis = ToEigen(j.axis);
    if (j.type != J::FIXED) {
      if (!axis.allFinite() || !(axis.norm() > 1e-12))
        Fail(WhereJoint(j.name), "axis " + Numbers(axis) + " has no direction");
      axis.normalize();
    }
    sgal::Pose turn;
    if (j.type != J::FIXED) turn.orientation = ZTo(axis);
    c.frame_a = turn;
    c.frame_b = origin * turn;
    switch (j.type) {
      case J::REVOLUTE:
      case J::CONTINUOUS:
        c.kind = sgal::ConstraintKind::kHinge;
        break;
      case J::PRISMATIC:
        c.kind = sgal::ConstraintKind::kSlider;
        break;
      case J::PLANAR:
        // free in the plane normal to the axis (x, y and the turn about z of the joint frame)
        c.kind = sgal::ConstraintKind::kGeneric6Dof;
        for (int i : {2, 3, 4}) c.limits[i].lower = c.limits[i].upper = 0;
        break;
      default:
        c.kind = sgal::ConstraintKind::kFixed;
        break;
    }
    if ((j.type == J::REVOLUTE || j.type == J::PRISMATIC) && j.limits) {
      if (!(j.limits->lower <= j.limits->upper))
        Fail(WhereJoint(j.name), "limit lower " + Number(j.limits->lower) + " is above upper " +
                                     Number(j.limits->upper));
      c.limits[0].lower = j.limits->lower;
      c.limits[0].upper = j.limits->upper;
      if (j.limits->lower == 0 && j.limits->upper == 0)
        Warn(WhereJoint(j.name),
             "<limit> with lower = upper = 0 (what URDF reads when both are "
             "left out) locks the joint");
      if (!(j.limits->lower <= 0 && 0 <= j.limits->upper))
        Warn(WhereJoint(j.name), "the link's frame is at joint position 0, outside the limits " +
                                     Number(j.limits->lower) + " .. " + Number(j.limits->upper) +
                                     (j.type == J::REVOLUTE ? " rad" : " m") +
                                     ": the limit pushes it in when the simulation starts");
    }
    if (j.dynamics && c.kind != sgal::ConstraintKind::kFixed) {
      const int dof = c.kind == sgal::ConstraintKind::kGeneric6Dof ? 5 : 0;
      if (!(j.dynamics->damping >= 0) || !(j.dynamics->friction >= 0))
        Fail(WhereJoint(j.name), "<dynamics> damping and friction must be numbers >= 0");
      c.springs[dof].damping = j.dynamics->damping;
      c.friction[dof] = j.dynamics->friction;
    }
    c.collide_connected = false;
    scene_.constraints.push_back(std::move(c));
  }

  void AddMimic(const ::urdf::Joint& j) {
    if (!j.mimic) return;
    const auto leader = model_->getJoint(j.mimic->joint_name);
    if (!leader)
      Fail(WhereJoint(j.name), "mimics joint '" + j.mimic->joint_name + "', which is not defined");
    auto moving = [](const ::urdf::Joint& k) {
      return k.type == ::urdf::Joint::REVOLUTE || k.type == ::urdf::Joint::CONTINUOUS ||
             k.type == ::urdf::Joint::PRISMATIC;
    };
    if (!moving(j) || !moving(*leader))
      Fail(WhereJoint(j.name), "a mimic between '" + leader->name + "' and '" + j.name +
                                   "': only revolute, continuous and prismatic joints couple");
    sgal::Coupling c;
    c.leader = leader->name;
    c.follower = j.name;
    c.ratio = j.mimic->multiplier;
    c.offset = j.mimic->offset;
    // a chain of mimics must end at a joint that mimics none
    std::vector<std::string> chain{j.name};
    for (auto k = leader; k; k = k->mimic ? model_->getJoint(k->mimic->joint_name) : nullptr) {
      if (std::find(chain.begin(), chain.end(), k->name) != chain.end()) {
        std::string cycle;
        for (const auto& n : chain) cycle += n + " (line " + std::to_string(JointLine(n)) + ") -> ";
        Fail(WhereJoint(j.name), "the mimics form a cycle: " + cycle + k->name);
      }
      chain.push_back(k->name);
      if (chain.size() > model_->joints_.size() + 1) break;
    }
    scene_.couplings.push_back(c);
  }

  // ---- Caliper's data: in the URDF, then in the side file

  void ReadCaliperData() {
    collada::ImportTechniqueXml(path_, "caliper", &scene_, warnings_);
    const fs::path side = SidePath();
    std::error_code ec;
    if (fs::is_regular_file(side, ec)) {
      if (collada::ImportTechniqueXml(side.string(), "caliper", &scene_, warnings_) == 0)
        Fail(side.string(), "its root element is not <caliper>");
    }
  }

  // ---- fixed joints merged into the parent

  void MergeFixedJoints() {
    // top-down, so that a link merged into one merged itself lands in the body that stays
    std::map<std::string, std::pair<std::string, sgal::Pose>> into;  // link -> body, frame in it
    std::vector<std::shared_ptr<const ::urdf::Link>> order{model_->getRoot()};
    for (size_t i = 0; i < order.size(); ++i)
      for (const auto& child : order[i]->child_links) order.push_back(child);
    for (const auto& link : order) {
      const auto joint = link->parent_joint;
      if (!joint || joint->type != ::urdf::Joint::FIXED || IsWorld(joint->parent_link_name))
        continue;
      std::string target = joint->parent_link_name;
      sgal::Pose frame = ToPose(joint->parent_to_joint_origin_transform);
      if (const auto it = into.find(target); it != into.end()) {
        frame = it->second.second * frame;
        target = it->second.first;
      }
      into[link->name] = {target, frame};
      MergeBody(link->name, target, frame);
    }
    merged_into_ = into;
  }

  void MergeBody(const std::string& from, const std::string& to, const sgal::Pose& frame) {
    const int fi = scene_.BodyIndex(from);
    const int ti = scene_.BodyIndex(to);
    sgal::Body moved = scene_.bodies[fi];
    sgal::Body& target = scene_.bodies[ti];
    for (auto s : moved.shapes) {
      s.pose = frame * s.pose;
      target.shapes.push_back(std::move(s));
    }
    for (auto v : moved.visuals) {
      v.pose = frame * v.pose;
      target.visuals.push_back(std::move(v));
    }
    MassProperties m = mass_[from];
    const Eigen::Matrix3d r = frame.orientation.toRotationMatrix();
    m.com = frame.Apply(m.com);
    m.tensor = r * m.tensor * r.transpose();
    mass_[to] = Combine(mass_[to], m);
    if (has_inertial_.count(from) > 0) has_inertial_.insert(to);
    for (auto& c : scene_.constraints) {
      if (c.body_a == from) {
        c.body_a = to;
        c.frame_a = frame * c.frame_a;
      }
      if (c.body_b == from) {
        c.body_b = to;
        c.frame_b = frame * c.frame_b;
      }
    }
    // wrap side points are in the obstacle's body frame: they move with the obstacle
    std::set<std::string> moving_obstacles;
    for (auto& o : scene_.obstacles)
      if (o.body == from) {
        moving_obstacles.insert(o.name);
        o.body = to;
        o.pose = frame * o.pose;
      }
    for (auto& t : scene_.tendons)
      for (auto& p : t.path) {
        if (p.kind == sgal::PathElement::Kind::kPoint && p.body == from) {
          p.body = to;
          p.position = frame.Apply(p.position);
        } else if (p.kind == sgal::PathElement::Kind::kWrap && p.side &&
                   moving_obstacles.count(p.obstacle) > 0) {
          p.side = frame.Apply(*p.side);
        }
      }
    scene_.bodies.erase(scene_.bodies.begin() + fi);
  }

  // ---- masses

  void FinishMasses() {
    for (auto& body : scene_.bodies) {
      MassProperties& m = mass_[body.name];
      const bool moving = body.type == sgal::BodyType::kDynamic;
      if (moving && has_inertial_.count(body.name) == 0) {
        Warn(WhereLink(body.name), "no <inertial> on a moving link; " + Number(kDefaultMass) +
                                       " kg assumed, as a solid sphere of radius " +
                                       Number(kDefaultRadius) + " m about the link's origin");
        m = DefaultMass();
      } else if (moving && !(m.mass > 0)) {
        const auto joint = model_->getLink(body.name)->parent_joint;
        if (joint && joint->type == ::urdf::Joint::FIXED) {
          // kept fixed joints (fixed_joints="keep"): a massless frame such as a tool flange
          Warn(WhereLink(body.name), "mass 0 kg on a link held by the fixed joint '" + joint->name +
                                         "', which is kept as a constraint; " +
                                         Number(kDefaultMass) + " kg assumed");
          m = DefaultMass();
        } else {
          Fail(WhereLink(body.name),
               "mass " + Number(m.mass) + " kg on a moving link (" +
                   (joint ? "its joint '" + joint->name + "' is not fixed"
                          : std::string("the root, free with a floating base")) +
                   "): a body that moves needs a positive mass");
        }
      }
      body.inertia.mass = m.mass;
      body.inertia.com = m.com;
      body.inertia.tensor = m.mass > 0 ? m.tensor : Eigen::Matrix3d::Zero();
      if (!moving && !(m.mass > 0)) {
        // a static body's mass is never used; sgal wants a positive one all the same
        body.inertia.mass = 0;
      }
    }
  }

  void CheckScene() {
    const auto problems = sgal::Validate(scene_);
    if (problems.empty()) return;
    std::string message;
    for (const auto& p : problems) {
      // a finding starts "body 'NAME'" or "constraint 'NAME'": the link's or the joint's line
      int line = 0;
      for (const std::string prefix : {"body '", "constraint '", "coupling of '"}) {
        if (p.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string name =
            p.substr(prefix.size(), p.find('\'', prefix.size()) - prefix.size());
        if (prefix[0] == 'b' && facts_.link_lines.count(name) > 0)
          line = facts_.link_lines.at(name);
        if (prefix[0] == 'c') line = JointLine(name);
      }
      message += (message.empty() ? "" : "\n") + At(line) + ": " + p;
    }
    throw ImportError(message);
  }

  std::string path_;
  std::vector<std::string>* warnings_;
  Options options_;
  XmlFacts facts_;
  std::shared_ptr<::urdf::ModelInterface> model_;
  bool world_is_link_ = false;
  sgal::Scene scene_;
  std::map<std::string, sgal::Pose> link_pose_;
  std::map<std::string, MassProperties> mass_;
  std::set<std::string> has_inertial_;
  std::map<std::string, std::pair<std::string, sgal::Pose>> merged_into_;
  internal::MeshLoader meshes_;
  internal::PackageFinder packages_;
};

}  // namespace

sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings,
                   const Options& options) {
  Importer importer(path, warnings, options);
  try {
    return importer.Run();
  } catch (const ImportError&) {
    throw;
  } catch (const collada::ImportError& e) {
    throw ImportError(e.what());
  } catch (const std::exception& e) {
    throw ImportError(path + ": " + e.what());
  }
}

}  // namespace caliper::urdf
