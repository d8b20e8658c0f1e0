#include "tree_model.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

namespace caliper::bench {

namespace {

using Eigen::Vector3d;

constexpr double kRadius = 0.03;   // capsule radius [m]
constexpr double kSegment = 0.1;   // distance between joints [m]

/// One body of the tree: where its centre is, the axis it extends along, its parent, hinge axis.
struct Link {
  std::string name;
  Vector3d centre;
  Vector3d along;      // unit, direction from the parent joint to this body's far end
  int parent;          // -1: root
  Vector3d joint;      // world position of the hinge to the parent
  Vector3d axis;       // hinge axis
};

std::vector<Link> Links(int bodies) {
  const int spine = bodies / 2, arm = bodies / 4;
  const int shoulder_body = spine - 3;  // spine body the arms hang from
  std::vector<Link> links;
  for (int i = 0; i < spine; ++i) {
    Link l;
    l.name = "spine" + std::to_string(i);
    l.along = Vector3d::UnitZ();
    l.centre = Vector3d(0, 0, 0.5 + kSegment * (i + 0.5));
    l.parent = i - 1;
    l.joint = Vector3d(0, 0, 0.5 + kSegment * i);
    l.axis = i % 2 ? Vector3d::UnitX() : Vector3d::UnitY();
    links.push_back(l);
  }
  for (int side : {-1, 1}) {
    for (int i = 0; i < arm; ++i) {
      Link l;
      l.name = std::string(side < 0 ? "left" : "right") + std::to_string(i);
      l.along = Vector3d(side, 0, 0);
      const Vector3d shoulder = links[shoulder_body].centre + Vector3d(side * kRadius, 0, 0);
      l.joint = shoulder + l.along * (kSegment * i);
      l.centre = l.joint + l.along * (kSegment / 2);
      l.parent = i == 0 ? shoulder_body : static_cast<int>(links.size()) - 1;
      l.axis = i % 2 ? Vector3d::UnitZ() : Vector3d::UnitY();
      links.push_back(l);
    }
  }
  return links;
}

/// A unit vector perpendicular to both the hinge axis and the link: where the tendons sit.
Vector3d Lever(const Link& l) { return l.axis.cross(l.along).normalized(); }

struct TendonSpec {
  std::string name;
  int body_a, body_b;
  Vector3d point_a, point_b;  // world positions at rest
};

std::vector<TendonSpec> Tendons(const std::vector<Link>& links, bool spanning, int count) {
  const int spine = static_cast<int>(links.size()) / 2, arm = static_cast<int>(links.size()) / 4;
  std::vector<TendonSpec> tendons;
  for (size_t c = 1; c < links.size(); ++c) {
    const Link& child = links[c];
    int from = child.parent;
    // spanning tendons start one body further up, so they cross the parent body
    if (spanning && links[from].parent >= 0) from = links[from].parent;
    const double offset = spanning ? 0.6 * kRadius : 1.5 * kRadius;
    for (int sign : {-1, 1}) {
      TendonSpec t;
      t.name = "t" + std::to_string(c) + (sign < 0 ? "a" : "b");
      t.body_a = from;
      t.body_b = static_cast<int>(c);
      const Vector3d lever = Lever(child) * (sign * offset);
      t.point_a = links[from].centre + lever;
      t.point_b = child.centre + lever;
      tendons.push_back(t);
    }
  }
  // two long tendons from the spine's base to the arm tips make 80
  for (int side : {0, 1}) {
    TendonSpec t;
    t.name = side ? "right_long" : "left_long";
    t.body_a = 0;
    t.body_b = spine + arm * side + arm - 1;
    t.point_a = links[0].centre + Vector3d(side ? 0.04 : -0.04, 0, 0);
    t.point_b = links[t.body_b].centre + Vector3d(0, 0, 0.04);
    tendons.push_back(t);
  }
  // more: the same again on levers turned about each body's axis; fewer: the first ones
  const std::vector<TendonSpec> base = tendons;
  for (int copy = 1; static_cast<int>(tendons.size()) < count; ++copy)
    for (const TendonSpec& b : base) {
      if (static_cast<int>(tendons.size()) >= count) break;
      TendonSpec t = b;
      t.name += "_" + std::to_string(copy);
      const double turn = 0.35 * copy;  // [rad] about the child's axis
      const Link& child = links[t.body_b];
      const Eigen::AngleAxisd r(turn, child.along);
      t.point_a = links[t.body_a].centre + r * (b.point_a - links[t.body_a].centre);
      t.point_b = child.centre + r * (b.point_b - child.centre);
      tendons.push_back(t);
    }
  tendons.resize(std::min<size_t>(tendons.size(), static_cast<size_t>(count)));
  return tendons;
}

Eigen::Quaterniond ZTo(const Vector3d& v) {
  return Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), v);
}

