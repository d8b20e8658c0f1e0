#include "mesh_util.h"

#include <cmath>

namespace caliper::collada::internal {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSegments = 24;

using Vertex = Eigen::Vector3f;

void AddQuad(sgal::Mesh* m, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  m->triangles.push_back({a, b, c});
  m->triangles.push_back({a, c, d});
}

std::shared_ptr<sgal::Mesh> BoxMesh(const Eigen::Vector3d& size) {
  auto m = std::make_shared<sgal::Mesh>();
  const Eigen::Vector3f h = (size / 2).cast<float>();
  for (int i = 0; i < 8; ++i)
    m->vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                             (i & 4) ? h.z() : -h.z());
  AddQuad(m.get(), 0, 2, 3, 1);  // -z
  AddQuad(m.get(), 4, 5, 7, 6);  // +z
  AddQuad(m.get(), 0, 1, 5, 4);  // -y
  AddQuad(m.get(), 2, 6, 7, 3);  // +y
  AddQuad(m.get(), 0, 4, 6, 2);  // -x
  AddQuad(m.get(), 1, 3, 7, 5);  // +x
  return m;
}

// A surface of revolution about z through rings (radius, z); closed by poles at the ends when
// the first or last radius is zero, by caps otherwise.
std::shared_ptr<sgal::Mesh> Revolve(const std::vector<std::pair<double, double>>& rings) {
  auto m = std::make_shared<sgal::Mesh>();
  std::vector<uint32_t> start;
  for (const auto& [r, z] : rings) {
    start.push_back(static_cast<uint32_t>(m->vertices.size()));
    const int n = r > 0 ? kSegments : 1;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * kPi * i / kSegments;
      m->vertices.emplace_back(static_cast<float>(r * std::cos(a)),
                               static_cast<float>(r * std::sin(a)), static_cast<float>(z));
    }
  }
  auto ring_size = [&](size_t k) { return rings[k].first > 0 ? kSegments : 1; };
  for (size_t k = 0; k + 1 < rings.size(); ++k) {
    const uint32_t a = start[k], b = start[k + 1];
    for (uint32_t i = 0; i < kSegments; ++i) {
      const uint32_t j = (i + 1) % kSegments;
      const bool pole_a = ring_size(k) == 1, pole_b = ring_size(k + 1) == 1;
      if (pole_a && pole_b) continue;
      if (pole_a) {
        m->triangles.push_back({a, b + j, b + i});
      } else if (pole_b) {
        m->triangles.push_back({a + i, a + j, b});
      } else {
        AddQuad(m.get(), a + i, a + j, b + j, b + i);
      }
    }
  }
  // caps for open ends
  auto cap = [&](size_t k, bool bottom) {
    if (ring_size(k) == 1) return;
    const uint32_t centre = static_cast<uint32_t>(m->vertices.size());
    m->vertices.emplace_back(0.f, 0.f, static_cast<float>(rings[k].second));
    for (uint32_t i = 0; i < kSegments; ++i) {
      const uint32_t j = (i + 1) % kSegments;
      if (bottom)
        m->triangles.push_back({centre, start[k] + j, start[k] + i});
      else
        m->triangles.push_back({centre, start[k] + i, start[k] + j});
    }
  };
  cap(0, true);
  cap(rings.size() - 1, false);
  return m;
}

// A sphere (half_length 0) or a capsule along z: two hemispheres apart by 2 half_length.
std::shared_ptr<sgal::Mesh> SphereRings(double radius, double half_length) {
  std::vector<std::pair<double, double>> rings;
  const int n = kSegments / 4;  // rings per quarter circle
  for (int i = 0; i <= n; ++i) {
    const double a = -kPi / 2 + (kPi / 2) * i / n;
    rings.emplace_back(i == 0 ? 0.0 : radius * std::cos(a), radius * std::sin(a) - half_length);
  }
  for (int i = half_length > 0 ? 0 : 1; i <= n; ++i) {
    const double a = (kPi / 2) * i / n;
    rings.emplace_back(i == n ? 0.0 : radius * std::cos(a), radius * std::sin(a) + half_length);
  }
  return Revolve(rings);
}

std::shared_ptr<sgal::Mesh> TransformMesh(const sgal::Mesh& in, const Eigen::Matrix3d& m) {
  auto out = std::make_shared<sgal::Mesh>(in);
  const Eigen::Matrix3f mf = m.cast<float>();
  for (auto& v : out->vertices) v = mf * v;
  if (!out->normals.empty()) {
    const Eigen::Matrix3f n = m.inverse().transpose().cast<float>();
    for (auto& v : out->normals) {
      v = n * v;
      const float len = v.norm();
      if (len > 0) v /= len;
    }
  }
  if (m.determinant() < 0)
    for (auto& t : out->triangles) std::swap(t[1], t[2]);
  return out;
}

