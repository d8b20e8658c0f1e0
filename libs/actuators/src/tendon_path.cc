#include "caliper/actuators/tendon_path.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace caliper::actuators {

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Kind = sgal::PathElement::Kind;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTiny = 1e-12;        // lengths below this count as zero [m]
constexpr double kArcStep = kPi / 12;  // spacing of the arc samples in the polyline [rad]

double Cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

Vector2d Rotate2(const Vector2d& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return Vector2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

// angle swept from direction a to direction b turning counterclockwise (turn = +1) or
// clockwise (turn = -1), in [0, 2 pi)
double SweptAngle(const Vector2d& a, const Vector2d& b, int turn) {
  double angle = std::atan2(Cross2(a, b), a.dot(b));
  if (turn < 0) angle = -angle;
  if (angle < 0) angle += 2 * kPi;
  return angle;
}

// one way around the circle (radius r, at the origin) from a to b, both outside the circle;
// turn +1: the path turns counterclockwise about the circle, -1 clockwise
struct CircleRoute {
  Vector2d t0 = Vector2d::Zero();  // tangent point seen from a [m]
  Vector2d t1 = Vector2d::Zero();  // tangent point seen from b [m]
  double angle = 0;                // arc angle [rad]
  bool valid = false;              // false: the two tangent lines cross (the string lifts off)
};

CircleRoute Route(const Vector2d& a, const Vector2d& b, double r, int turn) {
  const double la = a.norm(), lb = b.norm();
  const double beta_a = std::acos(std::clamp(r / la, -1.0, 1.0));
  const double beta_b = std::acos(std::clamp(r / lb, -1.0, 1.0));
  CircleRoute route;
  route.t0 = r * Rotate2(a / la, turn * beta_a);
  route.t1 = r * Rotate2(b / lb, -turn * beta_b);
  // the arc is what remains of the swept angle after the two tangent lines
  const double angle = SweptAngle(a, b, turn) - beta_a - beta_b;
  route.valid = angle >= 0;
  route.angle = std::max(angle, 0.0);
  return route;
}

// point on the segment a-b nearest to the origin
Vector2d NearestOnSegment(const Vector2d& a, const Vector2d& b) {
  const Vector2d dif = b - a;
  const double dd = dif.squaredNorm();
  const double u = dd > 0 ? std::clamp(-a.dot(dif) / dd, 0.0, 1.0) : 0.0;
  return a + u * dif;
}

// side point inside the circle: the string is drawn toward the centre until it touches the circle
// at one point t, where it reflects (equal angles with the normal, the stationary point of
// |a - t| + |t - b|). With alpha, beta the angles at the centre between t and a, b and z the sine
// of the angle between the normal and either string: alpha = asin z - asin(z r / |a|), same for
// beta, and alpha + beta = the angle between a and b; the left side grows with z, solved by
// bisection. Empty when the string cannot touch (a point inside, or the segment already crosses).
std::optional<Vector2d> InsideTouch(const Vector2d& a, const Vector2d& b, double r) {
  const double la = a.norm(), lb = b.norm();
  if (la <= r || lb <= r || r <= 0) return std::nullopt;
  const Vector2d dif = b - a;
  const double dd = dif.squaredNorm();
  if (dd > kTiny * kTiny) {
    const double u = -a.dot(dif) / dd;
    if (u > 0 && u < 1 && (a + u * dif).norm() <= r) return std::nullopt;
  }
  const double cos_g = std::clamp(a.dot(b) / (la * lb), -1.0, 1.0);
  if (cos_g < -1 + 1e-12) return std::nullopt;
  const Vector2d fallback = r * (a / la + b / lb).normalized();
  const double g = std::acos(cos_g);
  const double ka = r / la, kb = r / lb;
  auto excess = [&](double z) {
    return 2 * std::asin(z) - std::asin(ka * z) - std::asin(kb * z) - g;
  };
  if (g < 1e-12 || excess(1.0) <= 0) return fallback;
  double lo = 0, hi = 1;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) < 0 ? lo : hi) = mid;
  }
  const double z = 0.5 * (lo + hi);
  if (Cross2(a, b) > 0) return r * Rotate2(a / la, std::asin(z) - std::asin(ka * z));
  return r * Rotate2(b / lb, std::asin(z) - std::asin(kb * z));
}

// outcome of one wrap element: the points on the obstacle in world coordinates (tangent point,
// arc samples, tangent point; a single point for an inside wrap) and the length along it
struct WrapOutcome {
  bool wraps = false;
  std::vector<Vector3d> points;
  double length = 0;  // [m]
};

// 2-D frame of the wrap in the obstacle frame: the plane through the centre and both points for a
// sphere, the plane normal to the axis for a cylinder
struct WrapFrame {
  Vector3d e0 = Vector3d::UnitX();
  Vector3d e1 = Vector3d::UnitY();
};

