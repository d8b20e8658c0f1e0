#include "caliper/sgal/scene.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace caliper::sgal {

Eigen::Isometry3d Pose::ToIsometry() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = orientation.normalized().toRotationMatrix();
  t.translation() = position;
  return t;
}

Pose Pose::FromIsometry(const Eigen::Isometry3d& t) {
  Pose p;
  p.position = t.translation();
  p.orientation = Eigen::Quaterniond(t.rotation()).normalized();
  return p;
}

Pose Pose::operator*(const Pose& other) const {
  Pose p;
  p.position = position + orientation * other.position;
  p.orientation = (orientation * other.orientation).normalized();
  return p;
}

Pose Pose::Inverse() const {
  Pose p;
  p.orientation = orientation.conjugate();
  p.position = -(p.orientation * position);
  return p;
}

const char* GeometryName(const Geometry& g) {
  static const char* const kNames[] = {"box",   "sphere", "capsule",     "cylinder",
                                       "cone",  "plane",  "convex_hull", "triangle_mesh"};
  return kNames[g.index()];
}

double BoundingRadius(const Geometry& geometry) {
  return std::visit(
      [](const auto& g) -> double {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, Box>) {
          return g.size.norm() / 2;
        } else if constexpr (std::is_same_v<T, Sphere>) {
          return g.radius;
        } else if constexpr (std::is_same_v<T, Capsule>) {
          return g.radius + g.length / 2;
        } else if constexpr (std::is_same_v<T, Cylinder> || std::is_same_v<T, Cone>) {
          return std::hypot(g.radius, g.length / 2);
        } else if constexpr (std::is_same_v<T, Plane>) {
          return std::numeric_limits<double>::infinity();
        } else {
          double farthest = 0;
          if (g.mesh)
            for (const auto& v : g.mesh->vertices)
              farthest = std::max(farthest, static_cast<double>(v.norm()));
          return farthest;
        }
      },
      geometry);
}

const Body* Scene::FindBody(const std::string& n) const {
  for (const auto& b : bodies)
    if (b.name == n) return &b;
  return nullptr;
}

const Tendon* Scene::FindTendon(const std::string& n) const {
  for (const auto& t : tendons)
    if (t.name == n) return &t;
  return nullptr;
}

const WrapObstacle* Scene::FindObstacle(const std::string& n) const {
  for (const auto& o : obstacles)
    if (o.name == n) return &o;
  return nullptr;
}

int Scene::BodyIndex(const std::string& n) const {
  for (size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i].name == n) return static_cast<int>(i);
  return -1;
}

namespace {

bool Finite(const Pose& p) { return p.position.allFinite() && p.orientation.coeffs().allFinite(); }

}  // namespace

