#include "caliper/sgal/edits.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "caliper/core/ids.h"

namespace caliper::sgal {

namespace {

[[noreturn]] void Refuse(const std::string& what) { throw EditError(what); }

Tendon& TendonIn(Scene& s, const std::string& name) {
  for (auto& t : s.tendons)
    if (t.name == name) return t;
  Refuse("no tendon '" + name + "'");
}

const Tendon& TendonIn(const Scene& s, const std::string& name) {
  return TendonIn(const_cast<Scene&>(s), name);
}

Body& BodyIn(Scene& s, const std::string& name) {
  for (auto& b : s.bodies)
    if (b.name == name) return b;
  Refuse("no body '" + name + "'");
}

const Body& BodyIn(const Scene& s, const std::string& name) {
  return BodyIn(const_cast<Scene&>(s), name);
}

// a value in a refusal as a user typed it: 20, 0.02, 1e+06, nan (std::to_string gives 20.000000)
std::string Number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string Mm(const Eigen::Vector3d& p) {
  std::ostringstream out;
  out.precision(4);
  out << p.x() * 1000 << " " << p.y() * 1000 << " " << p.z() * 1000 << " mm";
  return out.str();
}

// a point element's body must exist (or be the world) and its position be finite
void CheckPoint(const Scene& s, const PathElement& e, const std::string& where) {
  if (e.kind == PathElement::Kind::kPoint) {
    if (!e.body.empty() && s.FindBody(e.body) == nullptr)
      Refuse(where + ": no body '" + e.body + "'");
    if (!e.position.allFinite()) Refuse(where + ": the position is not finite");
    if (!(e.friction >= 0) || !std::isfinite(e.friction))
      Refuse(where + ": the capstan friction must be finite and >= 0");
  } else if (s.FindObstacle(e.obstacle) == nullptr) {
    Refuse(where + ": no obstacle '" + e.obstacle + "'");
  }
}

std::string ElementName(const PathElement& e) {
  return e.kind == PathElement::Kind::kWrap ? "wrap around '" + e.obstacle + "'"
                                            : "point in " + (e.body.empty() ? std::string("the world")
                                                                            : "'" + e.body + "'");
}

size_t CountPoints(const Tendon& t) {
  return static_cast<size_t>(std::count_if(t.path.begin(), t.path.end(), [](const PathElement& e) {
    return e.kind == PathElement::Kind::kPoint;
  }));
}

}  // namespace

std::vector<double> GeometryDims(const Geometry& g) {
  struct Visitor {
    std::vector<double> operator()(const Box& b) const { return {b.size.x(), b.size.y(), b.size.z()}; }
    std::vector<double> operator()(const Sphere& s) const { return {s.radius}; }
    std::vector<double> operator()(const Capsule& c) const { return {c.radius, c.length}; }
    std::vector<double> operator()(const Cylinder& c) const { return {c.radius, c.length}; }
    std::vector<double> operator()(const Cone& c) const { return {c.radius, c.length}; }
    std::vector<double> operator()(const Plane& p) const {
      return {p.normal.x(), p.normal.y(), p.normal.z(), p.offset};
    }
    std::vector<double> operator()(const ConvexHull&) const { return {}; }
    std::vector<double> operator()(const TriangleMesh&) const { return {}; }
  };
  return std::visit(Visitor{}, g);
}

Geometry WithDims(const Geometry& g, const std::vector<double>& dims) {
  const std::vector<double> now = GeometryDims(g);
  const std::string kind = GeometryName(g);
  if (now.empty()) Refuse("a " + kind + " has no dimensions to set (edit its mesh in the file)");
  if (dims.size() != now.size())
    Refuse("a " + kind + " takes " + std::to_string(now.size()) + " dimensions, not " +
           std::to_string(dims.size()));
  for (double d : dims)
    if (!std::isfinite(d)) Refuse("the " + kind + "'s dimensions must be finite");
  Geometry out = g;
  if (auto* p = std::get_if<Plane>(&out)) {
    const Eigen::Vector3d n(dims[0], dims[1], dims[2]);
    if (n.norm() < 1e-9) Refuse("a plane's normal must not be zero");
    p->normal = n.normalized();
    p->offset = dims[3];
    return out;
  }
  // every other primitive: lengths, and at most 1 km (a typo in mm would give 1000 times)
  for (double d : dims)
    if (!(d > 0) || d > 1000)
      Refuse("the " + kind + "'s dimensions must be lengths in (0, 1000] m, not " + Number(d));
  if (auto* b = std::get_if<Box>(&out)) b->size = {dims[0], dims[1], dims[2]};
  if (auto* s = std::get_if<Sphere>(&out)) s->radius = dims[0];
  if (auto* c = std::get_if<Capsule>(&out)) *c = {dims[0], dims[1]};
  if (auto* c = std::get_if<Cylinder>(&out)) *c = {dims[0], dims[1]};
  if (auto* c = std::get_if<Cone>(&out)) *c = {dims[0], dims[1]};
  return out;
}

SceneEdit MovePathPoint(const Scene& scene, const std::string& tendon, size_t index,
                        const PathElement& to) {
  const Tendon& t = TendonIn(scene, tendon);
  const std::string where = "tendon '" + tendon + "' path element " + std::to_string(index);
  if (index >= t.path.size())
    Refuse(where + ": the path has " + std::to_string(t.path.size()) + " elements");
  const PathElement before = t.path[index];
  if (before.kind != PathElement::Kind::kPoint)
    Refuse(where + " is a wrap around '" + before.obstacle +
           "': move the obstacle (set_obstacle) instead");
  if (to.kind != PathElement::Kind::kPoint) Refuse(where + ": a point moves to a point");
  CheckPoint(scene, to, where);
  PathElement after = before;
  after.body = to.body;
  after.position = to.position;
  auto set = [tendon, index](const PathElement& e) {
    return [tendon, index, e](Scene& s) {
      Tendon& edited = TendonIn(s, tendon);
      if (index >= edited.path.size())
        Refuse("tendon '" + tendon + "' has no path element " + std::to_string(index));
      edited.path[index] = e;
    };
  };
  return {"move " + (index == 0 || index + 1 == t.path.size() ? std::string("attachment ")
                                                              : std::string("via point ")) +
              std::to_string(index) + " of " + tendon + " to " + Mm(to.position) +
              (to.body.empty() ? " in the world" : " in " + to.body),
          set(after), set(before)};
}

SceneEdit InsertPathPoint(const Scene& scene, const std::string& tendon, size_t index,
                          const PathElement& element) {
  const Tendon& t = TendonIn(scene, tendon);
  const std::string where = "tendon '" + tendon + "' insert before element " + std::to_string(index);
  if (index == 0 || index >= t.path.size())
    Refuse(where + ": a via point goes between the two ends (1 to " +
           std::to_string(t.path.size() - 1) + ")");
  CheckPoint(scene, element, where);
  auto insert = [tendon, index, element](Scene& s) {
    Tendon& edited = TendonIn(s, tendon);
    if (index > edited.path.size()) Refuse("tendon '" + tendon + "' is shorter than before");
    edited.path.insert(edited.path.begin() + static_cast<long>(index), element);
  };
  auto remove = [tendon, index](Scene& s) {
    Tendon& edited = TendonIn(s, tendon);
    if (index >= edited.path.size()) Refuse("tendon '" + tendon + "' is shorter than before");
    edited.path.erase(edited.path.begin() + static_cast<long>(index));
  };
  return {"insert " + ElementName(element) + " at " + std::to_string(index) + " of " + tendon,
          insert, remove};
}

SceneEdit RemovePathPoint(const Scene& scene, const std::string& tendon, size_t index) {
  const Tendon& t = TendonIn(scene, tendon);
  const std::string where = "tendon '" + tendon + "' path element " + std::to_string(index);
  if (index >= t.path.size())
    Refuse(where + ": the path has " + std::to_string(t.path.size()) + " elements");
  if (index == 0 || index + 1 == t.path.size())
    Refuse(where + " is an end of the tendon: move it, or remove the tendon");
  const PathElement removed = t.path[index];
  if (removed.kind == PathElement::Kind::kPoint && CountPoints(t) <= 2)
    Refuse(where + ": a tendon keeps at least two points");
  SceneEdit inverse = InsertPathPoint(scene, tendon, index, removed);
  return {"remove " + ElementName(removed) + " " + std::to_string(index) + " of " + tendon,
          inverse.revert, inverse.apply};
}

SceneEdit AddTendon(const Scene& scene, const Tendon& tendon, const Actuator& actuator) {
  if (tendon.name.empty()) Refuse("a new tendon needs a name");
  if (actuator.name.empty()) Refuse("the new tendon's actuator needs a name");
  if (scene.FindTendon(tendon.name) != nullptr) Refuse("a tendon '" + tendon.name + "' exists");
  for (const auto& a : scene.actuators)
    if (a.name == actuator.name) Refuse("an actuator '" + actuator.name + "' exists");
  if (tendon.path.size() < 2) Refuse("tendon '" + tendon.name + "' needs two points");
  for (size_t i = 0; i < tendon.path.size(); ++i)
    CheckPoint(scene, tendon.path[i], "tendon '" + tendon.name + "' element " + std::to_string(i));
  if (!(tendon.radius > 0) || tendon.radius > 0.1)
    Refuse("tendon '" + tendon.name + "': radius must be in (0, 0.1] m");
  Actuator a = actuator;
  a.tendon = tendon.name;
  auto add = [tendon, a](Scene& s) {
    s.tendons.push_back(tendon);
    s.actuators.push_back(a);
  };
  auto remove = [name = tendon.name, actuator = a.name](Scene& s) {
    s.tendons.erase(std::remove_if(s.tendons.begin(), s.tendons.end(),
                                   [&](const Tendon& t) { return t.name == name; }),
                    s.tendons.end());
    s.actuators.erase(std::remove_if(s.actuators.begin(), s.actuators.end(),
                                     [&](const Actuator& x) { return x.name == actuator; }),
                      s.actuators.end());
  };
  return {"add tendon " + tendon.name + " with " + a.kind + " " + a.name, add, remove};
}

SceneEdit RemoveTendon(const Scene& scene, const std::string& tendon) {
  TendonIn(scene, tendon);
  // what goes: the tendon, its actuators, and the measurement delays of their channels
  // (`<tendon>.tendon.*`, `<actuator>.*`, as engines name them), each put back in place on revert
  std::vector<std::string> owners = {tendon + ".tendon."};
  std::vector<std::pair<size_t, Actuator>> actuators;
  for (size_t i = 0; i < scene.actuators.size(); ++i)
    if (scene.actuators[i].tendon == tendon) {
      actuators.emplace_back(i, scene.actuators[i]);
      owners.push_back(scene.actuators[i].name + ".");
    }
  auto orphaned = [owners](const MeasurementDelay& d) {
    return std::any_of(owners.begin(), owners.end(), [&](const std::string& prefix) {
      return d.id.compare(0, prefix.size(), prefix) == 0;
    });
  };
  std::vector<std::pair<size_t, MeasurementDelay>> delays;
  for (size_t i = 0; i < scene.measurement_delays.size(); ++i)
    if (orphaned(scene.measurement_delays[i])) delays.emplace_back(i, scene.measurement_delays[i]);
  auto remove = [tendon, orphaned](Scene& s) {
    TendonIn(s, tendon);
    s.tendons.erase(std::remove_if(s.tendons.begin(), s.tendons.end(),
                                   [&](const Tendon& t) { return t.name == tendon; }),
                    s.tendons.end());
    s.actuators.erase(std::remove_if(s.actuators.begin(), s.actuators.end(),
                                     [&](const Actuator& a) { return a.tendon == tendon; }),
                      s.actuators.end());
    auto& d = s.measurement_delays;
    d.erase(std::remove_if(d.begin(), d.end(), orphaned), d.end());
  };
  size_t at = 0;
  while (scene.tendons[at].name != tendon) ++at;
  const Tendon removed = scene.tendons[at];
  auto restore = [removed, at, actuators, delays](Scene& s) {
    s.tendons.insert(s.tendons.begin() + static_cast<long>(std::min(at, s.tendons.size())), removed);
    for (const auto& [i, a] : actuators)
      s.actuators.insert(s.actuators.begin() + static_cast<long>(std::min(i, s.actuators.size())), a);
    auto& d = s.measurement_delays;
    for (const auto& [i, m] : delays)
      d.insert(d.begin() + static_cast<long>(std::min(i, d.size())), m);
  };
  std::string what = "remove tendon " + tendon + (actuators.empty() ? "" : " and its actuators");
  if (!delays.empty()) what += " (and " + std::to_string(delays.size()) + " measurement delays)";
  return {what, remove, restore};
}

SceneEdit SetObstacle(const Scene& scene, const WrapObstacle& obstacle) {
  const std::string where = "obstacle '" + obstacle.name + "'";
  if (obstacle.name.empty()) Refuse("an obstacle needs a name");
  if (!obstacle.body.empty() && scene.FindBody(obstacle.body) == nullptr)
    Refuse(where + ": no body '" + obstacle.body + "'");
  if (!(obstacle.radius > 0) || obstacle.radius > 10)
    Refuse(where + ": radius must be in (0, 10] m, not " + std::to_string(obstacle.radius));
  if (obstacle.kind == ObstacleKind::kCylinder && (!(obstacle.length > 0) || obstacle.length > 10))
    Refuse(where + ": a cylinder's length must be in (0, 10] m, not " +
           std::to_string(obstacle.length));
  if (!obstacle.pose.position.allFinite() || !obstacle.pose.orientation.coeffs().allFinite() ||
      std::abs(obstacle.pose.orientation.norm() - 1) > 1e-6)
    Refuse(where + ": the pose needs a finite position and a unit quaternion");
  const WrapObstacle* old = scene.FindObstacle(obstacle.name);
  auto put = [](const WrapObstacle& o) {
    return [o](Scene& s) {
      for (auto& x : s.obstacles)
        if (x.name == o.name) {
          x = o;
          return;
        }
      s.obstacles.push_back(o);
    };
  };
  if (old != nullptr) {
    if (old->body != obstacle.body)
      Refuse(where + " is fixed in '" + old->body + "': an obstacle stays in its body");
    return {"move and resize obstacle " + obstacle.name, put(obstacle), put(*old)};
  }
  auto remove = [name = obstacle.name](Scene& s) {
    s.obstacles.erase(std::remove_if(s.obstacles.begin(), s.obstacles.end(),
                                     [&](const WrapObstacle& o) { return o.name == name; }),
                      s.obstacles.end());
  };
  return {"add obstacle " + obstacle.name, put(obstacle), remove};
}

SceneEdit RemoveObstacle(const Scene& scene, const std::string& obstacle) {
  const WrapObstacle* old = scene.FindObstacle(obstacle);
  if (old == nullptr) Refuse("no obstacle '" + obstacle + "'");
  for (const auto& t : scene.tendons)
    for (const auto& e : t.path)
      if (e.kind == PathElement::Kind::kWrap && e.obstacle == obstacle)
        Refuse("obstacle '" + obstacle + "': tendon '" + t.name +
               "' wraps around it; remove that wrap first");
  const WrapObstacle kept = *old;
  size_t at = 0;
  while (scene.obstacles[at].name != obstacle) ++at;
  auto remove = [obstacle](Scene& s) {
    s.obstacles.erase(std::remove_if(s.obstacles.begin(), s.obstacles.end(),
                                     [&](const WrapObstacle& o) { return o.name == obstacle; }),
                      s.obstacles.end());
  };
  auto restore = [kept, at](Scene& s) {
    s.obstacles.insert(s.obstacles.begin() + static_cast<long>(std::min(at, s.obstacles.size())),
                       kept);
  };
  return {"remove obstacle " + obstacle, remove, restore};
}

SceneEdit SetShapeDims(const Scene& scene, const std::string& body, size_t index,
                       const std::vector<double>& dims) {
  const Body& b = BodyIn(scene, body);
  if (index >= b.shapes.size())
    Refuse("body '" + body + "' has " + std::to_string(b.shapes.size()) + " shapes, no shape " +
           std::to_string(index));
  const Geometry before = b.shapes[index].geometry;
  Geometry after;
  try {
    after = WithDims(before, dims);
  } catch (const EditError& e) {
    Refuse("body '" + body + "' shape " + std::to_string(index) + ": " + e.what());
  }
  const Pose pose = b.shapes[index].pose;
  // visuals drawn from the same geometry at the same place follow the shape
  std::vector<size_t> visuals;
  for (size_t v = 0; v < b.visuals.size(); ++v) {
    const Visual& vis = b.visuals[v];
    if (vis.geometry.index() == before.index() && GeometryDims(vis.geometry) == GeometryDims(before) &&
        (vis.pose.position - pose.position).norm() < 1e-9 &&
        vis.pose.orientation.angularDistance(pose.orientation) < 1e-9)
      visuals.push_back(v);
  }
  auto set = [body, index, visuals](const Geometry& g) {
    return [body, index, visuals, g](Scene& s) {
      Body& edited = BodyIn(s, body);
      if (index >= edited.shapes.size()) Refuse("body '" + body + "' has fewer shapes than before");
      edited.shapes[index].geometry = g;
      for (size_t v : visuals)
        if (v < edited.visuals.size()) edited.visuals[v].geometry = g;
    };
  };
  std::ostringstream dims_text;
  for (double d : dims) dims_text << " " << d;
  return {"set " + std::string(GeometryName(before)) + " " + std::to_string(index) + " of " + body +
              " to" + dims_text.str() + " m",
          set(after), set(before)};
}

SceneEdit SetMass(const Scene& scene, const std::string& body, double mass_kg) {
  const Body& b = BodyIn(scene, body);
  if (b.type != BodyType::kDynamic) Refuse("body '" + body + "' does not move: it has no mass");
  if (!(mass_kg > 0) || !std::isfinite(mass_kg) || mass_kg > 1e6)
    Refuse("body '" + body + "': mass must be in (0, 1e6] kg, not " + std::to_string(mass_kg));
  const Inertia before = b.inertia;
  Inertia after = before;
  after.mass = mass_kg;
  after.tensor = before.tensor * (mass_kg / before.mass);  // same shape, same density everywhere
  auto set = [body](const Inertia& in) {
    return [body, in](Scene& s) { BodyIn(s, body).inertia = in; };
  };
  std::ostringstream text;
  text << "set the mass of " << body << " to " << mass_kg << " kg";
  return {text.str(), set(after), set(before)};
}

SceneEdit SetMeasurementDelay(const Scene& scene, const std::string& channel, double delay_s) {
  // the id as the model file names it, or as the DAQ lists it (after the scene's id-safe name:
  // ecce_arm.elbow.position in a scene named "ECCE Arm")
  const std::string prefix = core::IdSafe(scene.name) + ".";
  const std::string id = channel.rfind(prefix, 0) == 0 ? channel.substr(prefix.size()) : channel;
  if (id.empty()) Refuse("a measurement delay needs a channel id");
  if (!std::isfinite(delay_s) || delay_s < 0 || delay_s > 10)
    Refuse("measurement delay of '" + id + "': delay must be in [0, 10] s, not " +
           Number(delay_s));
  const auto& delays = scene.measurement_delays;
  const auto found = std::find_if(delays.begin(), delays.end(),
                                  [&](const MeasurementDelay& d) { return d.id == id; });
  // the delay `d` of `id` (0: none), at its place in the list when it had one
  const size_t at = static_cast<size_t>(found - delays.begin());
  auto put = [id, at](double d) {
    return [id, at, d](Scene& s) {
      auto& list = s.measurement_delays;
      list.erase(std::remove_if(list.begin(), list.end(),
                                [&](const MeasurementDelay& m) { return m.id == id; }),
                 list.end());
      if (d > 0) list.insert(list.begin() + static_cast<long>(std::min(at, list.size())), {id, d});
    };
  };
  const double before = found == delays.end() ? 0.0 : found->delay;
  if (delay_s == 0 && before == 0) Refuse("channel '" + id + "' has no measurement delay");
  std::ostringstream text;
  if (delay_s == 0)
    text << "remove the measurement delay of " << id;
  else
    text << "delay " << id << " by " << delay_s * 1e3 << " ms";
  return {text.str(), put(delay_s), put(before)};
}

}  // namespace caliper::sgal
