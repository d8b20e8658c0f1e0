#include "caliper/actuators/tendon_contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace caliper::actuators {

namespace {

using Interval = std::optional<std::pair<double, double>>;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The interval helpers below are forced inline: called from several shape branches, GCC kept
// them out of line, and the calls with their returned optionals cost ~8% of the contact search.

/// Intersects [lo, hi] with the slab lo_s <= p + t d <= hi_s along one axis.
[[gnu::always_inline]] inline bool Slab(double p, double d, double lo_s, double hi_s, double* lo,
                                        double* hi) {
  if (std::abs(d) < 1e-15) return p >= lo_s && p <= hi_s;
  const double inverse = 1 / d;  // one division, not two
  double t0 = (lo_s - p) * inverse, t1 = (hi_s - p) * inverse;
  if (t0 > t1) std::swap(t0, t1);
  *lo = std::max(*lo, t0);
  *hi = std::min(*hi, t1);
  return *lo <= *hi;
}

Interval BoxInterval(const Eigen::Vector3d& half, const Eigen::Vector3d& p,
                     const Eigen::Vector3d& d, double t_max = 1) {
  double lo = 0, hi = t_max;
  for (int i = 0; i < 3; ++i)
    if (!Slab(p[i], d[i], -half[i], half[i], &lo, &hi)) return std::nullopt;
  return std::make_pair(lo, hi);
}

/// Roots of |p + t d - c|^2 = r^2 restricted to [0, 1].
[[gnu::always_inline]] inline Interval SphereInterval(const Eigen::Vector3d& c, double r,
                                                      const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& d, double t_max = 1) {
  const Eigen::Vector3d m = p - c;
  const double A = d.squaredNorm(), B = m.dot(d), C = m.squaredNorm() - r * r;
  if (A < 1e-30) return C <= 0 ? Interval(std::make_pair(0.0, t_max)) : std::nullopt;
  // the reciprocal is taken while the root is: the roots wait for a product, not a division
  const double inverse = 1 / A;
  const double disc = B * B - A * C;
  if (disc <= 0) return std::nullopt;
  const double s = std::sqrt(disc);
  const double lo = std::max(0.0, (-B - s) * inverse), hi = std::min(t_max, (-B + s) * inverse);
  if (lo > hi) return std::nullopt;
  return std::make_pair(lo, hi);
}

/// Infinite cylinder about z of radius r, cut to |z| <= half_length.
[[gnu::always_inline]] inline Interval CylinderInterval(double r, double half_length,
                                                        const Eigen::Vector3d& p,
                                                        const Eigen::Vector3d& d,
                                                        double t_max = 1) {
  double lo = 0, hi = t_max;
  if (!Slab(p.z(), d.z(), -half_length, half_length, &lo, &hi)) return std::nullopt;
  const double A = d.x() * d.x() + d.y() * d.y();
  const double B = p.x() * d.x() + p.y() * d.y();
  const double C = p.x() * p.x() + p.y() * p.y() - r * r;
  if (A < 1e-30) {
    if (C > 0) return std::nullopt;
  } else {
    const double inverse = 1 / A;
    const double disc = B * B - A * C;
    if (disc <= 0) return std::nullopt;
    const double s = std::sqrt(disc);
    lo = std::max(lo, (-B - s) * inverse);
    hi = std::min(hi, (-B + s) * inverse);
  }
  if (lo > hi) return std::nullopt;
  return std::make_pair(lo, hi);
}

/// The part of t in [0, t_max] where a signed distance start + t rate is below zero (inside a
/// half-space): for a plane in its own frame and in the world's alike. t_max may be infinite.
[[gnu::always_inline]] inline Interval HalfSpaceInterval(double start, double rate,
                                                         double t_max) {
  if (start < 0 && rate <= 0) return std::make_pair(0.0, t_max);  // inside, never leaves
  if (start >= 0 && rate >= 0) return std::nullopt;               // outside, never enters
  const double t = -start / rate;  // where it crosses
  if (start < 0) return std::make_pair(0.0, std::min(t, t_max));
  if (!(t < t_max)) return std::nullopt;
  return std::make_pair(t, t_max);
}

[[gnu::always_inline]] inline Interval Union(Interval a, Interval b) {
  if (!a) return b;
  if (!b) return a;
  return std::make_pair(std::min(a->first, b->first), std::max(a->second, b->second));
}

Eigen::Vector3d MeshHalfExtents(const sgal::Mesh* mesh, Eigen::Vector3d* center) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
  if (mesh != nullptr)
    for (const auto& v : mesh->vertices) {
      lo = lo.cwiseMin(v.cast<double>());
      hi = hi.cwiseMax(v.cast<double>());
    }
  if (!(lo.array() <= hi.array()).all()) {
    *center = Eigen::Vector3d::Zero();
    return Eigen::Vector3d::Zero();
  }
  *center = (lo + hi) / 2;
  return (hi - lo) / 2;
}

}  // namespace

void PrepareShape(WorldShape* shape) {
  shape->bounding_radius = sgal::BoundingRadius(*shape->geometry);
  shape->mesh_box.reset();
  const sgal::Mesh* mesh = nullptr;
  if (const auto* hull = std::get_if<sgal::ConvexHull>(shape->geometry)) mesh = hull->mesh.get();
  if (const auto* tri = std::get_if<sgal::TriangleMesh>(shape->geometry)) mesh = tri->mesh.get();
  if (std::holds_alternative<sgal::ConvexHull>(*shape->geometry) ||
      std::holds_alternative<sgal::TriangleMesh>(*shape->geometry)) {
    Eigen::Vector3d center;
    const Eigen::Vector3d half = MeshHalfExtents(mesh, &center);
    shape->mesh_box = std::make_pair(center, half);
  }
}