const Vector3d kBase(0, 0, 0.5);  // where the spine starts: the tilts' pivot [m]

}  // namespace

Eigen::Quaterniond StartTilt(int start) {
  if (start <= 0) return Eigen::Quaterniond::Identity();
  const double azimuth = 2 * M_PI * (start - 1) / (kStarts - 1);
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(kStartTilt, Vector3d(std::cos(azimuth), std::sin(azimuth), 0)));
}

sgal::Scene MakeTree(const TreeOptions& options) {
  sgal::Scene s;
  s.name = "tree40";
  const auto links = Links(options.bodies);
  const uint32_t mask = options.self_contact ? 0xffffffffu : 0x2u;  // 2: the floor's group
  for (const auto& l : links) {
    sgal::Body b;
    b.name = l.name;
    // the whole tree turned rigidly: the frames, tensors and attachments in the bodies' frames
    // stay as they are
    const Eigen::Quaterniond tilt = StartTilt(options.start);
    b.pose.position = kBase + tilt * (l.centre - kBase);
    b.pose.orientation = tilt;
    b.inertia.mass = 0.2;
    const double ia = 0.5 * 0.2 * kRadius * kRadius;
    const double ib = 0.2 * (3 * kRadius * kRadius + kSegment * kSegment) / 12;
    const Eigen::Matrix3d r = ZTo(l.along).toRotationMatrix();
    b.inertia.tensor = r * Vector3d(ib, ib, ia).asDiagonal() * r.transpose();
    sgal::Shape shape{"capsule", sgal::Capsule{kRadius, kSegment - 2 * kRadius}, {}};
    shape.pose.orientation = ZTo(l.along);
    shape.group = 1;
    shape.mask = mask;
    b.shapes.push_back(shape);
    s.bodies.push_back(b);
  }
  if (options.floor) {
    sgal::Body floor;
    floor.name = "floor";
    floor.type = sgal::BodyType::kStatic;
    sgal::Shape plane{"ground", sgal::Plane{}, {}};
    plane.group = 2;
    floor.shapes.push_back(plane);
    s.bodies.push_back(floor);
  }
  for (size_t c = 1; c < links.size(); ++c) {
    const Link& l = links[c];
    sgal::Constraint h;
    h.name = "j" + std::to_string(c);
    h.body_a = links[l.parent].name;
    h.body_b = l.name;
    const Eigen::Quaterniond axis = ZTo(l.axis);
    h.frame_a.position = l.joint - links[l.parent].centre;
    h.frame_a.orientation = axis;
    h.frame_b.position = l.joint - l.centre;
    h.frame_b.orientation = axis;
    s.constraints.push_back(h);
  }
  for (const auto& t : Tendons(links, options.spanning_tendons, options.tendons)) {
    sgal::Tendon tendon;
    tendon.name = t.name;
    tendon.radius = 0.002;
    sgal::PathElement a, b;
    a.body = links[t.body_a].name;
    a.position = t.point_a - links[t.body_a].centre;
    b.body = links[t.body_b].name;
    b.position = t.point_b - links[t.body_b].centre;
    tendon.path = {a, b};
    s.tendons.push_back(tendon);
    sgal::Actuator act;
    act.name = "m_" + t.name;
    act.kind = options.actuator_kind;
    act.tendon = t.name;
    s.actuators.push_back(act);
  }
  return s;
}

