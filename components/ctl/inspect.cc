#include "inspect.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "caliper/actuators/actuator.h"
#include "caliper/model_file/model_file.h"

namespace caliper::ctl {

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180;
constexpr int kNameWidth = 24;
constexpr size_t kLineWidth = 100;

std::string Num(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

std::string Vec(const Eigen::Vector3d& v) {
  return "(" + Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z()) + ")";
}

const char* TypeName(sgal::BodyType t) {
  switch (t) {
    case sgal::BodyType::kDynamic:
      return "dynamic";
    case sgal::BodyType::kStatic:
      return "static";
    case sgal::BodyType::kKinematic:
      return "kinematic";
  }
  return "?";
}

const char* KindName(sgal::ConstraintKind k) {
  switch (k) {
    case sgal::ConstraintKind::kHinge:
      return "hinge";
    case sgal::ConstraintKind::kSlider:
      return "slider";
    case sgal::ConstraintKind::kBall:
      return "ball";
    case sgal::ConstraintKind::kFixed:
      return "fixed";
    case sgal::ConstraintKind::kGeneric6Dof:
      return "generic_6dof";
  }
  return "?";
}

std::string BodyName(const std::string& name) { return name.empty() ? "world" : name; }

// `  name   text`, the text wrapped at kLineWidth on "; " and ", " boundaries
void Item(std::ostream& out, const std::string& name, const std::vector<std::string>& parts,
          const std::string& separator = ", ") {
  std::ostringstream head;
  head << "  " << std::left << std::setw(kNameWidth - 3) << name << " ";
  std::string line = head.str();
  const std::string indent(kNameWidth, ' ');
  // a comma ends a broken line; other separators (" > ") start the next one
  const bool comma = separator == ", ";
  bool first = true;
  for (const std::string& part : parts) {
    const std::string piece = (first ? "" : separator) + part;
    if (!first && line.size() + piece.size() > kLineWidth) {
      out << line << (comma ? "," : "") << "\n";
      line = indent + (comma ? "" : separator.substr(1)) + part;
    } else {
      line += piece;
    }
    first = false;
  }
  out << line << "\n";
}

// one degree of freedom's limit and spring: "-10 .. 25 deg", "free"; spring if any
void DofParts(const sgal::Constraint& c, int i, bool angular, const std::string& label,
              std::vector<std::string>* parts) {
  const double scale = angular ? 1 / kDegree : 1.0;
  const char* unit = angular ? "deg" : "m";
  const sgal::Limit& l = c.limits[i];
  std::string limit = label.empty() ? "limits " : label + " ";
  if (!l.enabled())
    limit += "free";
  else if (l.lower == l.upper)
    limit += "locked at " + Num(l.lower * scale) + " " + unit;
  else
    limit += Num(l.lower * scale) + " .. " + Num(l.upper * scale) + " " + unit;
  parts->push_back(limit);
  const sgal::JointSpring& s = c.springs[i];
  if (s.stiffness != 0)
    parts->push_back("spring " + Num(s.stiffness) + (angular ? " N m/rad" : " N/m") + " rest " +
                     Num(s.rest * scale) + " " + unit);
  if (s.damping != 0)
    parts->push_back("damping " + Num(s.damping) + (angular ? " N m s/rad" : " N s/m"));
  if (c.friction[i] != 0)
    parts->push_back("friction " + Num(c.friction[i]) + (angular ? " N m" : " N"));
}

void PrintBodies(const sgal::Scene& scene, std::ostream& out) {
  std::map<std::string, int> types;
  for (const auto& b : scene.bodies) ++types[TypeName(b.type)];
  out << "bodies (" << scene.bodies.size();
  std::string sep = ": ";
  for (const auto& [type, n] : types) {
    out << sep << n << " " << type;
    sep = ", ";
  }
  out << ")\n";
  for (const auto& b : scene.bodies) {
    std::vector<std::string> parts = {TypeName(b.type)};
    if (b.type == sgal::BodyType::kDynamic) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(b.inertia.tensor);
      const Eigen::Vector3d m = eig.eigenvalues();
      parts.push_back(Num(b.inertia.mass) + " kg");
      parts.push_back("principal moments " + Num(m.x()) + " " + Num(m.y()) + " " + Num(m.z()) +
                      " kg m^2");
      parts.push_back("centre of mass " + Vec(b.inertia.com) + " m");
    }
    parts.push_back("at " + Vec(b.pose.position) + " m");
    std::string shapes = b.shapes.empty() ? "no shapes" : "shapes";
    for (size_t i = 0; i < b.shapes.size(); ++i)
      shapes += std::string(i == 0 ? " " : ", ") + sgal::GeometryName(b.shapes[i].geometry);
    parts.push_back(shapes);
    parts.push_back(std::to_string(b.visuals.size()) + " visual" +
                    (b.visuals.size() == 1 ? "" : "s"));
    Item(out, b.name, parts);
  }
}