namespace {

/// SegmentInside in the shape's own frame: the points p + t d, t in [0, t_max] (t_max may be
/// infinite: a ray).
Interval LocalInterval(const WorldShape& shape, const Eigen::Vector3d& p, const Eigen::Vector3d& d,
                       double margin, double t_max = 1) {
  return std::visit(
      [&](const auto& g) -> Interval {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, sgal::Box>) {
          return BoxInterval(g.size / 2 + Eigen::Vector3d::Constant(margin), p, d, t_max);
        } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
          return SphereInterval(Eigen::Vector3d::Zero(), g.radius + margin, p, d, t_max);
        } else if constexpr (std::is_same_v<T, sgal::Capsule>) {
          const double r = g.radius + margin, h = g.length / 2;
          // a piece wholly on one side of the capsule's box misses it (most pieces near a
          // jointed neighbour do): no root nor division
          if (std::isfinite(t_max)) {
            const Eigen::Vector3d e = p + t_max * d;
            const Eigen::Vector3d reach(r, r, h + r);
            if ((p.array() > reach.array() && e.array() > reach.array()).any() ||
                (p.array() < -reach.array() && e.array() < -reach.array()).any())
              return std::nullopt;
          }
          Interval i = CylinderInterval(r, h, p, d, t_max);
          // a cap's ball adds to the cylinder and the other ball only beyond its end plane: a
          // segment that stays short of that plane needs no test against it
          const double z0 = p.z(), z1 = d.z() == 0 ? z0 : p.z() + t_max * d.z();  // t_max may be inf
          if (std::max(z0, z1) > h)
            i = Union(i, SphereInterval(Eigen::Vector3d(0, 0, h), r, p, d, t_max));
          if (std::min(z0, z1) < -h)
            i = Union(i, SphereInterval(Eigen::Vector3d(0, 0, -h), r, p, d, t_max));
          return i;
        } else if constexpr (std::is_same_v<T, sgal::Cylinder> || std::is_same_v<T, sgal::Cone>) {
          return CylinderInterval(g.radius + margin, g.length / 2 + margin, p, d, t_max);
        } else if constexpr (std::is_same_v<T, sgal::Plane>) {
          return HalfSpaceInterval(g.normal.dot(p) - g.offset - margin, g.normal.dot(d), t_max);
        } else {
          Eigen::Vector3d center;
          const Eigen::Vector3d half =
              shape.mesh_box ? shape.mesh_box->second : MeshHalfExtents(g.mesh.get(), &center);
          if (shape.mesh_box) center = shape.mesh_box->first;
          if (half.isZero()) return std::nullopt;
          return BoxInterval(half + Eigen::Vector3d::Constant(margin), p - center, d, t_max);
        }
      },
      *shape.geometry);
}

}  // namespace

Interval SegmentInside(const WorldShape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       double margin) {
  // into the shape's frame by the transposed rotation: no inverse, no 4x4 products
  const auto rotation = shape.pose.linear();
  const Eigen::Vector3d p = rotation.transpose() * (a - shape.pose.translation());
  const Eigen::Vector3d d = rotation.transpose() * (b - a);
  return LocalInterval(shape, p, d, margin);
}

namespace {

struct Crossing {
  double t_in = 1, t_out = 0;
  const WorldShape* shape = nullptr;
  double distance2 = 0;  // squared, of the shape's origin from the routed segment bent [m^2]
  Eigen::Vector3d p, d;  // the piece in the shape's frame: p + t d (see LocalInterval)
};

using Candidate = ContactScratch::Candidate;

/// Where the ray m + s w (s >= 0, in the shape's frame) leaves the shape grown by `margin`, as
/// LocalInterval's end over the whole ray; 0 when it does not start inside. A capsule's exit is
/// found directly: through its side where the ray leaves the side's infinite cylinder between the
/// end planes (each cap's ball lies inside that cylinder), else through the cap on that side.
double RayExit(const WorldShape& shape, const Eigen::Vector3d& m, const Eigen::Vector3d& w,
               double margin) {
  if (const auto* capsule = std::get_if<sgal::Capsule>(shape.geometry)) {
    const double r = capsule->radius + margin, h = capsule->length / 2;
    const double A = w.x() * w.x() + w.y() * w.y();
    const double B = m.x() * w.x() + m.y() * w.y();
    const double C = m.x() * m.x() + m.y() * m.y() - r * r;
    if (C <= 0 && A >= 1e-30) {  // inside the side's cylinder: one exit from it
      const double side = (-B + std::sqrt(B * B - A * C)) * (1 / A);
      const double z = m.z() + side * w.z();
      const double cap = z > h ? h : z < -h ? -h : 0.0;
      if (cap == 0.0) return side;
      const Eigen::Vector3d from = m - Eigen::Vector3d(0, 0, cap);
      const double A3 = w.squaredNorm(), B3 = from.dot(w), C3 = from.squaredNorm() - r * r;
      const double disc = B3 * B3 - A3 * C3;
      if (C3 <= 0 && disc >= 0) return (-B3 + std::sqrt(disc)) * (1 / A3);
    }
  }
  const auto exit = LocalInterval(shape, m, w, margin, kInf);  // anything else, the general way
  return exit ? exit->second : 0.0;
}

/// The deepest-cutting crossing of a-b with a shape not fixed to an excluded body. `ab` = b - a,
/// `l2` its squared length. No root nor division waits before the shapes are filtered.
Crossing FirstCrossing(const Eigen::Vector3d& a, const Eigen::Vector3d& ab, double l2,
                       const std::vector<Candidate>& candidates, int exclude_a, int exclude_b,
                       double margin) {
  Crossing best;
  double best_len = 0;
  for (const Candidate& s : candidates) {
    if (s.body == exclude_a || s.body == exclude_b) continue;
    // only shapes whose bounding ball (grown by the margin) comes near the segment are tested;
    // nothing here waits on the piece's length (a root and a division): its search starts at once
    const Eigen::Vector3d to_centre = s.centre - a;
    const double along = to_centre.dot(ab);
    const double centre2 = to_centre.squaredNorm();
    // the centre's squared distance from the segment, compared without dividing by l2
    const bool close = along <= 0    ? centre2 <= s.reach2
                       : along >= l2 ? (to_centre - ab).squaredNorm() <= s.reach2
                                     : (centre2 - s.reach2) * l2 <= along * along;
    if (!close) continue;
    const auto rotation = s.shape->pose.linear();
    const Eigen::Vector3d p = rotation.transpose() * (-to_centre);
    const Eigen::Vector3d d = rotation.transpose() * ab;
    const auto i = LocalInterval(*s.shape, p, d, margin);
    if (!i || i->second - i->first <= 1e-9) continue;
    if (i->second - i->first > best_len) {
      best_len = i->second - i->first;
      best = {i->first, i->second, s.shape, s.distance2, p, d};
    }
  }
  return best;
}

/// How far from its origin a point on the shape grown by `margin` can lie [m]: a bound on where a
/// detour point put on its surface goes.
double SurfaceReach(const WorldShape& shape, double margin) {
  return std::visit(
      [&](const auto& g) -> double {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, sgal::Box>) {
          return (g.size / 2 + Eigen::Vector3d::Constant(margin)).norm();
        } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
          return g.radius + margin;
        } else if constexpr (std::is_same_v<T, sgal::Capsule>) {
          return g.radius + g.length / 2 + margin;
        } else if constexpr (std::is_same_v<T, sgal::Cylinder> || std::is_same_v<T, sgal::Cone>) {
          return std::hypot(g.radius + margin, g.length / 2 + margin);
        } else if constexpr (std::is_same_v<T, sgal::Plane>) {
          return kInf;
        } else {
          // taken by their local bounding box, whose corners lie within sqrt(3) times the
          // farthest vertex
          const double radius = shape.bounding_radius >= 0 ? shape.bounding_radius
                                                           : sgal::BoundingRadius(*shape.geometry);
          return std::sqrt(3.0) * (radius + margin);
        }
      },
      *shape.geometry);
}

