#pragma once
// Compares two scene descriptions field by field within a tolerance and reports every
// difference as a test failure naming the element: what a round trip through a file must keep.

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "caliper/sgal/scene.h"

namespace caliper::testing {

class SceneComparison {
 public:
  /// `tolerance` is relative to the magnitude of each value (absolute below 1).
  explicit SceneComparison(double tolerance = 1e-9) : tolerance_(tolerance) {}

  /// Adds a failure for each difference; returns the number found.
  int Compare(const sgal::Scene& a, const sgal::Scene& b) {
    Vec("gravity", a.gravity, b.gravity);
    Num("settings.time_step", a.settings.time_step, b.settings.time_step);
    Eq("settings.solver_iterations", a.settings.solver_iterations, b.settings.solver_iterations);
    Num("settings.world_scale", a.settings.world_scale, b.settings.world_scale);
    if (Eq("material count", a.materials.size(), b.materials.size()))
      for (size_t i = 0; i < a.materials.size(); ++i) {
        const std::string w = "material '" + a.materials[i].name + "'";
        Eq(w + " name", a.materials[i].name, b.materials[i].name);
        Num(w + " friction", a.materials[i].friction, b.materials[i].friction);
        Num(w + " restitution", a.materials[i].restitution, b.materials[i].restitution);
      }
    if (Eq("body count", a.bodies.size(), b.bodies.size()))
      for (size_t i = 0; i < a.bodies.size(); ++i) CompareBody(a.bodies[i], b.bodies[i]);
    if (Eq("constraint count", a.constraints.size(), b.constraints.size()))
      for (size_t i = 0; i < a.constraints.size(); ++i)
        CompareConstraint(a.constraints[i], b.constraints[i]);
    if (Eq("coupling count", a.couplings.size(), b.couplings.size()))
      for (size_t i = 0; i < a.couplings.size(); ++i) {
        const auto &x = a.couplings[i], &y = b.couplings[i];
        const std::string w = "coupling of '" + x.follower + "'";
        Eq(w + " leader", x.leader, y.leader);
        Eq(w + " follower", x.follower, y.follower);
        Num(w + " ratio", x.ratio, y.ratio);
        Num(w + " offset", x.offset, y.offset);
      }
    if (Eq("obstacle count", a.obstacles.size(), b.obstacles.size()))
      for (size_t i = 0; i < a.obstacles.size(); ++i) {
        const auto &x = a.obstacles[i], &y = b.obstacles[i];
        const std::string w = "obstacle '" + x.name + "'";
        Eq(w + " name", x.name, y.name);
        Eq(w + " body", x.body, y.body);
        Eq(w + " kind", static_cast<int>(x.kind), static_cast<int>(y.kind));
        PoseEq(w + " pose", x.pose, y.pose);
        Num(w + " radius", x.radius, y.radius);
        Num(w + " length", x.length, y.length);
      }
    if (Eq("tendon count", a.tendons.size(), b.tendons.size()))
      for (size_t i = 0; i < a.tendons.size(); ++i) CompareTendon(a.tendons[i], b.tendons[i]);
    if (Eq("actuator count", a.actuators.size(), b.actuators.size()))
      for (size_t i = 0; i < a.actuators.size(); ++i) {
        const auto &x = a.actuators[i], &y = b.actuators[i];
        const std::string w = "actuator '" + x.name + "'";
        Eq(w + " name", x.name, y.name);
        Eq(w + " kind", x.kind, y.kind);
        Eq(w + " tendon", x.tendon, y.tendon);
        if (Eq(w + " parameter count", x.parameters.size(), y.parameters.size()))
          for (const auto& [k, v] : x.parameters) {
            const auto it = y.parameters.find(k);
            if (it == y.parameters.end())
              Fail(w + " lost parameter " + k);
            else
              Num(w + " parameter " + k, v, it->second);
          }
        Eq(w + " options", x.options, y.options);
      }
    if (Eq("measurement delay count", a.measurement_delays.size(), b.measurement_delays.size()))
      for (size_t i = 0; i < a.measurement_delays.size(); ++i) {
        const auto &x = a.measurement_delays[i], &y = b.measurement_delays[i];
        const std::string w = "measurement delay of '" + x.id + "'";
        Eq(w + " channel", x.id, y.id);
        Num(w + " delay", x.delay, y.delay);
      }
    return failures_;
  }

