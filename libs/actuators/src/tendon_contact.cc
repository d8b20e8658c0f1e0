#include "caliper/actuators/tendon_contact.h"

#include <algorithm>
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
                     const Eigen::Vector3d& d) {
  double lo = 0, hi = 1;
  for (int i = 0; i < 3; ++i)
    if (!Slab(p[i], d[i], -half[i], half[i], &lo, &hi)) return std::nullopt;
  return std::make_pair(lo, hi);
}

/// Roots of |p + t d - c|^2 = r^2 restricted to [0, 1].
[[gnu::always_inline]] inline Interval SphereInterval(const Eigen::Vector3d& c, double r,
                                                      const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& d) {
  const Eigen::Vector3d m = p - c;
  const double A = d.squaredNorm(), B = m.dot(d), C = m.squaredNorm() - r * r;
  if (A < 1e-30) return C <= 0 ? Interval(std::make_pair(0.0, 1.0)) : std::nullopt;
  // the reciprocal is taken while the root is: the roots wait for a product, not a division
  const double inverse = 1 / A;
  const double disc = B * B - A * C;
  if (disc <= 0) return std::nullopt;
  const double s = std::sqrt(disc);
  const double lo = std::max(0.0, (-B - s) * inverse), hi = std::min(1.0, (-B + s) * inverse);
  if (lo > hi) return std::nullopt;
  return std::make_pair(lo, hi);
}

/// Infinite cylinder about z of radius r, cut to |z| <= half_length.
[[gnu::always_inline]] inline Interval CylinderInterval(double r, double half_length,
                                                        const Eigen::Vector3d& p,
                                                        const Eigen::Vector3d& d) {
  double lo = 0, hi = 1;
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

Interval SegmentInside(const WorldShape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       double margin) {
  // into the shape's frame by the transposed rotation: no inverse, no 4x4 products
  const auto rotation = shape.pose.linear();
  const Eigen::Vector3d p = rotation.transpose() * (a - shape.pose.translation());
  const Eigen::Vector3d d = rotation.transpose() * (b - a);
  return std::visit(
      [&](const auto& g) -> Interval {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, sgal::Box>) {
          return BoxInterval(g.size / 2 + Eigen::Vector3d::Constant(margin), p, d);
        } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
          return SphereInterval(Eigen::Vector3d::Zero(), g.radius + margin, p, d);
        } else if constexpr (std::is_same_v<T, sgal::Capsule>) {
          const double r = g.radius + margin, h = g.length / 2;
          Interval i = CylinderInterval(r, h, p, d);
          // a cap's ball adds to the cylinder and the other ball only beyond its end plane: a
          // segment that stays short of that plane needs no test against it
          const double z0 = p.z(), z1 = p.z() + d.z();
          if (std::max(z0, z1) > h) i = Union(i, SphereInterval(Eigen::Vector3d(0, 0, h), r, p, d));
          if (std::min(z0, z1) < -h)
            i = Union(i, SphereInterval(Eigen::Vector3d(0, 0, -h), r, p, d));
          return i;
        } else if constexpr (std::is_same_v<T, sgal::Cylinder> || std::is_same_v<T, sgal::Cone>) {
          return CylinderInterval(g.radius + margin, g.length / 2 + margin, p, d);
        } else if constexpr (std::is_same_v<T, sgal::Plane>) {
          const double da = g.normal.dot(p) - g.offset - margin;
          const double db = g.normal.dot(p + d) - g.offset - margin;
          if (da >= 0 && db >= 0) return std::nullopt;
          if (da < 0 && db < 0) return std::make_pair(0.0, 1.0);
          const double t = da / (da - db);
          return da < 0 ? std::make_pair(0.0, t) : std::make_pair(t, 1.0);
        } else {
          Eigen::Vector3d center;
          const Eigen::Vector3d half =
              shape.mesh_box ? shape.mesh_box->second : MeshHalfExtents(g.mesh.get(), &center);
          if (shape.mesh_box) center = shape.mesh_box->first;
          if (half.isZero()) return std::nullopt;
          return BoxInterval(half + Eigen::Vector3d::Constant(margin), p - center, d);
        }
      },
      *shape.geometry);
}