/// The half extents of a sphere's, capsule's or cylinder's box in its frame, grown by `margin`
/// [m]; nothing for other shapes.
std::optional<Eigen::Vector3d> LocalReach(const WorldShape& shape, double margin) {
  if (const auto* sphere = std::get_if<sgal::Sphere>(shape.geometry))
    return Eigen::Vector3d::Constant(sphere->radius + margin);
  if (const auto* capsule = std::get_if<sgal::Capsule>(shape.geometry)) {
    const double r = capsule->radius + margin;
    return Eigen::Vector3d(r, r, capsule->length / 2 + r);
  }
  if (const auto* cylinder = std::get_if<sgal::Cylinder>(shape.geometry)) {
    const double r = cylinder->radius + margin;
    return Eigen::Vector3d(r, r, cylinder->length / 2 + margin);
  }
  return std::nullopt;
}

// Exact wraps (ContactOptions::exact_wraps). The shortest way of a string from a to b around a
// convex shape is a tangent from a, a geodesic of the surface and a tangent to b. It is drawn as
// a polygon circumscribing each curved part: its vertices stand out of the surface by
// 1 / cos(half the turn between them), so that every edge touches the surface and none cuts it,
// and the first and last edges continue the tangents. The length is the exact one.

constexpr int kMaxWrapVertices = 32;
constexpr double kMaxTurn = M_PI / 4;  // the largest turn of the string at one vertex [rad]
/// cos(kMaxTurn / 2), and its inverse: how far out of the surface a vertex can stand, relative
/// to its radius
constexpr double kCosHalfMaxTurn = 0.92387953251128674;
constexpr double kVertexReach = 1.0823922002923940;

/// A wrap in the shape's frame: the vertices in order from a to b and the length from a to b.
struct ExactWrap {
  double length = 0;  // [m]
  int count = 0;
  std::array<Eigen::Vector3d, kMaxWrapVertices> vertices;
  bool Add(const Eigen::Vector3d& v) {
    if (count == kMaxWrapVertices) return false;
    vertices[count++] = v;
    return true;
  }
};

/// Turns the unit vector (c, s) by the angle x; a small turn by its series, with no call.
inline void Turn(double x, double* c, double* s) {
  double cos_x, sin_x;
  if (std::abs(x) < 0.02) {  // the first terms left out are below 1e-18
    const double x2 = x * x;
    // by products with the coefficients: no division waits in the Newton steps
    cos_x = 1 - x2 * (1.0 / 2 - x2 * (1.0 / 24 - x2 * (1.0 / 720)));
    sin_x = x * (1 - x2 * (1.0 / 6 - x2 * (1.0 / 120 - x2 * (1.0 / 5040))));
  } else {
    cos_x = std::cos(x);
    sin_x = std::sin(x);
  }
  const double next = *c * cos_x - *s * sin_x;
  *s = *s * cos_x + *c * sin_x;
  *c = next;
}

/// Halves the angle whose cosine and sine are (*c, *s), for angles in (-pi, pi): two roots side
/// by side (a small half angle's sine is off by about 1e-16 / itself, a vertex by far less than
/// a nanometre).
inline void Halve(double* c, double* s) {
  const double half_sin = std::copysign(std::sqrt(std::max(0.0, (1 - *c) / 2)), *s);
  *c = std::sqrt((1 + *c) / 2);
  *s = half_sin;
}

/// Adds the vertices circumscribing the arc c + r (cos psi e1 + sin psi e2) from psi0 over the
/// turn (either way, less than pi), both given by their cosines and sines, e1 and e2
/// orthonormal: none when the turn is nil. The arc is cut in a power of two of equal turns of
/// at most kMaxTurn, so that a half turn comes from the whole by halving, with no angle taken.
bool AddArc(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2,
            double cos0, double sin0, double cos_turn, double sin_turn, ExactWrap* wrap) {
  if (!(std::abs(sin_turn) > 1e-12) && cos_turn > 0) return true;
  int n = 1;
  double cos_half = cos_turn, sin_half = sin_turn;
  Halve(&cos_half, &sin_half);
  while (cos_half < kCosHalfMaxTurn) {
    n *= 2;
    Halve(&cos_half, &sin_half);
  }
  const double out = r / cos_half;
  // the vertices' directions by one rotation each
  const double cos_step = cos_half * cos_half - sin_half * sin_half;
  const double sin_step = 2 * sin_half * cos_half;
  double cos_psi = cos0 * cos_half - sin0 * sin_half, sin_psi = sin0 * cos_half + cos0 * sin_half;
  for (int k = 0; k < n; ++k) {
    if (!wrap->Add(c + out * (cos_psi * e1 + sin_psi * e2))) return false;
    const double next = cos_psi * cos_step - sin_psi * sin_step;
    sin_psi = sin_psi * cos_step + cos_psi * sin_step;
    cos_psi = next;
  }
  return true;
}