// a plane normal's sign is fixed by a reference direction (first non-zero of z, y, x positive),
// so that "counterclockwise" keeps its meaning when the points pass through the centre's line
Vector3d OrientNormal(const Vector3d& n) {
  for (int i = 2; i >= 0; --i) {
    if (std::abs(n[i]) > 1e-12) return n[i] < 0 ? Vector3d(-n) : n;
  }
  return n;
}

// the plane through the sphere's centre and both points; when they are in line with the centre,
// the plane through the side point, else the one normal to the obstacle's z axis (or x axis)
WrapFrame SphereFrame(const Vector3d& q0, const Vector3d& q1, const std::optional<Vector3d>& s) {
  const double scale = q0.norm();
  Vector3d n = q0.cross(q1);
  if (n.norm() < 1e-12 * scale * q1.norm() && s) n = q0.cross(*s);
  if (n.norm() < 1e-12 * scale * (s ? s->norm() : q1.norm())) {
    const Vector3d e0 = q0 / scale;
    n = Vector3d::UnitZ() - e0.z() * e0;
    if (n.norm() < 1e-6) n = Vector3d::UnitX() - e0.x() * e0;
  }
  n = OrientNormal(n.normalized());
  WrapFrame f;
  f.e0 = q0 / scale;
  f.e1 = n.cross(f.e0).normalized();
  return f;
}

// MuJoCo's rules (mju_wrap, wrap_circle, wrap_inside), reproduced: a point inside the circle
// means no wrap; the string wraps when the straight segment crosses the circle, or, with a side
// point outside, when the segment's point nearest the centre lies on the far side from it; with a
// side point the route whose tangent points' mean direction is nearest the side point is taken;
// a side point inside the circle draws the string onto the circle at one point. Without a side
// point the shorter route is taken the first time, and `side` keeps it on later calls until the
// string lifts off, so that it does not jump sides when the obstacle crosses the straight line.
WrapOutcome WrapAround(const Vector3d& p0, const Vector3d& p1, const WorldElement& wrap,
                       int* side) {
  WrapOutcome out;
  const WorldObstacle& ob = wrap.obstacle;
  const double r = ob.radius;
  const Eigen::Isometry3d to_local = ob.pose.inverse();
  const Vector3d q0 = to_local * p0, q1 = to_local * p1;
  std::optional<Vector3d> s;
  if (wrap.side) s = to_local * *wrap.side;
  const bool cylinder = ob.kind == sgal::ObstacleKind::kCylinder;
  if (r <= 0 || q0.norm() < kTiny || q1.norm() < kTiny) {
    *side = 0;
    return out;
  }
  const WrapFrame f = cylinder ? WrapFrame{} : SphereFrame(q0, q1, s);
  const Vector2d a(q0.dot(f.e0), q0.dot(f.e1)), b(q1.dot(f.e0), q1.dot(f.e1));
  std::optional<Vector2d> sd;
  bool side_inside = false;
  if (s) {
    sd = Vector2d(s->dot(f.e0), s->dot(f.e1));
    side_inside = (cylinder ? sd->norm() : s->norm()) < r;
  }

  Vector2d t0, t1;
  double angle = 0;
  int turn = 0;
  if (side_inside) {
    const std::optional<Vector2d> t = InsideTouch(a, b, r);
    *side = 0;
    if (!t) return out;
    t0 = t1 = *t;
  } else {
    if (a.norm() < r || b.norm() < r || (b - a).squaredNorm() < kTiny * kTiny) {
      *side = 0;
      return out;
    }
    const Vector2d nearest = NearestOnSegment(a, b);
    const bool crosses = nearest.squaredNorm() <= r * r;
    const CircleRoute ccw = Route(a, b, r, +1), cw = Route(a, b, r, -1);
    const CircleRoute* chosen = nullptr;
    if (sd) {
      if (!crosses && sd->dot(nearest) >= 0) {
        *side = 0;
        return out;
      }
      auto goodness = [&](const CircleRoute& c) {
        const Vector2d mid = c.t0 + c.t1;
        return c.valid ? (mid.norm() > kTiny ? mid.normalized().dot(*sd) : 0.0) : -1e4;
      };
      turn = goodness(cw) > goodness(ccw) ? -1 : +1;
    } else if (*side != 0 && (*side > 0 ? ccw : cw).valid) {
      turn = *side;
    } else {
      if (!crosses) {
        *side = 0;
        return out;
      }
      turn = (cw.valid && (!ccw.valid || cw.angle < ccw.angle)) ? -1 : +1;
    }
    chosen = turn > 0 ? &ccw : &cw;
    if (!chosen->valid) {
      *side = 0;
      return out;
    }
    *side = turn;
    t0 = chosen->t0;
    t1 = chosen->t1;
    angle = chosen->angle;
  }

  // back to 3-D: the cylinder's axial coordinate grows in proportion to the unrolled length, which
  // makes the wrap a helix and the whole path a geodesic
  const double arc = r * angle;
  double z_t0 = 0, z_t1 = 0;
  if (cylinder) {
    const double l0 = (a - t0).norm(), l1 = (b - t1).norm(), total = l0 + arc + l1;
    const double rise = q1.z() - q0.z();
    z_t0 = q0.z() + (total > kTiny ? rise * l0 / total : 0.0);
    z_t1 = q0.z() + (total > kTiny ? rise * (l0 + arc) / total : 0.0);
  }
  auto to_world = [&](const Vector2d& p, double z) {
    Vector3d local = p.x() * f.e0 + p.y() * f.e1;
    if (cylinder) local.z() = z;
    return Vector3d(ob.pose * local);
  };
  out.wraps = true;
  out.length = cylinder ? std::hypot(arc, z_t1 - z_t0) : arc;
  out.points.push_back(to_world(t0, z_t0));
  if (turn == 0) return out;
  const int segments = std::max(1, static_cast<int>(std::ceil(angle / kArcStep - 1e-9)));
  for (int k = 1; k < segments; ++k) {
    const double u = static_cast<double>(k) / segments;
    out.points.push_back(to_world(Rotate2(t0, turn * angle * u), z_t0 + u * (z_t1 - z_t0)));
  }
  out.points.push_back(to_world(t1, z_t1));
  return out;
}

