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
  const double l2 = ab.squaredNorm();
  const double len = std::sqrt(l2);
  const double inverse_l2 = l2 > 0 ? 1 / l2 : 0.0;
  // a segment may touch the bodies its routed ends sit on; points inserted by contact exclude none
  const Crossing c = FirstCrossing(a.position, ab, l2, *bend->near, a.contact ? -2 : a.body,
                                   b.contact ? -2 : b.body, options.margin);
  if (c.shape == nullptr) return;
  const WorldShape& shape = *c.shape;
  if (len < 1e-12) return;
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
    Eigen::Vector3d away = c.p - c.d * (c.d.dot(c.p) * inverse_l2);
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