void PrintConstraints(const sgal::Scene& scene, std::ostream& out) {
  out << "constraints (" << scene.constraints.size() << ")\n";
  static const char* const kDofs[6] = {"x", "y", "z", "rx", "ry", "rz"};
  for (const auto& c : scene.constraints) {
    std::vector<std::string> parts = {std::string(KindName(c.kind)) + " " + BodyName(c.body_a) +
                                      " to " + BodyName(c.body_b)};
    switch (c.kind) {
      case sgal::ConstraintKind::kHinge:
      case sgal::ConstraintKind::kSlider: {
        // the joint turns about (slides along) frame_b's z axis; the world direction is the one
        // at the description pose (a body_b of "" is the world itself)
        // rounding leftovers of a quarter turn (2e-16) shown as 0
        auto clean = [](Eigen::Vector3d v) {
          for (int i = 0; i < 3; ++i)
            if (std::abs(v[i]) < 1e-12) v[i] = 0;
          return v;
        };
        const Eigen::Vector3d raw = c.frame_b.orientation * Eigen::Vector3d::UnitZ();
        const sgal::Body* b = c.body_b.empty() ? nullptr : scene.FindBody(c.body_b);
        const Eigen::Vector3d world = clean(b ? Eigen::Vector3d(b->pose.orientation * raw) : raw);
        const Eigen::Vector3d local = clean(raw);
        parts.push_back("axis " + Vec(local) + " in " + BodyName(c.body_b) + ", " + Vec(world) +
                        " in world");
        DofParts(c, 0, c.kind == sgal::ConstraintKind::kHinge, "", &parts);
        break;
      }
      case sgal::ConstraintKind::kGeneric6Dof:
        for (int i = 0; i < 6; ++i) DofParts(c, i, i >= 3, kDofs[i], &parts);
        break;
      case sgal::ConstraintKind::kBall:
      case sgal::ConstraintKind::kFixed:
        break;
    }
    Item(out, c.name, parts);
  }
  out << "couplings (" << scene.couplings.size() << ")\n";
  for (const auto& c : scene.couplings)
    Item(out, c.follower, {"= " + Num(c.ratio) + " * " + c.leader + " + " + Num(c.offset)});
}

void PrintTendons(const sgal::Scene& scene, std::ostream& out) {
  out << "obstacles (" << scene.obstacles.size() << ")\n";
  for (const auto& o : scene.obstacles) {
    std::vector<std::string> parts;
    if (o.kind == sgal::ObstacleKind::kCylinder)
      parts = {"cylinder on " + BodyName(o.body), "radius " + Num(o.radius) + " m",
               "length " + Num(o.length) + " m"};
    else
      parts = {"sphere on " + BodyName(o.body), "radius " + Num(o.radius) + " m"};
    parts.push_back("at " + Vec(o.pose.position) + " m");
    Item(out, o.name, parts);
  }
  out << "tendons (" << scene.tendons.size() << "; path points in their bodies' frames [m])\n";
  for (const auto& t : scene.tendons) {
    std::vector<std::string> path;
    for (const auto& e : t.path) {
      if (e.kind == sgal::PathElement::Kind::kWrap) {
        path.push_back("wrap " + e.obstacle);
      } else {
        std::string p = BodyName(e.body) + " " + Vec(e.position);
        if (e.friction != 0) p += " friction " + Num(e.friction);
        path.push_back(p);
      }
    }
    path.front() = "radius " + Num(t.radius) + " m" +
                   (t.collide_with_bodies ? "" : ", passes through bodies") + ": " + path.front();
    Item(out, t.name, path, " > ");
  }
}

