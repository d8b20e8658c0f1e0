#include "arm26.h"

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace caliper::testing {

namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;
using sgal::PathElement;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDensity = 1000;  // MuJoCo's default geom density [kg/m^3]

// a capsule along x from 0 to `length`, radius `radius`: shape, visual and inertia (MuJoCo's
// capsule inertia: a cylinder plus two hemispheres, about the centre of mass)
void AddArmSegment(sgal::Body* body, const std::string& name, double radius, double length,
                   const Eigen::Vector4f& color) {
  sgal::Pose pose;
  pose.position = Vector3d(length / 2, 0, 0);
  pose.orientation = Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), Vector3d::UnitX());
  body->shapes.push_back(
      sgal::Shape{name, sgal::Capsule{radius, length}, pose, 1, 0xffffffffu, ""});
  body->visuals.push_back(sgal::Visual{name, sgal::Capsule{radius, length}, pose, color});

  const double r2 = radius * radius, h = length;
  const double m_cyl = kDensity * kPi * r2 * h;                   // [kg]
  const double m_sph = kDensity * 4.0 / 3.0 * kPi * r2 * radius;  // two hemispheres [kg]
  const double axial = m_cyl * r2 / 2 + m_sph * 2 * r2 / 5;       // [kg m^2]
  const double transverse =
      m_cyl * (3 * r2 + h * h) / 12 + m_sph * (2 * r2 / 5 + h * h / 4 + 3 * h * radius / 8);
  body->inertia.mass = m_cyl + m_sph;
  body->inertia.com = Vector3d(length / 2, 0, 0);
  body->inertia.tensor = Vector3d(axial, transverse, transverse).asDiagonal();
}

// the cylinders the tendons wrap around (MuJoCo geoms of mass 0, size = radius, half-length)
void AddWrapCylinder(sgal::Scene* scene, sgal::Body* body, const std::string& name, double radius,
                     double half_length) {
  const Eigen::Vector4f color(0.5f, 0.1f, 0.8f, 0.5f);
  body->shapes.push_back(
      sgal::Shape{name, sgal::Cylinder{radius, 2 * half_length}, sgal::Pose{}, 1, 0xffffffffu, ""});
  body->visuals.push_back(sgal::Visual{name, sgal::Cylinder{radius, 2 * half_length}, {}, color});
  sgal::WrapObstacle o;
  o.name = name;
  o.body = body->name;
  o.kind = sgal::ObstacleKind::kCylinder;
  o.radius = radius;
  o.length = 2 * half_length;
  scene->obstacles.push_back(o);
}

PathElement Site(const std::string& body, double x, double y) {
  PathElement e;
  e.kind = PathElement::Kind::kPoint;
  e.body = body;
  e.position = Vector3d(x, y, 0);
  return e;
}

PathElement Wrap(const std::string& obstacle) {
  PathElement e;
  e.kind = PathElement::Kind::kWrap;
  e.obstacle = obstacle;
  return e;
}

PathElement Wrap(const std::string& obstacle, double side_x, double side_y) {
  PathElement e = Wrap(obstacle);
  e.side = Vector3d(side_x, side_y, 0);
  return e;
}

sgal::Constraint Hinge(const std::string& name, const std::string& child, const std::string& parent,
                       const Vector3d& in_parent) {
  sgal::Constraint c;
  c.name = name;
  c.kind = sgal::ConstraintKind::kHinge;
  c.body_a = child;
  c.body_b = parent;
  c.frame_b.position = in_parent;
  c.limits[0] = sgal::Limit{0.0, 120.0 * kPi / 180};
  c.springs[0].damping = 0.1;  // [N m s/rad]
  return c;
}

// pose, angular velocity and origin velocity of a body in the world
struct BodyMotion {
  Isometry3d pose = Isometry3d::Identity();
  Vector3d omega = Vector3d::Zero();     // [rad/s]
  Vector3d velocity = Vector3d::Zero();  // of the body origin [m/s]
  Vector3d PointVelocity(const Vector3d& p) const {
    return velocity + omega.cross(p - pose.translation());
  }
};