namespace {

struct Crossing {
  double t_in = 1, t_out = 0;
  const WorldShape* shape = nullptr;
  double distance2 = 0;  // squared, of the shape's origin from the routed segment bent [m^2]
};

using Candidate = ContactScratch::Candidate;

/// The deepest-cutting crossing of a-b with a shape not fixed to an excluded body.
/// `ab` = b - a, `len` its length.
Crossing FirstCrossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& ab, double len,
                       const std::vector<Candidate>& candidates, int exclude_a, int exclude_b,
                       double margin) {
  Crossing best;
  double best_len = 0;
  const double l2 = ab.squaredNorm();
  // the ball around the segment: a cheap first test that rejects most shapes of a short piece
  const Eigen::Vector3d mid = (a + b) / 2;
  const double half_length = len / 2 * (1 + 1e-9) + 1e-12;
  for (const Candidate& s : candidates) {
    if (s.body == exclude_a || s.body == exclude_b) continue;
    const double ball = s.reach + half_length;
    if ((s.centre - mid).squaredNorm() > ball * ball) continue;
    // only shapes whose bounding ball (grown by the margin) comes near the segment are tested
    const double t = l2 > 0 ? std::clamp((s.centre - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
    if (!((a + t * ab - s.centre).squaredNorm() <= s.reach2)) continue;
    const auto i = SegmentInside(*s.shape, a, b, margin);
    if (!i || i->second - i->first <= 1e-9) continue;
    if (i->second - i->first > best_len) {
      best_len = i->second - i->first;
      best = {i->first, i->second, s.shape, s.distance2};
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

/// One routed segment being bent. Every detour point lies within `rho` of the routed segment, so
/// a shape can come near a piece of the bent path only if it comes within its reach plus `rho`
/// of the routed segment: `near` holds those, in the query's order, and grows with `rho`.
struct Bend {
  const std::vector<Candidate>* candidates;
  std::vector<Candidate>* near;
  double rho = 0;  // [m]
  const ContactOptions* options;
  std::vector<PathPoint>* out;

  void Select() {
    near->clear();
    // a little slack for rounding: keeping one shape too many changes nothing
    for (const Candidate& c : *candidates) {
      const double bound = (c.reach + rho) * (1 + 1e-9) + 1e-12;
      if (c.distance2 <= bound * bound) near->push_back(c);
    }
  }
};

void Refine(const PathPoint& a, const PathPoint& b, Bend* bend, int depth) {
  if (depth <= 0) return;
  const ContactOptions& options = *bend->options;
  const Eigen::Vector3d ab = b.position - a.position;
  const double len = ab.norm();
  // taken now, while the crossing is searched for: the detour direction then waits on a product
  const double inverse_len = 1 / len;
  // a segment may touch the bodies its routed ends sit on; points inserted by contact exclude none
  const Crossing c =
      FirstCrossing(a.position, b.position, ab, len, *bend->near, a.contact ? -2 : a.body,
                    b.contact ? -2 : b.body, options.margin);
  if (c.shape == nullptr) return;
  const WorldShape& shape = *c.shape;
  if (len < 1e-12) return;
  const Eigen::Vector3d mid = a.position + ab * ((c.t_in + c.t_out) / 2);
  const Eigen::Vector3d u = ab * inverse_len;
  Eigen::Vector3d away;
  if (const auto* plane = std::get_if<sgal::Plane>(shape.geometry)) {
    // out of a half-space along its normal
    away = shape.pose.linear() * plane->normal;
    away.normalize();
  } else {
    // perpendicular to the segment, away from the shape's centre
    const Eigen::Vector3d centre = shape.pose.translation();
    away = (mid - centre) - u * u.dot(mid - centre);
    const double norm = away.norm();
    if (norm < 1e-9) {
      away = u.unitOrthogonal().normalized();  // through the centre: any perpendicular
    } else {
      away /= norm;
    }
  }
  // where the ray from the middle of the chord along `away` leaves the shape (grown by margin)
  const double reach = 10 * len + 1.0;
  const auto exit = SegmentInside(shape, mid, mid + away * reach, options.margin);
  if (exit && exit->second >= 1.0) return;  // no way out along that direction: leave it straight
  PathPoint q;
  q.position = mid + away * ((exit ? exit->second : 0.0) * reach + 1e-9);
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
    const auto i = SegmentInside(*plane, a, b, margin);
    if (i && i->second - i->first > 1e-9) return false;
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
    shapes.clear();
    const double pad = options.margin + options.detour_reach;
    query(a.position, b.position, pad, &shapes);
    candidates.clear();
    const Eigen::Vector3d ab = b.position - a.position;
    const double l2 = ab.squaredNorm();
    // the distances only choose which shapes are tested (with slack): a product will do for the
    // division
    const double inverse_l2 = l2 > 0 ? 1 / l2 : 0.0;
    for (const WorldShape* shape : shapes) {
      const double radius = shape->bounding_radius >= 0 ? shape->bounding_radius
                                                        : sgal::BoundingRadius(*shape->geometry);
      const double reach = radius + options.margin;
      const Eigen::Vector3d centre = shape->pose.translation();
      const double t = std::clamp((centre - a.position).dot(ab) * inverse_l2, 0.0, 1.0);
      const double distance2 = (a.position + t * ab - centre).squaredNorm();
      candidates.push_back({centre, reach * reach, reach, distance2, shape->body, shape});
    }
    if (memory != nullptr) {
      // shapes the query left out lie farther than `pad` from the segment's box; those it gave
      // are remembered one by one (a shape's own travel is then enough for it)
      double clearance = options.detour_reach;
      ContactMemory::Segment& s = memory->segments[i];
      s.planes.clear();
      s.near.clear();
      for (const Candidate& c : candidates) {
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
  for (size_t i = 0; i + 1 < out.size(); ++i)
    bent += (out[i + 1].position - out[i].position).norm();
  path->length += bent - straight;
  // the straight path's buffer becomes the next call's
  std::swap(path->points, out);
  return inserted;
}

}  // namespace caliper::actuators