bool IsDiagonal(const Eigen::Matrix3d& m) {
  const double scale = m.cwiseAbs().maxCoeff();
  const Eigen::Matrix3d off = m - Eigen::Matrix3d(m.diagonal().asDiagonal());
  return off.cwiseAbs().maxCoeff() <= 1e-9 * scale;
}

}  // namespace

std::shared_ptr<const sgal::Mesh> Tessellate(const sgal::Geometry& geometry) {
  struct Visitor {
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::Box& b) const {
      return BoxMesh(b.size);
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::Sphere& s) const {
      return SphereRings(s.radius, 0);
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::Capsule& c) const {
      return SphereRings(c.radius, c.length / 2);
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::Cylinder& c) const {
      return Revolve({{c.radius, -c.length / 2}, {c.radius, c.length / 2}});
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::Cone& c) const {
      return Revolve({{c.radius, -c.length / 2}, {0.0, c.length / 2}});
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::Plane& p) const {
      auto m = BoxMesh(Eigen::Vector3d(10, 10, 0));
      m->triangles.resize(4);  // the two faces of the square
      const Eigen::Quaterniond q =
          Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), p.normal.normalized());
      const Eigen::Vector3f shift = (p.normal.normalized() * p.offset).cast<float>();
      for (auto& v : m->vertices) v = q.cast<float>() * v + shift;
      return m;
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::ConvexHull& h) const {
      return h.mesh ? h.mesh : std::make_shared<sgal::Mesh>();
    }
    std::shared_ptr<const sgal::Mesh> operator()(const sgal::TriangleMesh& t) const {
      return t.mesh ? t.mesh : std::make_shared<sgal::Mesh>();
    }
  };
  return std::visit(Visitor{}, geometry);
}

sgal::Geometry ApplyLinear(const sgal::Geometry& geometry, const Eigen::Matrix3d& m,
                           bool* approximated) {
  if ((m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-12) return geometry;
  const bool diagonal = IsDiagonal(m);
  const Eigen::Vector3d d = m.diagonal().cwiseAbs();
  auto near = [](double a, double b) {
    return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
  };
  auto hull = [&]() -> sgal::Geometry {
    *approximated = true;
    return sgal::ConvexHull{TransformMesh(*Tessellate(geometry), m)};
  };
  if (const auto* b = std::get_if<sgal::Box>(&geometry)) {
    if (diagonal) return sgal::Box{b->size.cwiseProduct(d)};
    return sgal::ConvexHull{TransformMesh(*Tessellate(geometry), m)};  // exact: a box's hull
  }
  if (const auto* s = std::get_if<sgal::Sphere>(&geometry)) {
    if (diagonal && near(d.x(), d.y()) && near(d.y(), d.z()))
      return sgal::Sphere{s->radius * d.x()};
    return hull();
  }
  if (const auto* c = std::get_if<sgal::Capsule>(&geometry)) {
    if (diagonal && near(d.x(), d.y()) && near(d.y(), d.z()))
      return sgal::Capsule{c->radius * d.x(), c->length * d.z()};
    return hull();
  }
  if (const auto* c = std::get_if<sgal::Cylinder>(&geometry)) {
    if (diagonal && near(d.x(), d.y())) return sgal::Cylinder{c->radius * d.x(), c->length * d.z()};
    return hull();
  }
  if (const auto* c = std::get_if<sgal::Cone>(&geometry)) {
    if (diagonal && near(d.x(), d.y()) && m(2, 2) > 0)
      return sgal::Cone{c->radius * d.x(), c->length * d.z()};
    return hull();
  }
  if (const auto* p = std::get_if<sgal::Plane>(&geometry)) {
    // points x with n.x = offset map to y = m x with (m^-T n).y = offset
    const Eigen::Vector3d n = m.inverse().transpose() * p->normal;
    const double len = n.norm();
    return sgal::Plane{n / len, p->offset / len};
  }
  if (const auto* h = std::get_if<sgal::ConvexHull>(&geometry))
    return sgal::ConvexHull{h->mesh ? TransformMesh(*h->mesh, m) : h->mesh};
  const auto& t = std::get<sgal::TriangleMesh>(geometry);
  return sgal::TriangleMesh{t.mesh ? TransformMesh(*t.mesh, m) : t.mesh};
}

bool ExtendBounds(const sgal::Geometry& geometry, const sgal::Pose& pose,
                  Eigen::AlignedBox3d* box) {
  if (std::holds_alternative<sgal::Plane>(geometry)) return false;
  const auto mesh = Tessellate(geometry);
  for (const auto& v : mesh->vertices) box->extend(pose.Apply(v.cast<double>()));
  return true;
}

}  // namespace caliper::collada::internal