void PrintActuators(const sgal::Scene& scene, std::ostream& out) {
  std::map<std::string, int> kinds;
  for (const auto& a : scene.actuators) ++kinds[a.kind];
  out << "actuators (" << scene.actuators.size();
  std::string sep = ": ";
  for (const auto& [kind, n] : kinds) {
    out << sep << n << " " << kind;
    sep = ", ";
  }
  out << ")\n";
  for (const auto& a : scene.actuators) {
    std::map<std::string, std::string> units;
    try {
      for (const auto& spec : actuators::KindParameters(a.kind)) units[spec.name] = spec.unit;
    } catch (const std::exception&) {
      // an unregistered kind: the parameters are printed without units
    }
    std::vector<std::string> parts = {a.kind + " on " + a.tendon};
    for (const auto& [name, value] : a.parameters) {
      const auto unit = units.find(name);
      const bool has_unit = unit != units.end() && !unit->second.empty();
      parts.push_back(name + " " + Num(value) + (has_unit ? " " + unit->second : ""));
    }
    for (const auto& [name, value] : a.options) parts.push_back(name + " = " + value);
    Item(out, a.name, parts);
  }
}

}  // namespace

void PrintSceneReport(const std::string& path, const sgal::Scene& scene,
                      const collada::FileInfo& info, const std::vector<std::string>& warnings,
                      std::ostream& out) {
  const int w = kNameWidth;
  out << std::left << std::setw(w) << "file" << path << "\n";
  if (model_file::FormatOf(path) == model_file::Format::kUrdf) {
    out << std::setw(w) << "format" << "URDF (joints at 0; fixed joints merged into the parent)\n";
    out << std::setw(w) << "units" << "SI (m, kg, s, N) as URDF has them, angles shown in deg, Z up\n";
  } else {
    out << std::setw(w) << "format"
        << "COLLADA " << (info.version.empty() ? "?" : info.version)
        << (info.zipped ? " (.zae archive)" : "")
        << (info.authoring_tool.empty() ? "" : ", written by " + info.authoring_tool) << "\n";
    out << std::setw(w) << "units"
        << "<unit meter=\"" << Num(info.meter) << "\""
        << (info.unit_name.empty() ? "" : " name=\"" + info.unit_name + "\"") << ">, "
        << info.up_axis << "; shown in SI (m, kg, s, N), angles in deg, Z up\n";
  }
  out << std::setw(w) << "scene" << scene.name << "\n";
  out << std::setw(w) << "gravity" << Vec(scene.gravity) << " m/s^2\n";
  out << std::setw(w) << "settings"
      << "time step " << Num(scene.settings.time_step) << " s, " << scene.settings.solver_iterations
      << " solver iterations, world scale " << Num(scene.settings.world_scale)
      << " (engine units per m)\n";
  out << "materials (" << scene.materials.size() << ")\n";
  for (const auto& m : scene.materials)
    Item(out, m.name, {"friction " + Num(m.friction), "restitution " + Num(m.restitution)});
  PrintBodies(scene, out);
  PrintConstraints(scene, out);
  PrintTendons(scene, out);
  PrintActuators(scene, out);
  out << "warnings (" << warnings.size() << ")\n";
  for (const auto& warning : warnings) out << "  " << warning << "\n";
}

}  // namespace caliper::ctl