/// From the frame's origin (the shape's) across the line p + t d, 1 / |d|^2 given: where the
/// bisection's detour goes out, and what picks an exact wrap's way round when the ends and the
/// centre are in line.
Eigen::Vector3d Across(const Eigen::Vector3d& p, const Eigen::Vector3d& d, double inverse_d2) {
  return p - d * (d.dot(p) * inverse_d2);
}

Eigen::Vector3d Across(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return Across(a, b - a, 1 / (b - a).squaredNorm());
}

/// The string from a to b around the ball (c, r): a tangent, an arc of the great circle through
/// a and b, a tangent (when a, b and c are in line, in the plane through Across(a, b)). The arc's
/// ends (the tangent points) go to *t_a and *t_b. False when an end is inside or the ends see
/// each other.
bool WrapBall(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
              ExactWrap* wrap, Eigen::Vector3d* t_a, Eigen::Vector3d* t_b) {
  const Eigen::Vector3d u = a - c, v = b - c;
  const double r2 = r * r, du2 = u.squaredNorm(), dv2 = v.squaredNorm();
  if (!(du2 > r2 && dv2 > r2)) return false;
  const double du = std::sqrt(du2), dv = std::sqrt(dv2);
  const double inverse_du = 1 / du, inverse_dv = 1 / dv;
  const Eigen::Vector3d e1 = u * inverse_du;
  Eigen::Vector3d e2 = v - e1 * e1.dot(v);
  const double across = e2.norm(), along = e1.dot(v);
  if (across > 1e-12 * dv) {
    e2 /= across;
  } else {  // in line (rarely): the plane through the line's perpendicular
    const Eigen::Vector3d across_line = Across(a, b);
    e2 = across_line - e1 * e1.dot(across_line);
    if (!(e2.squaredNorm() > 1e-24)) e2 = e1.unitOrthogonal();
    e2.normalize();
  }
  // the angles at c, by their cosines and sines: gamma between a and b, alpha_a and alpha_b
  // between each end and its tangent point (cos alpha = r / distance); the arc turns by
  // gamma - alpha_a - alpha_b
  const double tangent_a = std::sqrt(du2 - r2), tangent_b = std::sqrt(dv2 - r2);
  const double cos_g = along * inverse_dv, sin_g = across * inverse_dv;
  const double cos_a = r * inverse_du, sin_a = tangent_a * inverse_du;
  const double cos_b = r * inverse_dv, sin_b = tangent_b * inverse_dv;
  const double cos_gb = cos_g * cos_b + sin_g * sin_b, sin_gb = sin_g * cos_b - cos_g * sin_b;
  const double cos_turn = cos_gb * cos_a + sin_gb * sin_a;
  const double sin_turn = sin_gb * cos_a - cos_gb * sin_a;
  if (!(sin_turn > 0)) return false;  // the turn lies in (-pi, pi): the ends see each other
  const double turn = std::atan2(sin_turn, cos_turn);
  wrap->length = tangent_a + tangent_b + r * turn;
  *t_a = c + r * (cos_a * e1 + sin_a * e2);
  *t_b = c + r * (cos_gb * e1 + sin_gb * e2);
  return AddArc(c, r, e1, e2, cos_a, sin_a, cos_turn, sin_turn, wrap);
}

/// One end of a capsule wrap over a cap: the end at u from the cap's centre (|u| > r), the string
/// leaving the cap's ball for the side at p = r (cos theta, sin theta, 0) on its end circle. Its
/// length from the end to p is the tangent plus r (phi - alpha), phi the angle between u and p,
/// alpha = acos(r / |u|) the tangent's; the derivatives in theta are phi's.
struct CapEnd {
  Eigen::Vector3d u;
  double du, inverse_du, tangent;
  double k, k1, sin_phi, inverse_sin_phi;  // cos(phi), its derivative in theta, sin(phi)
  double slope, curvature;  // d phi / d theta and d2 phi / d theta2 (k'' = -k)
  void At(double cos_theta, double sin_theta) {
    k = (u.x() * cos_theta + u.y() * sin_theta) * inverse_du;
    k1 = (u.y() * cos_theta - u.x() * sin_theta) * inverse_du;
    // the root and the reciprocal of its square side by side, not one after the other
    const double sin2 = std::max(0.0, 1 - k * k);
    sin_phi = std::sqrt(sin2);
    inverse_sin_phi = sin_phi * (1 / sin2);
    slope = -k1 * inverse_sin_phi;
    curvature = k * inverse_sin_phi * (1 - slope * slope);
  }
  /// phi - alpha, the arc over the cap, by its cosine and sine; false when it is negative.
  bool Arc(double r, double* cos_turn, double* sin_turn) const {
    const double cos_alpha = r * inverse_du, sin_alpha = tangent * inverse_du;
    *cos_turn = k * cos_alpha + sin_phi * sin_alpha;
    *sin_turn = sin_phi * cos_alpha - k * sin_alpha;
    return *sin_turn >= 0;
  }
};