std::vector<std::string> Validate(const Scene& s) {
  std::vector<std::string> errors;
  auto error = [&](const std::string& m) { errors.push_back(m); };
  std::set<std::string> names;
  for (const auto& b : s.bodies) {
    const std::string where = "body '" + b.name + "'";
    if (!names.insert(b.name).second) error(where + ": defined twice");
    if (!Finite(b.pose)) error(where + ": pose is not finite");
    if (b.type == BodyType::kDynamic) {
      if (!(b.inertia.mass > 0) || !std::isfinite(b.inertia.mass))
        error(where + ": mass " + std::to_string(b.inertia.mass) +
              " kg; a dynamic body needs a positive mass");
      const Eigen::Matrix3d& I = b.inertia.tensor;
      if (!I.allFinite() || (I - I.transpose()).norm() > 1e-9 * (1 + I.norm())) {
        error(where + ": inertia tensor is not symmetric");
      } else {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
        const Eigen::Vector3d e = eig.eigenvalues();
        if (!(e.minCoeff() > 0)) {
          error(where + ": inertia tensor is not positive definite (eigenvalues " +
                std::to_string(e[0]) + ", " + std::to_string(e[1]) + ", " + std::to_string(e[2]) +
                " kg m^2)");
        } else if (e[0] + e[1] < e[2] * (1 - 1e-6)) {
          error(where + ": principal moments violate the triangle inequality");
        }
      }
    }
  }
  auto body_exists = [&](const std::string& n) { return n.empty() || s.FindBody(n) != nullptr; };
  for (const auto& c : s.constraints) {
    const std::string where = "constraint '" + c.name + "'";
    if (c.body_a.empty() || !s.FindBody(c.body_a)) error(where + ": no body '" + c.body_a + "'");
    if (!body_exists(c.body_b)) error(where + ": no body '" + c.body_b + "'");
    for (size_t i = 0; i < c.friction.size(); ++i)
      if (!(c.friction[i] >= 0) || !std::isfinite(c.friction[i]))
        error(where + ": friction[" + std::to_string(i) + "] = " + std::to_string(c.friction[i]) +
              " (N or N m) must be finite and not negative");
  }
  std::set<std::string> followers;
  for (const auto& k : s.couplings) {
    const std::string where = "coupling of '" + k.follower + "' to '" + k.leader + "'";
    for (const std::string* joint : {&k.leader, &k.follower}) {
      const auto c = std::find_if(s.constraints.begin(), s.constraints.end(),
                                  [&](const Constraint& x) { return x.name == *joint; });
      if (c == s.constraints.end())
        error(where + ": no constraint (joint) '" + *joint + "'");
      else if (c->kind != ConstraintKind::kHinge && c->kind != ConstraintKind::kSlider)
        error(where + ": constraint '" + *joint + "' is not a hinge or slider");
    }
    if (k.leader == k.follower) error(where + ": a joint cannot follow itself");
    if (!std::isfinite(k.ratio) || !std::isfinite(k.offset))
      error(where + ": ratio and offset must be finite");
    if (!followers.insert(k.follower).second)
      error(where + ": joint '" + k.follower + "' already follows another coupling");
  }
  for (const auto& o : s.obstacles) {
    if (!body_exists(o.body))
      error("obstacle '" + o.name + "': no body '" + o.body + "'");
    if (!(o.radius > 0)) error("obstacle '" + o.name + "': radius must be positive");
  }
  for (const auto& t : s.tendons) {
    const std::string where = "tendon '" + t.name + "'";
    int points = 0;
    for (size_t i = 0; i < t.path.size(); ++i) {
      const auto& e = t.path[i];
      if (e.kind == PathElement::Kind::kPoint) {
        ++points;
        if (!body_exists(e.body)) error(where + ": point " + std::to_string(i) + " on unknown body '" + e.body + "'");
        if (!e.position.allFinite()) error(where + ": point " + std::to_string(i) + " is not finite");
      } else {
        if (!s.FindObstacle(e.obstacle))
          error(where + ": unknown wrap obstacle '" + e.obstacle + "'");
        if (i == 0 || i + 1 == t.path.size() ||
            t.path[i - 1].kind != PathElement::Kind::kPoint ||
            t.path[i + 1].kind != PathElement::Kind::kPoint)
          error(where + ": wrap '" + e.obstacle + "' must stand between two points");
      }
    }
    if (points < 2) error(where + ": needs at least two points, has " + std::to_string(points));
  }
  for (const auto& a : s.actuators) {
    if (a.kind.empty()) error("actuator '" + a.name + "': no kind");
    if (!s.FindTendon(a.tendon))
      error("actuator '" + a.name + "': no tendon '" + a.tendon + "'");
    for (const auto& [k, v] : a.parameters)
      if (!std::isfinite(v)) error("actuator '" + a.name + "': parameter " + k + " is not finite");
  }
  if (!(s.settings.time_step > 0)) error("time step must be positive");
  if (!(s.settings.world_scale > 0)) error("world scale must be positive");
  return errors;
}

}  // namespace caliper::sgal