 private:
  void CompareBody(const sgal::Body& x, const sgal::Body& y) {
    const std::string w = "body '" + x.name + "'";
    Eq(w + " name", x.name, y.name);
    Eq(w + " type", static_cast<int>(x.type), static_cast<int>(y.type));
    PoseEq(w + " pose", x.pose, y.pose);
    Num(w + " mass", x.inertia.mass, y.inertia.mass);
    Vec(w + " centre of mass", x.inertia.com, y.inertia.com);
    Mat(w + " inertia", x.inertia.tensor, y.inertia.tensor);
    Vec(w + " linear velocity", x.linear_velocity, y.linear_velocity);
    Vec(w + " angular velocity", x.angular_velocity, y.angular_velocity);
    if (Eq(w + " shape count", x.shapes.size(), y.shapes.size()))
      for (size_t i = 0; i < x.shapes.size(); ++i) {
        const auto &s = x.shapes[i], &t = y.shapes[i];
        const std::string ws = w + " shape " + std::to_string(i);
        PoseEq(ws + " pose", s.pose, t.pose);
        Eq(ws + " material", s.material, t.material);
        Eq(ws + " group", s.group, t.group);
        Eq(ws + " mask", s.mask, t.mask);
        GeometryEq(ws, s.geometry, t.geometry);
      }
    Eq(w + " visual count", x.visuals.size(), y.visuals.size());
  }

  void CompareConstraint(const sgal::Constraint& x, const sgal::Constraint& y) {
    const std::string w = "constraint '" + x.name + "'";
    Eq(w + " name", x.name, y.name);
    Eq(w + " kind", static_cast<int>(x.kind), static_cast<int>(y.kind));
    Eq(w + " body_a", x.body_a, y.body_a);
    Eq(w + " body_b", x.body_b, y.body_b);
    PoseEq(w + " frame_a", x.frame_a, y.frame_a);
    PoseEq(w + " frame_b", x.frame_b, y.frame_b);
    Eq(w + " collide_connected", x.collide_connected, y.collide_connected);
    const bool one =
        x.kind == sgal::ConstraintKind::kHinge || x.kind == sgal::ConstraintKind::kSlider;
    const bool six = x.kind == sgal::ConstraintKind::kGeneric6Dof;
    for (int i = 0; i < (six ? 6 : one ? 1 : 0); ++i) {
      const std::string wl = w + " limit " + std::to_string(i);
      if (Eq(wl + " enabled", x.limits[i].enabled(), y.limits[i].enabled()) &&
          x.limits[i].enabled()) {
        Num(wl + " lower", x.limits[i].lower, y.limits[i].lower);
        Num(wl + " upper", x.limits[i].upper, y.limits[i].upper);
      }
      Num(wl + " spring stiffness", x.springs[i].stiffness, y.springs[i].stiffness);
      Num(wl + " spring damping", x.springs[i].damping, y.springs[i].damping);
      Num(wl + " spring rest", x.springs[i].rest, y.springs[i].rest);
      Num(wl + " friction", x.friction[i], y.friction[i]);
    }
  }

  void CompareTendon(const sgal::Tendon& x, const sgal::Tendon& y) {
    const std::string w = "tendon '" + x.name + "'";
    Eq(w + " name", x.name, y.name);
    Num(w + " radius", x.radius, y.radius);
    Eq(w + " collide_with_bodies", x.collide_with_bodies, y.collide_with_bodies);
    if (!Eq(w + " path length", x.path.size(), y.path.size())) return;
    for (size_t i = 0; i < x.path.size(); ++i) {
      const auto &p = x.path[i], &q = y.path[i];
      const std::string wp = w + " element " + std::to_string(i);
      Eq(wp + " kind", static_cast<int>(p.kind), static_cast<int>(q.kind));
      Eq(wp + " body", p.body, q.body);
      Vec(wp + " position", p.position, q.position);
      Num(wp + " friction", p.friction, q.friction);
      Eq(wp + " obstacle", p.obstacle, q.obstacle);
      if (Eq(wp + " has side", p.side.has_value(), q.side.has_value()) && p.side)
        Vec(wp + " side", *p.side, *q.side);
    }
  }