// forward kinematics over the hinge tree: a child's frame_a turns by q about z of the parent's
// frame_b
std::vector<BodyMotion> Kinematics(const sgal::Scene& scene, double q_shoulder, double q_elbow,
                                   double qd_shoulder, double qd_elbow) {
  std::vector<BodyMotion> motion(scene.bodies.size());
  std::vector<int> done(scene.bodies.size(), 0);
  std::function<BodyMotion(const std::string&)> solve = [&](const std::string& name) {
    if (name.empty()) return BodyMotion{};
    const int index = scene.BodyIndex(name);
    if (index < 0) throw std::invalid_argument("arm26: no body '" + name + "'");
    if (done[index]) return motion[index];
    BodyMotion m;
    m.pose = scene.bodies[index].pose.ToIsometry();
    for (const auto& c : scene.constraints) {
      if (c.kind != sgal::ConstraintKind::kHinge || c.body_a != name) continue;
      const double q = c.name == "shoulder" ? q_shoulder : q_elbow;
      const double qd = c.name == "shoulder" ? qd_shoulder : qd_elbow;
      const BodyMotion parent = solve(c.body_b);
      const Isometry3d joint = parent.pose * c.frame_b.ToIsometry();
      m.pose = joint * Eigen::AngleAxisd(q, Vector3d::UnitZ()) * c.frame_a.ToIsometry().inverse();
      m.omega = parent.omega + qd * joint.linear().col(2);
      const Vector3d joint_velocity = parent.PointVelocity(joint.translation());
      m.velocity = joint_velocity + m.omega.cross(m.pose.translation() - joint.translation());
    }
    motion[index] = m;
    done[index] = 1;
    return m;
  };
  for (const auto& b : scene.bodies) solve(b.name);
  return motion;
}

}  // namespace

sgal::Scene MakeArm26() {
  sgal::Scene s;
  s.name = "2-link 6-muscle arm";
  s.source = "MuJoCo model/tendon_arm/arm26.xml, rebuilt in tests/support/arm26.cc";
  s.settings.time_step = 0.005;  // [s]
  s.settings.solver_iterations = 50;

  sgal::Body upper;
  upper.name = "upper_arm";
  AddArmSegment(&upper, "upper arm", 0.045, 0.5, Eigen::Vector4f(0.5f, 0.1f, 0.1f, 1.0f));
  AddWrapCylinder(&s, &upper, "shoulder", 0.1, 0.05);

  sgal::Body fore;
  fore.name = "forearm";
  fore.pose.position = Vector3d(0.5, 0, 0);
  AddArmSegment(&fore, "forearm", 0.035, 0.5, Eigen::Vector4f(0.5f, 0.1f, 0.1f, 1.0f));
  AddWrapCylinder(&s, &fore, "elbow", 0.08, 0.05);

  sgal::Body floor;
  floor.name = "floor";
  floor.type = sgal::BodyType::kStatic;
  floor.pose.position = Vector3d(0, 0, -0.5);
  floor.shapes.push_back(sgal::Shape{"floor", sgal::Plane{}, {}, 1, 0xffffffffu, ""});
  floor.visuals.push_back(
      sgal::Visual{"floor", sgal::Plane{}, {}, Eigen::Vector4f(0.25f, 0.25f, 0.25f, 1.0f)});

  s.bodies = {upper, fore, floor};
  s.constraints = {Hinge("shoulder", "upper_arm", "", Vector3d::Zero()),
                   Hinge("elbow", "forearm", "upper_arm", Vector3d(0.5, 0, 0))};

  // sites: s0 (world) -0.15 0 0; s1..s6 on the upper arm; s7, s8 on the forearm; side sites x0
  // (world, 0 -0.15 0) and x1 (upper arm, 0.5 -0.15 0), here relative to the wrapped cylinder's
  // body
  const PathElement s0 = Site("", -0.15, 0);
  const PathElement s1 = Site("upper_arm", 0.15, 0.06), s2 = Site("upper_arm", 0.15, -0.06);
  const PathElement s3 = Site("upper_arm", 0.4, 0.06), s4 = Site("upper_arm", 0.4, -0.06);
  const PathElement s5 = Site("upper_arm", 0.25, 0.1), s6 = Site("upper_arm", 0.25, -0.1);
  const PathElement s7 = Site("forearm", 0.11, 0.05), s8 = Site("forearm", 0.11, -0.05);
  const PathElement shoulder = Wrap("shoulder"), shoulder_x0 = Wrap("shoulder", 0, -0.15);
  const PathElement elbow = Wrap("elbow"), elbow_x1 = Wrap("elbow", 0, -0.15);
  auto tendon = [&](const std::string& name, double width, std::vector<PathElement> path) {
    sgal::Tendon t;
    t.name = name;
    t.radius = width;
    t.collide_with_bodies = false;
    t.path = std::move(path);
    s.tendons.push_back(t);
  };
  tendon("SF", 0.01, {s0, shoulder, s1});
  tendon("SE", 0.01, {s0, shoulder_x0, s2});
  tendon("EF", 0.01, {s3, elbow, s7});
  tendon("EE", 0.01, {s4, elbow_x1, s8});
  tendon("BF", 0.009, {s0, shoulder, s5, elbow, s7});
  tendon("BE", 0.009, {s0, shoulder_x0, s6, elbow_x1, s8});

  // muscle parameters as Debian's MuJoCo 2.2.2 compiled them for this model
  // (corpus reference/mujoco222_generated/mujoco222_arm26_model_params.csv): actuator_lengthrange
  // [m], acc0 [rad/s^2 per unit ctrl], gainprm = range 0.75 1.05, force -1 (i.e. scale / acc0),
  // scale 200, lmin 0.5, lmax 1.6, vmax 1.5 [L0/s], fpmax 1.3, fvmax 1.2; dynprm = tau_act 0.01 s,
  // tau_deact 0.04 s
  struct Compiled {
    const char* name;
    double length_lo, length_hi, acc0;
  };
  const Compiled compiled[] = {
      {"SF", 0.10242022997, 0.340386464984, 0.558692074634},
      {"SE", 0.34032594475, 0.549867948465, 0.558692074634},
      {"EF", 0.0102621210586, 0.216452832502, 1.4931422226},
      {"EE", 0.216363618394, 0.384063470156, 1.4931422226},
      {"BF", 0.331974923978, 0.799956463487, 0.939915716774},
      {"BE", 0.799802841732, 1.17701879782, 0.939915716774},
  };
  for (const Compiled& c : compiled) {
    sgal::Actuator a;
    a.name = c.name;
    a.kind = "hill_muscle";
    a.tendon = c.name;
    a.options["curves"] = "mujoco";
    a.parameters = {
        {"lengthrange_lo", c.length_lo},  // [m]
        {"lengthrange_hi", c.length_hi},  // [m]
        {"acc0", c.acc0},
        {"range0", 0.75},
        {"range1", 1.05},
        {"force", -1},
        {"scale", 200},
        {"lmin", 0.5},
        {"lmax", 1.6},
        {"vmax", 1.5},
        {"fpmax", 1.3},
        {"fvmax", 1.2},
        {"tau_act", 0.01},    // [s]
        {"tau_deact", 0.04},  // [s]
    };
    s.actuators.push_back(a);
  }
  return s;
}