std::string MakeTreeMjcf(const TreeOptions& options) {
  const auto links = Links(options.bodies);
  std::ostringstream x;
  x << "<mujoco model=\"tree40\">\n<option timestep=\"0.001\"/>\n<worldbody>\n";
  if (options.floor) x << "<geom name=\"floor\" type=\"plane\" size=\"10 10 .1\" contype=\"2\" conaffinity=\"1\"/>\n";
  // nested bodies: write each link, children inside
  std::function<void(int)> write = [&](int i) {
    const Link& l = links[i];
    const Eigen::Quaterniond tilt = StartTilt(options.start);
    const Vector3d rel = l.parent < 0 ? Vector3d(kBase + tilt * (l.centre - kBase))
                                      : Vector3d(l.centre - links[l.parent].centre);
    x << "<body name=\"" << l.name << "\" pos=\"" << rel.x() << " " << rel.y() << " " << rel.z()
      << "\"";
    if (l.parent < 0)  // the root's turn carries its children (their frames are relative)
      x << " quat=\"" << tilt.w() << " " << tilt.x() << " " << tilt.y() << " " << tilt.z() << "\"";
    x << ">\n";
    if (l.parent < 0) {
      x << "<freejoint/>\n";
    } else {
      const Vector3d j = l.joint - l.centre;
      x << "<joint type=\"hinge\" pos=\"" << j.x() << " " << j.y() << " " << j.z() << "\" axis=\""
        << l.axis.x() << " " << l.axis.y() << " " << l.axis.z() << "\"/>\n";
    }
    const Vector3d half = l.along * (kSegment / 2 - kRadius);
    x << "<geom type=\"capsule\" size=\"" << kRadius << "\" fromto=\"" << -half.x() << " "
      << -half.y() << " " << -half.z() << " " << half.x() << " " << half.y() << " " << half.z()
      << "\" mass=\"0.2\" contype=\"" << (options.self_contact ? 1 : 0) << "\" conaffinity=\""
      << (options.self_contact || options.floor ? 1 : 0) << "\"/>\n";
    for (const auto& t : Tendons(links, options.spanning_tendons, options.tendons)) {
      for (int end = 0; end < 2; ++end) {
        const int body = end ? t.body_b : t.body_a;
        if (body != i) continue;
        const Vector3d p = (end ? t.point_b : t.point_a) - l.centre;
        x << "<site name=\"" << t.name << (end ? "_b" : "_a") << "\" pos=\"" << p.x() << " "
          << p.y() << " " << p.z() << "\"/>\n";
      }
    }
    for (size_t c = 0; c < links.size(); ++c)
      if (links[c].parent == i) write(static_cast<int>(c));
    x << "</body>\n";
  };
  write(0);
  x << "</worldbody>\n<contact>\n";
  x << "</contact>\n<tendon>\n";
  for (const auto& t : Tendons(links, options.spanning_tendons, options.tendons))
    x << "<spatial name=\"" << t.name << "\" stiffness=\"0\"><site site=\"" << t.name
      << "_a\"/><site site=\"" << t.name << "_b\"/></spatial>\n";
  x << "</tendon>\n<actuator>\n";
  for (const auto& t : Tendons(links, options.spanning_tendons, options.tendons))
    x << "<motor tendon=\"" << t.name << "\" gear=\"-1\" ctrlrange=\"0 50\" ctrllimited=\"true\"/>\n";
  x << "</actuator>\n</mujoco>\n";
  return x.str();
}

}  // namespace caliper::bench