  void GeometryEq(const std::string& w, const sgal::Geometry& g, const sgal::Geometry& h) {
    if (!Eq(w + " geometry", std::string(sgal::GeometryName(g)),
            std::string(sgal::GeometryName(h))))
      return;
    if (const auto* b = std::get_if<sgal::Box>(&g))
      Vec(w + " box size", b->size, std::get<sgal::Box>(h).size);
    if (const auto* s = std::get_if<sgal::Sphere>(&g))
      Num(w + " radius", s->radius, std::get<sgal::Sphere>(h).radius);
    if (const auto* c = std::get_if<sgal::Capsule>(&g)) {
      Num(w + " radius", c->radius, std::get<sgal::Capsule>(h).radius);
      Num(w + " length", c->length, std::get<sgal::Capsule>(h).length);
    }
    if (const auto* c = std::get_if<sgal::Cylinder>(&g)) {
      Num(w + " radius", c->radius, std::get<sgal::Cylinder>(h).radius);
      Num(w + " length", c->length, std::get<sgal::Cylinder>(h).length);
    }
    if (const auto* c = std::get_if<sgal::Cone>(&g)) {
      Num(w + " radius", c->radius, std::get<sgal::Cone>(h).radius);
      Num(w + " length", c->length, std::get<sgal::Cone>(h).length);
    }
    if (const auto* p = std::get_if<sgal::Plane>(&g)) {
      Vec(w + " normal", p->normal, std::get<sgal::Plane>(h).normal);
      Num(w + " offset", p->offset, std::get<sgal::Plane>(h).offset);
    }
    if (const auto* m = std::get_if<sgal::ConvexHull>(&g))
      MeshEq(w, m->mesh, std::get<sgal::ConvexHull>(h).mesh);
    if (const auto* m = std::get_if<sgal::TriangleMesh>(&g))
      MeshEq(w, m->mesh, std::get<sgal::TriangleMesh>(h).mesh);
  }

  void MeshEq(const std::string& w, const std::shared_ptr<const sgal::Mesh>& a,
              const std::shared_ptr<const sgal::Mesh>& b) {
    if (!Eq(w + " has mesh", a != nullptr, b != nullptr) || !a) return;
    if (!Eq(w + " vertex count", a->vertices.size(), b->vertices.size())) return;
    if (!Eq(w + " triangle count", a->triangles.size(), b->triangles.size())) return;
    for (size_t i = 0; i < a->vertices.size(); ++i)
      if (!Vec(w + " vertex " + std::to_string(i), a->vertices[i].cast<double>(),
               b->vertices[i].cast<double>(), 1e-6))
        return;
    for (size_t i = 0; i < a->triangles.size(); ++i)
      if (!Eq(w + " triangle " + std::to_string(i), a->triangles[i], b->triangles[i])) return;
  }

  bool Close(double a, double b, double tolerance) const {
    if (std::isnan(a) && std::isnan(b)) return true;
    return std::abs(a - b) <= tolerance * std::max({1.0, std::abs(a), std::abs(b)});
  }
  template <typename T>
  bool Eq(const std::string& what, const T& a, const T& b) {
    if (a == b) return true;
    Fail(what + " differs");
    return false;
  }
  bool Num(const std::string& what, double a, double b) {
    if (Close(a, b, tolerance_)) return true;
    std::ostringstream s;
    s.precision(17);
    s << what << ": " << a << " vs " << b;
    Fail(s.str());
    return false;
  }
  bool Vec(const std::string& what, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
           double tolerance = -1) {
    const double t = tolerance < 0 ? tolerance_ : tolerance;
    for (int i = 0; i < 3; ++i)
      if (!Close(a[i], b[i], t)) {
        std::ostringstream s;
        s.precision(17);
        s << what << ": (" << a.transpose() << ") vs (" << b.transpose() << ")";
        Fail(s.str());
        return false;
      }
    return true;
  }
  bool Mat(const std::string& what, const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
    const double scale = std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
    if ((a - b).cwiseAbs().maxCoeff() <= tolerance_ * std::max(scale, 1e-12)) return true;
    std::ostringstream s;
    s.precision(17);
    s << what << ":\n" << a << "\nvs\n" << b;
    Fail(s.str());
    return false;
  }
  bool PoseEq(const std::string& what, const sgal::Pose& a, const sgal::Pose& b) {
    const bool ok = Vec(what + " position", a.position, b.position);
    const double angle = a.orientation.normalized().angularDistance(b.orientation.normalized());
    if (angle > tolerance_ * 10) {
      Fail(what + " orientation differs by " + std::to_string(angle) + " rad");
      return false;
    }
    return ok;
  }
  void Fail(const std::string& what) {
    ++failures_;
    if (failures_ <= 20) ADD_FAILURE() << what;
  }

  double tolerance_;
  int failures_ = 0;
};

}  // namespace caliper::testing