/// The string from a (beyond the end plane z = -h) to b (beyond z = h) over both caps of the
/// capsule (radius r, caps' centres at z = -h and h) and along its side: where it crosses the end
/// circles (theta_a, theta_b) minimises cap + helix + cap, by Newton's method from the ends'
/// mean direction about the axis (or Across(a, b)'s). The angles are carried as unit vectors, turned
/// by each step, and their difference as a number. False when that is not the shortest way (a
/// tangent would not meet its cap, or the search does not settle): the bisection takes it.
bool WrapCapsuleOverCaps(double r, double h, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         ExactWrap* wrap) {
  const Eigen::Vector3d ca(0, 0, -h), cb(0, 0, h);
  CapEnd ea, eb;
  ea.u = a - ca;
  eb.u = b - cb;
  ea.du = ea.u.norm();
  eb.du = eb.u.norm();
  if (!(ea.du > r && eb.du > r)) return false;
  ea.inverse_du = 1 / ea.du;
  eb.inverse_du = 1 / eb.du;
  ea.tangent = std::sqrt(ea.du * ea.du - r * r);
  eb.tangent = std::sqrt(eb.du * eb.du - r * r);
  Eigen::Vector2d mean = ea.u.head<2>() * ea.inverse_du + eb.u.head<2>() * eb.inverse_du;
  if (!(mean.squaredNorm() > 1e-16)) mean = Across(a, b).head<2>();
  const double mean2 = mean.squaredNorm();
  if (!(mean2 > 1e-24)) return false;
  mean *= 1 / std::sqrt(mean2);
  double cos_a = mean.x(), sin_a = mean.y(), cos_b = cos_a, sin_b = sin_a;
  double turn = 0;  // theta_b - theta_a [rad]
  const double rise2 = 4 * h * h, r2 = r * r;
  bool settled = false;
  for (int iteration = 0; iteration < 30 && !settled; ++iteration) {
    ea.At(cos_a, sin_a);
    eb.At(cos_b, sin_b);
    if (!(ea.sin_phi > 1e-9 && eb.sin_phi > 1e-9)) return false;
    const double helix2 = rise2 + r2 * turn * turn;
    const double inverse_helix = std::sqrt(helix2) * (1 / helix2);
    const double pull = r2 * turn * inverse_helix;
    const double stiff = r2 * rise2 * inverse_helix * inverse_helix * inverse_helix;
    const double g_a = r * ea.slope - pull, g_b = r * eb.slope + pull;
    const double h_aa = r * ea.curvature + stiff, h_bb = r * eb.curvature + stiff;
    const double h_ab = -stiff, det = h_aa * h_bb - h_ab * h_ab;
    if (!(h_aa > 0 && det > 0)) return false;  // not near a minimum
    const double inverse_det = 1 / det;
    double step_a = -(h_bb * g_a - h_ab * g_b) * inverse_det;
    double step_b = -(h_aa * g_b - h_ab * g_a) * inverse_det;
    const double largest = std::max(std::abs(step_a), std::abs(step_b));
    // Newton's method doubles the digits a step: a step under 1e-6 rad says these angles are off
    // by about that, so the wrap is taken here (its vertices off the geodesic's by 1e-6 of the
    // radius, their edges still touching; the length, stationary in the angles, by 1e-12 of it)
    // without evaluating the point again
    settled = largest < 1e-6;
    if (settled) break;
    if (largest > 0.5) {  // no more than half a radian at once
      step_a *= 0.5 / largest;
      step_b *= 0.5 / largest;
    }
    Turn(step_a, &cos_a, &sin_a);
    Turn(step_b, &cos_b, &sin_b);
    turn += step_b - step_a;
  }
  if (!settled) return false;
  // each tangent must meet its cap before the end circle, and the helix turn the short way
  double cos_arc_a, sin_arc_a, cos_arc_b, sin_arc_b;
  if (!ea.Arc(r, &cos_arc_a, &sin_arc_a) || !eb.Arc(r, &cos_arc_b, &sin_arc_b) ||
      !(std::abs(turn) < M_PI))
    return false;
  // both arcs' angles at once when neither passes a right angle (their sum is then below pi)
  const double arcs =
      cos_arc_a >= 0 && cos_arc_b >= 0
          ? std::atan2(sin_arc_a * cos_arc_b + cos_arc_a * sin_arc_b,
                       cos_arc_a * cos_arc_b - sin_arc_a * sin_arc_b)
          : std::atan2(sin_arc_a, cos_arc_a) + std::atan2(sin_arc_b, cos_arc_b);
  const double helix = std::sqrt(rise2 + r2 * turn * turn);
  wrap->length = ea.tangent + eb.tangent + r * arcs + helix;
  // over a's cap in the plane of u and p_a, from the tangent point to the end circle
  Eigen::Vector3d e1 = ea.u * ea.inverse_du;
  Eigen::Vector3d e2 = (Eigen::Vector3d(cos_a, sin_a, 0) - ea.k * e1) * ea.inverse_sin_phi;
  if (!AddArc(ca, r, e1, e2, r * ea.inverse_du, ea.tangent * ea.inverse_du, cos_arc_a, sin_arc_a,
              wrap))
    return false;
  // along the side: a helix, straight when the side is unrolled; its vertices circumscribe
  // the end circle's arc at heights in proportion. Where the string passes from cap to side
  // (p_a, p_b) it needs no vertex: the last vertex over the cap and the first along the side
  // both lie in the plane touching the capsule there, so the edge between them does too, and
  // no edge cuts in
  if (std::abs(turn) > 1e-12) {
    int n = 1;
    while (std::abs(turn) > n * kMaxTurn) n *= 2;  // as the arcs are cut
    const double half = turn / (2 * n);
    double cos_t = cos_a, sin_t = sin_a, cos_half = 1, sin_half = 0;
    Turn(half, &cos_half, &sin_half);
    Turn(half, &cos_t, &sin_t);
    const double out = r / cos_half, rise = 2 * h / n;
    for (int k = 0; k < n; ++k) {
      if (!wrap->Add(Eigen::Vector3d(out * cos_t, out * sin_t, -h + rise * (k + 0.5))))
        return false;
      Turn(2 * half, &cos_t, &sin_t);
    }
  }
  // over b's cap, from the end circle back to the tangent point
  e1 = eb.u * eb.inverse_du;
  e2 = (Eigen::Vector3d(cos_b, sin_b, 0) - eb.k * e1) * eb.inverse_sin_phi;
  return AddArc(cb, r, e1, e2, eb.k, eb.sin_phi, cos_arc_b, -sin_arc_b, wrap);
}