void CheckElements(const std::vector<WorldElement>& elements) {
  int points = 0;
  for (size_t i = 0; i < elements.size(); ++i) {
    if (elements[i].kind == Kind::kPoint) {
      ++points;
    } else if (i == 0 || i + 1 == elements.size() || elements[i - 1].kind != Kind::kPoint ||
               elements[i + 1].kind != Kind::kPoint) {
      throw std::invalid_argument("tendon path: wrap element " + std::to_string(i) +
                                  " must stand between two points");
    }
  }
  if (points < 2)
    throw std::invalid_argument("tendon path: needs at least two points, has " +
                                std::to_string(points));
}

}  // namespace

PathGeometry TendonPath::Evaluate(const std::vector<WorldElement>& elements) {
  PathGeometry path;
  Evaluate(elements, &path);
  return path;
}

void TendonPath::Evaluate(const std::vector<WorldElement>& elements, PathGeometry* out) {
  CheckElements(elements);
  if (wrap_side_.size() != elements.size()) wrap_side_.assign(elements.size(), 0);

  PathGeometry& path = *out;
  path.points.clear();
  path.length = 0;
  path.speed = 0;
  path.points.reserve(elements.size() + 16);
  // Each straight piece is measured as its end point is added: its length, and d/dt of length
  // (unit vector . relative velocity). The pieces along a surface between a wrap's points were
  // counted exactly by the wrap and add no speed: their ends are tangent points, where the
  // tangent lines' rate of change along the surface is zero to first order.
  Vector3d last_velocity = Vector3d::Zero();  // of the last point added
  bool along_surface = false;                 // whether the piece from the last point does
  auto add = [&](const Vector3d& p, const Vector3d& v, int body, double friction, bool on_wrap) {
    if (!path.points.empty() && !along_surface) {
      const Vector3d d = p - path.points.back().position;
      const double len = d.norm();
      path.length += len;
      if (len > kTiny) path.speed += d.dot(v - last_velocity) / len;
    }
    path.points.push_back(PathPoint{p, body, friction, on_wrap});
    last_velocity = v;
    along_surface = false;
  };

  for (size_t i = 0; i < elements.size(); ++i) {
    const WorldElement& e = elements[i];
    if (e.kind != Kind::kPoint) continue;
    if (i >= 2 && elements[i - 1].kind == Kind::kWrap) {
      const WorldElement& w = elements[i - 1];
      const WrapOutcome wrap = WrapAround(elements[i - 2].point, e.point, w, &wrap_side_[i - 1]);
      if (wrap.wraps) {
        // points on the obstacle move with it: the wrap element's velocity is the obstacle's
        // (its rotation is neglected, which is exact for spheres and for cylinders turning about
        // their own axis)
        for (size_t k = 0; k < wrap.points.size(); ++k) {
          add(wrap.points[k], w.velocity, w.body, 0, true);
          along_surface = k + 1 < wrap.points.size();
        }
        path.length += wrap.length;
      }
    }
    add(e.point, e.velocity, e.body, e.friction, false);
  }
}

std::vector<PointForce> PathForces(const PathGeometry& path, double tension) {
  std::vector<PointForce> forces;
  PathForces(path, tension, &forces);
  return forces;
}

void PathForces(const PathGeometry& path, double tension, std::vector<PointForce>* out) {
  const std::vector<PathPoint>& points = path.points;
  std::vector<PointForce>& forces = *out;
  forces.resize(points.size());
  EmitPathForces(points, path.speed, tension, [&](size_t k, const Vector3d& force) {
    forces[k].body = points[k].body;
    forces[k].position = points[k].position;
    forces[k].force = force;
  });
}

}  // namespace caliper::actuators