std::vector<actuators::WorldElement> Arm26Elements(const sgal::Scene& scene,
                                                   const sgal::Tendon& tendon, double shoulder_rad,
                                                   double elbow_rad) {
  return Arm26Elements(scene, tendon, shoulder_rad, elbow_rad, 0, 0);
}

std::vector<actuators::WorldElement> Arm26Elements(const sgal::Scene& scene,
                                                   const sgal::Tendon& tendon, double shoulder_rad,
                                                   double elbow_rad, double shoulder_speed,
                                                   double elbow_speed) {
  const std::vector<BodyMotion> motion =
      Kinematics(scene, shoulder_rad, elbow_rad, shoulder_speed, elbow_speed);
  auto body_motion = [&](const std::string& body) {
    return body.empty() ? BodyMotion{} : motion[scene.BodyIndex(body)];
  };
  std::vector<actuators::WorldElement> out;
  for (const PathElement& e : tendon.path) {
    actuators::WorldElement w;
    w.kind = e.kind;
    if (e.kind == PathElement::Kind::kPoint) {
      const BodyMotion m = body_motion(e.body);
      w.body = scene.BodyIndex(e.body);
      w.point = m.pose * e.position;
      w.velocity = m.PointVelocity(w.point);
      w.friction = e.friction;
    } else {
      const sgal::WrapObstacle* o = scene.FindObstacle(e.obstacle);
      if (!o) throw std::invalid_argument("arm26: no obstacle '" + e.obstacle + "'");
      const BodyMotion m = body_motion(o->body);
      w.body = scene.BodyIndex(o->body);
      w.obstacle.kind = o->kind;
      w.obstacle.pose = m.pose * o->pose.ToIsometry();
      w.obstacle.radius = o->radius;
      w.obstacle.length = o->length;
      w.velocity = m.PointVelocity(w.obstacle.pose.translation());
      if (e.side) w.side = m.pose * *e.side;
    }
    out.push_back(w);
  }
  return out;
}

}  // namespace caliper::testing