/// The string from a to b around a sphere or capsule grown to radius r (in its frame), when one
/// of the cases above is the shortest way; false otherwise.
bool WrapExactly(const sgal::Geometry& geometry, double margin, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, ExactWrap* wrap) {
  wrap->count = 0;
  Eigen::Vector3d t_a, t_b;
  if (const auto* sphere = std::get_if<sgal::Sphere>(&geometry))
    return WrapBall(Eigen::Vector3d::Zero(), sphere->radius + margin, a, b, wrap, &t_a, &t_b);
  const auto* capsule = std::get_if<sgal::Capsule>(&geometry);
  if (capsule == nullptr) return false;
  const double r = capsule->radius + margin, h = capsule->length / 2;
  if (!(h > 1e-6 * r)) {  // no side to speak of: a ball
    return WrapBall(Eigen::Vector3d::Zero(), r, a, b, wrap, &t_a, &t_b);
  }
  // both ends beyond one end plane: over that cap's ball, if the arc stays beyond the plane too
  // (the segments to the tangent points then do as well, and the capsule is the ball there)
  for (const double side : {-1.0, 1.0}) {
    if (side * a.z() > h && side * b.z() > h) {
      const Eigen::Vector3d centre(0, 0, side * h);
      return WrapBall(centre, r, a, b, wrap, &t_a, &t_b) && side * t_a.z() >= h &&
             side * t_b.z() >= h;
    }
  }
  if (a.z() < -h && b.z() > h) return WrapCapsuleOverCaps(r, h, a, b, wrap);
  if (a.z() > h && b.z() < -h) {
    // the same turned upside down (half a turn about x), and back
    const Eigen::Vector3d flip(1, -1, -1);
    if (!WrapCapsuleOverCaps(r, h, a.cwiseProduct(flip), b.cwiseProduct(flip), wrap))
      return false;
    for (int k = 0; k < wrap->count; ++k) wrap->vertices[k] = wrap->vertices[k].cwiseProduct(flip);
    return true;
  }
  return false;  // the side first: the bisection
}

/// One routed segment being bent. Every detour point lies within `rho` of the routed segment, so
/// a shape can come near a piece of the bent path only if it comes within its reach plus `rho`
/// of the routed segment: `near` holds those, in the query's order, and grows with `rho`.
struct Bend {
  const std::vector<Candidate>* candidates;
  std::vector<Candidate>* near;
  double rho = 0;  // [m]
  const ContactOptions* options;
  std::vector<PathPoint>* out;
  /// The exact wraps: where their pieces run in `out` (from the point before the first vertex
  /// to the point after the last) and their lengths [m], in order.
  std::vector<ContactScratch::Wrapped>* wrapped;
  ExactWrap wrap;
  std::array<Eigen::Vector3d, kMaxWrapVertices + 2> local;  // a wrap in another shape's frame

  void Select() {
    near->clear();
    // a little slack for rounding: keeping one shape too many changes nothing
    for (const Candidate& c : *candidates) {
      const double bound = (c.reach + rho) * (1 + 1e-9) + 1e-12;
      if (c.distance2 <= bound * bound) near->push_back(c);
    }
  }
};

/// Bends a-b exactly around the crossing's shape (ContactOptions::exact_wraps) when it is a
/// sphere or capsule, the wrap is the shortest way, and no other shape cuts it.
bool WrapCrossing(const PathPoint& a, const PathPoint& b, const Crossing& c, Bend* bend) {
  const WorldShape& shape = *c.shape;
  const ContactOptions& options = *bend->options;
  ExactWrap& wrap = bend->wrap;
  if (!WrapExactly(*shape.geometry, options.margin, c.p, c.p + c.d, &wrap)) return false;
  // every vertex lies within the surface's reach, pushed out by at most kVertexReach: the
  // shapes the pieces can come near must all be known
  const double rho =
      std::sqrt(c.distance2) + kVertexReach * SurfaceReach(shape, options.margin) + 1e-9;
  if (!(rho <= options.margin + options.detour_reach)) return false;
  if (rho > bend->rho) {
    bend->rho = rho;
    bend->Select();
  }
  // to the world, with the box around the whole wrap
  const auto rotation = shape.pose.linear();
  const Eigen::Vector3d origin = shape.pose.translation();
  Eigen::Vector3d lo = a.position.cwiseMin(b.position), hi = a.position.cwiseMax(b.position);
  for (int k = 0; k < wrap.count; ++k) {
    Eigen::Vector3d& v = wrap.vertices[k];
    v = origin + rotation * v;
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  // no other shape may cut a piece (the tendon's own ends' bodies excepted, as the bisection
  // excepts them); only those whose bounding ball comes near the box can. Each is tested in its
  // own frame, first by its box against all the pieces it may cut at once
  const int count = wrap.count;
  auto point = [&](int k) -> const Eigen::Vector3d& {
    return k < 0 ? a.position : k < count ? wrap.vertices[k] : b.position;
  };
  for (const Candidate& n : *bend->near) {
    if (n.shape == &shape) continue;
    const Eigen::Vector3d nearest = n.centre.cwiseMax(lo).cwiseMin(hi);
    if (!((n.centre - nearest).squaredNorm() <= n.reach2)) continue;  // planes: always tested
    // pieces first..last (piece k runs from point k - 1 to point k)
    const int first = n.body == a.body && !a.contact ? 1 : 0;
    const int last = n.body == b.body && !b.contact ? count - 1 : count;
    if (first > last) continue;
    const auto turn = n.shape->pose.linear();
    const Eigen::Vector3d at = n.shape->pose.translation();
    const std::optional<Eigen::Vector3d> reach = LocalReach(*n.shape, options.margin);
    if (reach) {
      // along its axis alone first (a third of the products): a jointed neighbour's box ends
      // where the wrap begins
      const Eigen::Vector3d axis = turn.col(2);
      const double offset = axis.dot(at);
      double z_lo = kInf, z_hi = -kInf;
      for (int k = first - 1; k <= last; ++k) {
        const double z = axis.dot(point(k)) - offset;
        z_lo = std::min(z_lo, z);
        z_hi = std::max(z_hi, z);
      }
      if (z_lo > reach->z() || z_hi < -reach->z()) continue;
    }
    std::array<Eigen::Vector3d, kMaxWrapVertices + 2>& local = bend->local;
    Eigen::Vector3d local_lo = Eigen::Vector3d::Constant(kInf), local_hi = -local_lo;
    for (int k = first - 1; k <= last; ++k) {
      Eigen::Vector3d& q = local[k + 1];
      q = turn.transpose() * (point(k) - at);
      local_lo = local_lo.cwiseMin(q);
      local_hi = local_hi.cwiseMax(q);
    }
    if (reach && ((local_lo.array() > reach->array()).any() ||
                  (local_hi.array() < -reach->array()).any()))
      continue;
    for (int k = first; k <= last; ++k) {
      const auto i = LocalInterval(*n.shape, local[k], local[k + 1] - local[k], options.margin);
      if (i && i->second - i->first > 1e-9) return false;
    }
  }
  // a is the last point out (Refine's order); b follows the vertices
  std::vector<PathPoint>& out = *bend->out;
  bend->wrapped->push_back({out.size() - 1, out.size() + count, wrap.length});
  for (int k = 0; k < wrap.count; ++k) {
    PathPoint q;
    q.position = wrap.vertices[k];
    q.body = shape.body;
    q.contact = true;
    out.push_back(q);
  }
  return true;
}

void Refine(const PathPoint& a, const PathPoint& b, Bend* bend, int depth) {
  if (depth <= 0) return;
  const ContactOptions& options = *bend->options;
  const Eigen::Vector3d ab = b.position - a.position;
  const double l2 = ab.squaredNorm();
  const double len = std::sqrt(l2);
  const double inverse_l2 = l2 > 0 ? 1 / l2 : 0.0;
  // a segment may touch the bodies its routed ends sit on; points inserted by contact exclude none
  const Crossing c = FirstCrossing(a.position, ab, l2, *bend->near, a.contact ? -2 : a.body,
                                   b.contact ? -2 : b.body, options.margin);
  if (c.shape == nullptr) return;
  const WorldShape& shape = *c.shape;
  if (len < 1e-12) return;
  if (options.exact_wraps && WrapCrossing(a, b, c, bend)) return;
  const double t_mid = (c.t_in + c.t_out) / 2;
  const Eigen::Vector3d mid = a.position + ab * t_mid;
  // the detour point: where the ray from the middle of the cut along `away` leaves the shape
  // (grown by the margin); no way out within `reach`: the piece stays straight
  const double reach = 10 * len + 1.0;
  PathPoint q;
  if (const auto* plane = std::get_if<sgal::Plane>(shape.geometry)) {
    // out of a half-space along its normal
    Eigen::Vector3d away = shape.pose.linear() * plane->normal;
    away.normalize();
    const auto exit = SegmentInside(shape, mid, mid + away * reach, options.margin);
    if (exit && exit->second >= 1.0) return;
    q.position = mid + away * ((exit ? exit->second : 0.0) * reach + 1e-9);
  } else {
    // perpendicular to the piece, away from the shape's centre (its frame's origin), in the
    // shape's frame where the cut was found. Every point of the piece has the same part across
    // it, so the direction is taken from the piece's start and need not wait for the cut (a root
    // and a division). The ray is followed along the unnormalised direction, so that the search
    // need not wait for its length either
    const Eigen::Vector3d mid_local = c.p + c.d * t_mid;
    Eigen::Vector3d away = Across(c.p, c.d, inverse_l2);
    double away2 = away.squaredNorm();
    if (away2 < 1e-18) {  // through the centre: any perpendicular
      away = c.d.unitOrthogonal().normalized();
      away2 = 1;
    }
    const double inverse_norm = 1 / std::sqrt(away2);
    // the whole ray: an exit beyond `reach` is refused below
    const double s = RayExit(shape, mid_local, away, options.margin);
    if (s * s * away2 >= reach * reach) return;
    q.position = mid + shape.pose.linear() * (away * (s + 1e-9 * inverse_norm));
  }
  q.body = shape.body;
  q.contact = true;
  // the new point lies on the shape's surface: widen the shapes the pieces can come near
  const double rho = std::sqrt(c.distance2) + SurfaceReach(shape, options.margin) + 1e-9;
  if (rho > bend->rho) {
    bend->rho = rho;
    bend->Select();
  }
  Refine(a, q, bend, depth - 1);
  bend->out->push_back(q);
  Refine(q, b, bend, depth - 1);
}

}  // namespace

int WrapAroundBodies(PathGeometry* path, const ShapeQuery& query, const ContactOptions& options) {
  ContactScratch scratch;
  return WrapAroundBodies(path, query, options, &scratch);
}

int WrapAroundBodies(PathGeometry* path, const ShapeQuery& query, const ContactOptions& options,
                     ContactScratch* scratch) {
  return WrapAroundBodies(path, query, options, scratch, nullptr, 0.0);
}

namespace {

// What a clearance proof leaves for rounding [m]: the distances it compares carry errors of a
// few 1e-16 m per metre of coordinates, so this holds for scenes up to kilometres across.
constexpr double kClearanceSlack = 1e-9;

/// Whether the segment a-b cuts the shape grown by `margin` over more than 1e-9 of its length, as
/// SegmentInside says; a plane in the world's frame (no transform of the segment).
bool Cuts(const WorldShape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
          double margin) {
  Interval i;
  if (const auto* plane = std::get_if<sgal::Plane>(shape.geometry)) {
    const Eigen::Vector3d normal = shape.pose.linear() * plane->normal;
    i = HalfSpaceInterval(normal.dot(a - shape.pose.translation()) - plane->offset - margin,
                          normal.dot(b - a), 1.0);
  } else {
    i = SegmentInside(shape, a, b, margin);
  }
  return i && i->second - i->first > 1e-9;
}

/// Whether `memory` proves that the routed segment a-b crosses no shape: every other shape was
/// farther than its reach by more than the segment's ends and the shapes have moved since, and
/// no plane cuts it (tested as the search would).
bool ProvenClear(const ContactMemory& memory, size_t index, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, int exclude_a, int exclude_b, double travel,
                 double margin) {
  const ContactMemory::Segment& s = memory.segments[index];
  if (!(s.clearance > 0) || s.exclude_a != exclude_a || s.exclude_b != exclude_b) return false;
  // every point of the segment moved no more than the farther of its ends (it stays straight)
  const Eigen::Vector3d da = a - s.a, db = b - s.b;
  const double ends = std::sqrt(std::max(da.squaredNorm(), db.squaredNorm()));
  if (!(ends + (travel - s.travel) + kClearanceSlack < s.clearance)) return false;
  // distances do not change when everything moves alike: against the ends' mean move, the
  // segment's points moved at most half the ends' difference, and a shape what is left of its own
  const Eigen::Vector3d mean = (da + db) / 2;
  const double ends_relative = (da - db).norm() / 2;
  for (const ContactMemory::Segment::Near& n : s.near) {
    // squared, no root per shape: the slack covers the rounding of the square
    const double room = n.clearance - ends_relative - kClearanceSlack;
    if (!(room > 0)) return false;
    if (!((n.shape->pose.translation() - n.centre - mean).squaredNorm() < room * room))
      return false;
  }
  for (const WorldShape* plane : s.planes) {
    if (Cuts(*plane, a, b, margin)) return false;
  }
  return true;
}

}  // namespace

int WrapAroundBodies(PathGeometry* path, const ShapeQuery& query, const ContactOptions& options,
                     ContactScratch* scratch, ContactMemory* memory, double travel) {
  if (path->points.size() < 2) return 0;
  const size_t segments = path->points.size() - 1;
  if (memory != nullptr &&
      (memory->margin != options.margin || memory->segments.size() != segments)) {
    // another path shape or margin: nothing remembered holds
    memory->Clear();
    memory->margin = options.margin;
    memory->segments.resize(segments);
  }
  std::vector<PathPoint>& out = scratch->points;
  out.clear();
  std::vector<const WorldShape*>& shapes = scratch->shapes;
  std::vector<Candidate>& candidates = scratch->candidates;
  Bend bend;
  bend.candidates = &candidates;
  bend.near = &scratch->near;
  bend.wrapped = &scratch->wrapped;
  scratch->wrapped.clear();
  bend.options = &options;
  bend.out = &out;
  int inserted = 0;
  for (size_t i = 0; i < segments; ++i) {
    const PathPoint& a = path->points[i];
    const PathPoint& b = path->points[i + 1];
    out.push_back(a);
    // the bodies the search lets the routed segment touch (as Refine excludes them)
    const int exclude_a = a.contact ? -2 : a.body, exclude_b = b.contact ? -2 : b.body;
    if (memory != nullptr && ProvenClear(*memory, i, a.position, b.position, exclude_a, exclude_b,
                                         travel, options.margin))
      continue;
    const size_t before = out.size();
    const double pad = options.margin + options.detour_reach;
    shapes.clear();
    query(a.position, b.position, pad, &shapes);
    candidates.clear();
    const Eigen::Vector3d ab = b.position - a.position;
    const double l2 = ab.squaredNorm();
    // the distances only choose which shapes are tested (with slack): a product will do for the
    // division
    const double inverse_l2 = l2 > 0 ? 1 / l2 : 0.0;
    bool inside_a_ball = false;  // of a shape the segment may not touch
    for (const WorldShape* shape : shapes) {
      const double radius = shape->bounding_radius >= 0 ? shape->bounding_radius
                                                        : sgal::BoundingRadius(*shape->geometry);
      const double reach = radius + options.margin;
      const Eigen::Vector3d centre = shape->pose.translation();
      const double t = std::clamp((centre - a.position).dot(ab) * inverse_l2, 0.0, 1.0);
      const double distance2 = (a.position + t * ab - centre).squaredNorm();
      candidates.push_back({centre, reach * reach, reach, distance2, shape->body, shape});
      inside_a_ball |= distance2 <= reach * reach && shape->body != exclude_a &&
                       shape->body != exclude_b && std::isfinite(reach);
    }
    if (memory != nullptr) {
      // shapes the query left out lie farther than `pad` from the segment's box; those it gave
      // are remembered one by one (a shape's own travel is then enough for it)
      double clearance = options.detour_reach;
      ContactMemory::Segment& s = memory->segments[i];
      s.planes.clear();
      s.near.clear();
      // a segment through a shape's bounding ball has no clearance: nothing to measure
      if (inside_a_ball) clearance = -1;
      for (const Candidate& c : candidates) {
        if (inside_a_ball) break;
        if (c.body == exclude_a || c.body == exclude_b) continue;
        if (std::isinf(c.reach)) {
          s.planes.push_back(c.shape);
        } else {
          const double own = std::sqrt(c.distance2) - c.reach - kClearanceSlack;
          if (own < options.detour_reach) s.near.push_back({c.shape, own, c.centre});
          clearance = std::min(clearance, own);
        }
      }
      // a segment that may touch a shape is searched at every step; otherwise every shape the
      // query left out, or gave farther than that, clears it by `detour_reach`
      if (clearance > 0) {
        clearance = options.detour_reach;
      } else {
        s.near.clear();
      }
      s.a = a.position;
      s.b = b.position;
      s.exclude_a = exclude_a;
      s.exclude_b = exclude_b;
      s.clearance = clearance - kClearanceSlack;
      s.travel = travel;
    }
    bend.rho = 0;
    bend.Select();
    Refine(a, b, &bend, options.max_depth);
    inserted += static_cast<int>(out.size() - before);
  }
  out.push_back(path->points.back());
  if (inserted == 0) return 0;
  // the detour lengthens the path: add what the new points add over the straight segments
  double straight = 0, bent = 0;
  for (size_t i = 0; i + 1 < path->points.size(); ++i)
    straight += (path->points[i + 1].position - path->points[i].position).norm();
  // the pieces of exact wraps by their exact lengths
  auto wrap = scratch->wrapped.begin();
  for (size_t i = 0; i + 1 < out.size(); ++i) {
    if (wrap != scratch->wrapped.end() && wrap->first == i) {
      bent += wrap->length;
      i = wrap->last - 1;
      ++wrap;
    } else {
      bent += (out[i + 1].position - out[i].position).norm();
    }
  }
  path->length += bent - straight;
  // the straight path's buffer becomes the next call's
  std::swap(path->points, out);
  return inserted;
}

}  // namespace caliper::actuators
