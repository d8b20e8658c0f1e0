#include "models.h"

#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>

namespace caliper::models {

namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;
using Eigen::Vector4f;
using sgal::PathElement;

constexpr double kPi = 3.14159265358979323846;
constexpr double kGravity = 9.81;  // [m/s^2]

// colours (RGBA)
const Vector4f kFrameColor(0.35f, 0.37f, 0.42f, 1.0f);    // torso, stands
const Vector4f kMotorColor(0.15f, 0.15f, 0.17f, 1.0f);    // motor banks
const Vector4f kBoneColor(0.92f, 0.89f, 0.80f, 1.0f);     // ECCE's hand-moulded "bones"
const Vector4f kHousingColor(0.55f, 0.60f, 0.68f, 1.0f);  // shoulder housing
const Vector4f kPulleyColor(0.80f, 0.55f, 0.20f, 0.6f);   // wrap cylinders
const Vector4f kLinkColor(0.20f, 0.45f, 0.75f, 1.0f);     // rig links

// collision groups of the ECCE arm: the torso stops the forearm and hand, the hand the upper arm;
// the girdle and the shoulder touch nothing (they sit inside the torso's outline)
constexpr uint32_t kTorsoGroup = 1, kGirdleGroup = 2, kUpperArmGroup = 4, kForearmGroup = 8,
                   kHandGroup = 16;

Quaterniond ZTo(const Vector3d& axis) {
  return Quaterniond::FromTwoVectors(Vector3d::UnitZ(), axis.normalized());
}

// inertia tensors about the centre of mass, along the shape's axes [kg m^2]
Matrix3d SolidCylinderZ(double mass, double radius, double length) {
  const double axial = mass * radius * radius / 2;
  const double transverse = mass * (3 * radius * radius + length * length) / 12;
  return Vector3d(transverse, transverse, axial).asDiagonal();
}
Matrix3d SolidBox(double mass, const Vector3d& size) {
  const Vector3d s2 = size.cwiseProduct(size);
  return (Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()) * (mass / 12)).asDiagonal();
}
Matrix3d SolidSphere(double mass, double radius) {
  return Matrix3d::Identity() * (0.4 * mass * radius * radius);
}
// a tensor given along the shape's axes, expressed along body axes turned by q
Matrix3d Turned(const Matrix3d& tensor, const Quaterniond& q) {
  const Matrix3d r = q.toRotationMatrix();
  return r * tensor * r.transpose();
}

// Builds a scene whose bodies all start with their axes along the world's, so that every
// position can be given in world coordinates at the rest pose.
class Builder {
 public:
  Builder(const std::string& name, double time_step, int solver_iterations) {
    scene_.name = name;
    scene_.settings.time_step = time_step;
    scene_.settings.solver_iterations = solver_iterations;
  }

  void AddMaterial(const std::string& name, double friction, double restitution) {
    scene_.materials.push_back({name, friction, restitution});
  }

  // a body whose frame sits at `origin` [m]
  void AddBody(const std::string& name, sgal::BodyType type, const Vector3d& origin) {
    sgal::Body b;
    b.name = name;
    b.type = type;
    b.pose.position = origin;
    scene_.bodies.push_back(b);
  }

  // mass [kg], centre of mass (world at rest) [m], tensor about it along world axes [kg m^2]
  void SetInertia(const std::string& body, double mass, const Vector3d& com,
                  const Matrix3d& tensor) {
    sgal::Body& b = Body(body);
    b.inertia.mass = mass;
    b.inertia.com = Local(body, com);
    b.inertia.tensor = tensor;
  }

  // a collision shape and a visual of the same geometry, centred at `center` (world at rest)
  void AddShape(const std::string& body, const std::string& name, const sgal::Geometry& geometry,
                const Vector3d& center, const Quaterniond& orientation, uint32_t group,
                uint32_t mask, const Vector4f& color, const std::string& material = "") {
    sgal::Shape s;
    s.name = name;
    s.geometry = geometry;
    s.pose.position = Local(body, center);
    s.pose.orientation = orientation;
    s.group = group;
    s.mask = mask;
    s.material = material;
    Body(body).shapes.push_back(s);
    AddVisual(body, name, geometry, center, orientation, color);
  }

  // something drawn that does not collide
  void AddVisual(const std::string& body, const std::string& name, const sgal::Geometry& geometry,
                 const Vector3d& center, const Quaterniond& orientation, const Vector4f& color) {
    sgal::Visual v;
    v.name = name;
    v.geometry = geometry;
    v.pose.position = Local(body, center);
    v.pose.orientation = orientation;
    v.color = color;
    Body(body).visuals.push_back(v);
  }

  // a hinge at `point` about `axis` (world at rest): positive angles turn the child
  // counter-clockwise about the axis; limits [deg], damping [N m s/rad]
  void AddHinge(const std::string& name, const std::string& child, const std::string& parent,
                const Vector3d& point, const Vector3d& axis, double lower_deg, double upper_deg,
                double damping) {
    sgal::Constraint c;
    c.name = name;
    c.kind = sgal::ConstraintKind::kHinge;
    c.body_a = child;
    c.body_b = parent;
    c.frame_a.position = Local(child, point);
    c.frame_a.orientation = ZTo(axis);
    c.frame_b.position = parent.empty() ? point : Local(parent, point);
    c.frame_b.orientation = ZTo(axis);
    c.limits[0] = sgal::Limit{lower_deg * kPi / 180, upper_deg * kPi / 180};
    c.springs[0].damping = damping;
    scene_.constraints.push_back(c);
  }

  // a wrap cylinder of `body` centred at `center` along `axis` (world at rest), drawn but not
  // colliding (the tendon lies on it)
  void AddPulley(const std::string& name, const std::string& body, const Vector3d& center,
                 const Vector3d& axis, double radius, double length) {
    sgal::WrapObstacle o;
    o.name = name;
    o.body = body;
    o.kind = sgal::ObstacleKind::kCylinder;
    o.pose.position = Local(body, center);
    o.pose.orientation = ZTo(axis);
    o.radius = radius;
    o.length = length;
    scene_.obstacles.push_back(o);
    AddVisual(body, name, sgal::Cylinder{radius, length}, center, ZTo(axis), kPulleyColor);
  }

  // a path point fixed in `body` at `world` (at rest) [m]; friction: capstan coefficient
  PathElement Point(const std::string& body, const Vector3d& world, double friction = 0) const {
    PathElement e;
    e.kind = PathElement::Kind::kPoint;
    e.body = body;
    e.position = Local(body, world);
    e.friction = friction;
    return e;
  }

  // a wrap around a declared obstacle on the side of `side` (world at rest)
  PathElement Wrap(const std::string& obstacle, const Vector3d& side) const {
    const sgal::WrapObstacle* o = scene_.FindObstacle(obstacle);
    if (o == nullptr) throw std::logic_error("no obstacle '" + obstacle + "'");
    PathElement e;
    e.kind = PathElement::Kind::kWrap;
    e.obstacle = obstacle;
    e.side = Local(o->body, side);
    return e;
  }

  void AddTendon(const std::string& name, std::vector<PathElement> path, double radius = 0.0015) {
    sgal::Tendon t;
    t.name = name;
    t.path = std::move(path);
    t.radius = radius;
    scene_.tendons.push_back(t);
  }

  sgal::Actuator& AddActuator(const std::string& name, const std::string& kind,
                              const std::string& tendon) {
    sgal::Actuator a;
    a.name = name;
    a.kind = kind;
    a.tendon = tendon;
    scene_.actuators.push_back(a);
    return scene_.actuators.back();
  }

  // a point of a path element in the world at rest [m]
  Vector3d World(const PathElement& e) const {
    return e.body.empty() ? e.position : Body(e.body).pose.position + e.position;
  }

  // the length of a tendon's path at rest through its points, wraps taken as straight [m]
  double StraightLength(const std::string& tendon) const {
    const sgal::Tendon* t = scene_.FindTendon(tendon);
    double length = 0;
    std::optional<Vector3d> last;
    for (const PathElement& e : t->path) {
      if (e.kind != PathElement::Kind::kPoint) continue;
      if (last) length += (World(e) - *last).norm();
      last = World(e);
    }
    return length;
  }

  // the torque [N m] about a hinge (positive: its positive direction) that a unit tension in
  // a straight tendon exerts on the child through its end point `on_child`, pulled toward
  // `toward` (both world at rest)
  double MomentArm(const std::string& hinge, const Vector3d& on_child,
                   const Vector3d& toward) const {
    const auto [point, axis] = HingeAxis(hinge);
    return ((on_child - point).cross((toward - on_child).normalized())).dot(axis);
  }

  // the torque [N m] gravity exerts about a hinge on the bodies listed
  double GravityTorque(const std::string& hinge, const std::vector<std::string>& bodies) const {
    const auto [point, axis] = HingeAxis(hinge);
    double torque = 0;
    for (const std::string& name : bodies) {
      const sgal::Body& b = Body(name);
      const Vector3d com = b.pose.position + b.inertia.com;
      torque += ((com - point).cross(scene_.gravity * b.inertia.mass)).dot(axis);
    }
    return torque;
  }

  sgal::Scene Take() { return std::move(scene_); }

 private:
  sgal::Body& Body(const std::string& name) {
    for (auto& b : scene_.bodies)
      if (b.name == name) return b;
    throw std::logic_error("no body '" + name + "'");
  }
  const sgal::Body& Body(const std::string& name) const {
    const sgal::Body* b = scene_.FindBody(name);
    if (b == nullptr) throw std::logic_error("no body '" + name + "'");
    return *b;
  }
  // a world point at rest in the body's frame ("" is the world)
  Vector3d Local(const std::string& body, const Vector3d& world) const {
    return body.empty() ? world : Vector3d(world - Body(body).pose.position);
  }
  // a hinge's point and axis in the world at rest
  std::pair<Vector3d, Vector3d> HingeAxis(const std::string& hinge) const {
    for (const auto& c : scene_.constraints)
      if (c.name == hinge) {
        const Vector3d point = c.body_b.empty() ? c.frame_b.position
                                                : Body(c.body_b).pose.position + c.frame_b.position;
        return {point, c.frame_b.orientation * Vector3d::UnitZ()};
      }
    throw std::logic_error("no hinge '" + hinge + "'");
  }

  sgal::Scene scene_;
};

// The reference (ECCE) motor, gearbox and spool of libs/actuators, written out so that a model
// keeps its motor whatever the kind's defaults become; a 3 A driver limit.
void SetEcceMotor(sgal::Actuator* a) {
  a->parameters["resistance"] = 0.516;          // [ohm]
  a->parameters["inductance"] = 5.73e-5;        // [H]
  a->parameters["torque_constant"] = 0.0115;    // [N m/A]
  a->parameters["back_emf_constant"] = 0.0115;  // [V s/rad]
  a->parameters["rotor_inertia"] = 1.45e-6;     // [kg m^2]
  a->parameters["gear_inertia"] = 4e-8;         // [kg m^2]
  a->parameters["gear_ratio"] = 128;            // [-]
  a->parameters["efficiency"] = 0.59;           // [-]
  a->parameters["spool_radius"] = 0.0045;       // [m]
  a->parameters["supply_voltage"] = 12;         // [V]
  a->parameters["current_limit"] = 3;           // [A]
}

// a steel spring or stiff cord: stiffness [N/m], damping [N s/m], rest length [m],
// tension at reset [N]
void SetLinearElastic(sgal::Actuator* a, double stiffness, double damping, double rest_length,
                      double pretension) {
  a->options["elastic"] = "linear";
  a->parameters["stiffness"] = stiffness;
  a->parameters["damping"] = damping;
  a->parameters["rest_length"] = rest_length;
  a->parameters["pretension"] = pretension;
}

// ECCE's shock cord as a Zener solid (the moduli and viscosity of libs/actuators): cross-section
// [m^2], rest length [m], tension at reset [N]
void SetShockCord(sgal::Actuator* a, double area, double rest_length, double pretension) {
  a->options["elastic"] = "zener";
  a->parameters["zener_E0"] = 0.694e6;    // [Pa]
  a->parameters["zener_E1"] = 0.2116e6;   // [Pa]
  a->parameters["zener_mu"] = 277788.48;  // [Pa s]
  a->parameters["zener_area"] = area;     // [m^2]
  a->parameters["rest_length"] = rest_length;
  a->parameters["pretension"] = pretension;
}

// Landmarks of the ECCE arm at rest [m]: sternoclavicular joint, glenohumeral (shoulder) centre,
// elbow, wrist; x forward, y left, z up; the right arm hangs at y = -0.24.
struct ArmLandmarks {
  Vector3d sc = Vector3d(0, -0.06, 1.47);
  Vector3d gh = Vector3d(0, -0.24, 1.47);
  Vector3d elbow = Vector3d(0, -0.24, 1.17);
  Vector3d wrist = Vector3d(0, -0.24, 0.92);
};

// The ECCE arm's bodies: torso, shoulder girdle, shoulder housing, upper arm, forearm, hand.
void AddEcceBodies(Builder& b, const ArmLandmarks& at) {
  const auto kDynamic = sgal::BodyType::kDynamic;
  const Vector3d y = Vector3d::UnitY();

  // torso: static chest and neck post, the motor banks and a stand drawn only
  b.AddBody("torso", sgal::BodyType::kStatic, Vector3d(0, 0, 1.15));
  const uint32_t torso_mask = kForearmGroup | kHandGroup;
  b.AddShape("torso", "chest", sgal::Box{Vector3d(0.2, 0.3, 0.6)}, Vector3d(0, 0, 1.15),
             Quaterniond::Identity(), kTorsoGroup, torso_mask, kFrameColor);
  b.AddShape("torso", "neck_post", sgal::Cylinder{0.04, 0.2}, Vector3d(-0.02, 0, 1.55),
             Quaterniond::Identity(), kTorsoGroup, torso_mask, kFrameColor);
  b.AddVisual("torso", "motor_bank", sgal::Box{Vector3d(0.06, 0.24, 0.3)}, Vector3d(-0.13, 0, 1.2),
              Quaterniond::Identity(), kMotorColor);
  b.AddVisual("torso", "stand", sgal::Cylinder{0.04, 0.85}, Vector3d(0, 0, 0.425),
              Quaterniond::Identity(), kFrameColor);

  // girdle: clavicle from the sternoclavicular joint to the shoulder, acromion on top, scapula
  // plate behind
  b.AddBody("girdle", kDynamic, at.sc);
  b.AddShape("girdle", "clavicle", sgal::Capsule{0.02, 0.14}, (at.sc + at.gh) / 2, ZTo(y),
             kGirdleGroup, 0, kBoneColor, "polymorph");
  b.AddShape("girdle", "acromion", sgal::Box{Vector3d(0.08, 0.05, 0.03)}, Vector3d(0, -0.24, 1.535),
             Quaterniond::Identity(), kGirdleGroup, 0, kBoneColor, "polymorph");
  b.AddShape("girdle", "scapula", sgal::Box{Vector3d(0.015, 0.07, 0.12)},
             Vector3d(-0.07, -0.19, 1.40), Quaterniond::Identity(), kGirdleGroup, 0, kBoneColor,
             "polymorph");
  b.SetInertia("girdle", 0.6, Vector3d(-0.01, -0.17, 1.46),
               Vector3d(0.0025, 0.0008, 0.0025).asDiagonal());

  // shoulder housing between the two shoulder hinges: drawn, not colliding
  b.AddBody("shoulder", kDynamic, at.gh);
  b.AddVisual("shoulder", "housing", sgal::Sphere{0.045}, at.gh, Quaterniond::Identity(),
              kHousingColor);
  b.SetInertia("shoulder", 0.4, at.gh, SolidSphere(0.4, 0.05));

  // upper arm 0.30 m, forearm 0.25 m, hand
  b.AddBody("upper_arm", kDynamic, at.gh);
  b.AddShape("upper_arm", "humerus", sgal::Capsule{0.035, 0.23}, Vector3d(0, -0.24, 1.32),
             Quaterniond::Identity(), kUpperArmGroup, kHandGroup, kBoneColor, "polymorph");
  b.SetInertia("upper_arm", 1.6, Vector3d(0, -0.24, 1.33), SolidCylinderZ(1.6, 0.035, 0.30));

  b.AddBody("forearm", kDynamic, at.elbow);
  b.AddShape("forearm", "ulna", sgal::Capsule{0.03, 0.19}, Vector3d(0, -0.24, 1.045),
             Quaterniond::Identity(), kForearmGroup, kTorsoGroup, kBoneColor, "polymorph");
  b.SetInertia("forearm", 1.0, Vector3d(0, -0.24, 1.06), SolidCylinderZ(1.0, 0.03, 0.25));

  b.AddBody("hand", kDynamic, at.wrist);
  b.AddShape("hand", "palm", sgal::Box{Vector3d(0.03, 0.08, 0.15)}, Vector3d(0, -0.24, 0.825),
             Quaterniond::Identity(), kHandGroup, kTorsoGroup | kUpperArmGroup, kBoneColor,
             "polymorph");
  b.AddVisual("hand", "thumb", sgal::Capsule{0.01, 0.04}, Vector3d(0.02, -0.19, 0.86),
              Quaterniond::Identity(), kBoneColor);
  b.SetInertia("hand", 0.45, Vector3d(0, -0.24, 0.83), SolidBox(0.45, Vector3d(0.03, 0.08, 0.15)));
}

// The ECCE arm's hinges and the pulleys on their axes.
void AddEcceJoints(Builder& b, const ArmLandmarks& at) {
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY();
  // joints: positive girdle elevation lifts the shoulder, positive abduction swings the arm out,
  // positive flexion forward; limits [deg], damping [N m s/rad]
  b.AddHinge("girdle_elevation", "girdle", "torso", at.sc, -x, -10, 25, 0.5);
  b.AddHinge("shoulder_abduction", "shoulder", "girdle", at.gh, -x, -10, 100, 0.1);
  b.AddHinge("shoulder_flexion", "upper_arm", "shoulder", at.gh, -y, -40, 150, 0.1);
  b.AddHinge("elbow", "forearm", "upper_arm", at.elbow, -y, 0, 145, 0.3);
  b.AddHinge("wrist", "hand", "forearm", at.wrist, -y, -70, 70, 0.02);

  // pulleys on the joint axes: the tendons wrap them, so that their moment arms stay put
  b.AddPulley("shoulder_abduction_pulley", "girdle", at.gh, x, 0.05, 0.08);
  b.AddPulley("shoulder_flexion_pulley", "shoulder", at.gh, y, 0.05, 0.08);
  b.AddPulley("elbow_pulley", "upper_arm", at.elbow, y, 0.04, 0.06);
  b.AddPulley("wrist_pulley", "forearm", at.wrist, y, 0.036, 0.05);
}

// The ECCE arm's tendon paths (world points at rest, 5-10 mm off the surfaces): the motors'
// antagonistic pairs, the ligaments and the biceps.
void AddEcceTendons(Builder& b, const ArmLandmarks& at) {
  const Vector3d front(0.1, 0, 0), back(-0.1, 0, 0), lateral(0, -0.1, 0);
  const Vector3d &gh = at.gh, &elbow = at.elbow, &wrist = at.wrist;
  b.AddTendon("girdle_elevator", {b.Point("torso", Vector3d(-0.02, -0.05, 1.62)),
                                  b.Point("girdle", Vector3d(0, -0.20, 1.495))});
  b.AddTendon("girdle_depressor", {b.Point("torso", Vector3d(0, -0.16, 1.25)),
                                   b.Point("girdle", Vector3d(0, -0.20, 1.445))});
  b.AddTendon("shoulder_flexor", {b.Point("girdle", Vector3d(0.048, -0.235, 1.53)),
                                  b.Wrap("shoulder_flexion_pulley", gh + front),
                                  b.Point("upper_arm", Vector3d(0.04, -0.235, 1.35))});
  b.AddTendon("shoulder_extensor", {b.Point("girdle", Vector3d(-0.048, -0.235, 1.53)),
                                    b.Wrap("shoulder_flexion_pulley", gh + back),
                                    b.Point("upper_arm", Vector3d(-0.04, -0.235, 1.35))});
  b.AddTendon("shoulder_abductor", {b.Point("girdle", Vector3d(0, -0.275, 1.535)),
                                    b.Wrap("shoulder_abduction_pulley", gh + lateral),
                                    b.Point("upper_arm", Vector3d(0, -0.28, 1.35))});
  b.AddTendon("shoulder_adductor", {b.Point("girdle", Vector3d(0, -0.17, 1.44)),
                                    b.Point("upper_arm", Vector3d(0, -0.20, 1.35))});
  // the elbow and wrist motors sit on the bone above; their lines run down through a guide (a
  // via point with a little capstan friction) to the pulley
  b.AddTendon("elbow_flexor", {b.Point("upper_arm", Vector3d(0.04, -0.25, 1.42)),
                               b.Point("upper_arm", Vector3d(0.044, -0.25, 1.27), 0.03),
                               b.Wrap("elbow_pulley", elbow + front),
                               b.Point("forearm", Vector3d(0.035, -0.25, 1.10))});
  b.AddTendon("elbow_extensor", {b.Point("upper_arm", Vector3d(-0.04, -0.25, 1.42)),
                                 b.Point("upper_arm", Vector3d(-0.044, -0.25, 1.27), 0.03),
                                 b.Wrap("elbow_pulley", elbow + back),
                                 b.Point("forearm", Vector3d(-0.035, -0.25, 1.10))});
  b.AddTendon("wrist_flexor", {b.Point("forearm", Vector3d(0.038, -0.245, 1.14)),
                               b.Point("forearm", Vector3d(0.042, -0.245, 1.02), 0.03),
                               b.Wrap("wrist_pulley", wrist + front),
                               b.Point("hand", Vector3d(0.025, -0.245, 0.87))});
  b.AddTendon("wrist_extensor", {b.Point("forearm", Vector3d(-0.038, -0.245, 1.14)),
                                 b.Point("forearm", Vector3d(-0.042, -0.245, 1.02), 0.03),
                                 b.Wrap("wrist_pulley", wrist + back),
                                 b.Point("hand", Vector3d(-0.025, -0.245, 0.87))});
  // passive: the costoclavicular ligament holds the girdle down, the posterior elbow ligament
  // stops deep flexion, the palmar wrist ligament deep extension
  b.AddTendon("costoclavicular", {b.Point("torso", Vector3d(0, -0.155, 1.40)),
                                  b.Point("girdle", Vector3d(0, -0.15, 1.445))});
  b.AddTendon("elbow_posterior", {b.Point("upper_arm", Vector3d(-0.04, -0.225, 1.21)),
                                  b.Point("forearm", Vector3d(-0.035, -0.225, 1.13))});
  b.AddTendon("wrist_palmar", {b.Point("forearm", Vector3d(0.038, -0.225, 0.96)),
                               b.Point("hand", Vector3d(0.02, -0.225, 0.885))});
  // a biarticular biceps: over the shoulder and the elbow, through two via points
  b.AddTendon("biceps", {b.Point("girdle", Vector3d(0.048, -0.22, 1.53)),
                         b.Wrap("shoulder_flexion_pulley", gh + front),
                         b.Point("upper_arm", Vector3d(0.045, -0.22, 1.37), 0.05),
                         b.Point("upper_arm", Vector3d(0.042, -0.23, 1.24), 0.05),
                         b.Wrap("elbow_pulley", elbow + front),
                         b.Point("forearm", Vector3d(0.035, -0.23, 1.10))});
}

// The ECCE arm's ten motors in five antagonistic pairs, with the pretensions that hold it at rest.
void AddEcceMotors(Builder& b) {
  // the girdle hangs on its elevator: a pretension that balances gravity on the girdle and the
  // arm, and the depressor's
  const double depressor_pretension = 10;  // [N]
  const double gravity =
      b.GravityTorque("girdle_elevation", {"girdle", "shoulder", "upper_arm", "forearm", "hand"});
  const double elevator_arm =
      b.MomentArm("girdle_elevation", Vector3d(0, -0.20, 1.495), Vector3d(-0.02, -0.05, 1.62));
  const double depressor_arm =
      b.MomentArm("girdle_elevation", Vector3d(0, -0.20, 1.445), Vector3d(0, -0.16, 1.25));
  const double elevator_pretension =
      -(gravity + depressor_pretension * depressor_arm) / elevator_arm;
  // the adductor runs straight: its pretension balances the abductor's over the pulley
  const double pair_pretension = 8;  // [N]
  const double adductor_arm =
      b.MomentArm("shoulder_abduction", Vector3d(0, -0.20, 1.35), Vector3d(0, -0.17, 1.44));
  const double adductor_pretension = pair_pretension * 0.05 / std::abs(adductor_arm);

  // the girdle, shoulder and elbow on steel springs, the wrist on shock cord (a 10 mm cord)
  struct Motor {
    const char* name;
    double stiffness;   // [N/m]; 0: shock cord
    double damping;     // [N s/m]
    double pretension;  // [N]
  };
  const Motor motors[] = {
      {"girdle_elevator", 8000, 40, elevator_pretension},
      {"girdle_depressor", 8000, 40, depressor_pretension},
      {"shoulder_flexor", 5000, 30, pair_pretension},
      {"shoulder_extensor", 5000, 30, pair_pretension},
      {"shoulder_abductor", 5000, 30, pair_pretension},
      {"shoulder_adductor", 5000, 30, adductor_pretension},
      {"elbow_flexor", 3000, 20, pair_pretension},
      {"elbow_extensor", 3000, 20, pair_pretension},
      {"wrist_flexor", 0, 0, 3},
      {"wrist_extensor", 0, 0, 3},
  };
  for (const Motor& m : motors) {
    sgal::Actuator& a = b.AddActuator(m.name, "dc_motor_tendon", m.name);
    SetEcceMotor(&a);
    if (m.stiffness > 0)
      SetLinearElastic(&a, m.stiffness, m.damping, 0.04, m.pretension);
    else
      SetShockCord(&a, kPi * 0.01 * 0.01 / 4, 0.04, m.pretension);
  }
}

// The ECCE arm's passive ligaments and its biceps muscle.
void AddEcceLigamentsAndBiceps(Builder& b) {
  // ligaments: slack at rest except the costoclavicular one (taut at its rest path length)
  sgal::Actuator& costoclavicular = b.AddActuator("costoclavicular", "ligament", "costoclavicular");
  costoclavicular.parameters = {{"stiffness", 3000}, {"damping", 5}, {"rest_length", 0}};
  sgal::Actuator& elbow_posterior = b.AddActuator("elbow_posterior", "ligament", "elbow_posterior");
  elbow_posterior.parameters = {{"stiffness", 2000},
                                {"damping", 5},
                                {"rest_length", b.StraightLength("elbow_posterior") + 0.075}};
  sgal::Actuator& wrist_palmar = b.AddActuator("wrist_palmar", "ligament", "wrist_palmar");
  wrist_palmar.parameters = {{"stiffness", 1000},
                             {"damping", 2},
                             {"rest_length", b.StraightLength("wrist_palmar") + 0.03}};

  // the biceps: Thelen 2003 with a rigid tendon, its fibres at their optimal length at rest
  const double biceps_length = b.StraightLength("biceps");
  const double fiber = 0.12;  // [m]
  sgal::Actuator& biceps = b.AddActuator("biceps", "hill_muscle", "biceps");
  biceps.options = {{"curves", "thelen2003"}, {"tendon", "rigid"}};
  biceps.parameters = {{"max_isometric_force", 150},
                       {"optimal_fiber_length", fiber},
                       {"tendon_slack_length", biceps_length - fiber},
                       {"pennation_angle", 0},
                       {"max_contraction_velocity", 10},
                       {"activation_time_constant", 0.015},
                       {"deactivation_time_constant", 0.05}};
}

}  // namespace

sgal::Scene MakeEcceArm() {
  Builder b("ecce_arm", 1e-3, 50);
  b.AddMaterial("polymorph", 0.6, 0.1);
  const ArmLandmarks at;
  AddEcceBodies(b, at);
  AddEcceJoints(b, at);
  AddEcceTendons(b, at);
  AddEcceMotors(b);
  AddEcceLigamentsAndBiceps(b);
  return b.Take();
}

sgal::Scene MakePendulumTendon() {
  Builder b("pendulum_tendon", 1e-3, 20);
  const Vector3d pivot(0, 0, 1.10);

  // a static frame: base plate (holding the motor), post, beam with the pivot under it
  b.AddBody("frame", sgal::BodyType::kStatic, Vector3d::Zero());
  b.AddShape("frame", "base", sgal::Box{Vector3d(0.7, 0.3, 0.04)}, Vector3d(0.1, 0, 0.02),
             Quaterniond::Identity(), 1, 0xffffffffu, kFrameColor);
  b.AddShape("frame", "post", sgal::Cylinder{0.02, 1.1}, Vector3d(-0.12, 0, 0.59),
             Quaterniond::Identity(), 1, 0xffffffffu, kFrameColor);
  b.AddShape("frame", "beam", sgal::Box{Vector3d(0.48, 0.04, 0.04)}, Vector3d(0.1, 0, 1.15),
             Quaterniond::Identity(), 1, 0xffffffffu, kFrameColor);
  b.AddVisual("frame", "motor", sgal::Box{Vector3d(0.06, 0.04, 0.04)}, Vector3d(0.3, -0.05, 0.06),
              Quaterniond::Identity(), kMotorColor);

  // the pendulum: a rod and a 0.5 kg bob, 0.4 m below the pivot
  b.AddBody("pendulum", sgal::BodyType::kDynamic, pivot);
  b.AddShape("pendulum", "rod", sgal::Cylinder{0.01, 0.32}, Vector3d(0, 0, 0.92),
             Quaterniond::Identity(), 1, 0xffffffffu, kLinkColor);
  b.AddShape("pendulum", "bob", sgal::Sphere{0.04}, Vector3d(0, 0, 0.70), Quaterniond::Identity(),
             1, 0xffffffffu, kLinkColor);
  const double rod_mass = 0.1, bob_mass = 0.5;  // [kg]
  const Vector3d rod_com(0, 0, 0.92), bob_com(0, 0, 0.70);
  const Vector3d com = (rod_mass * rod_com + bob_mass * bob_com) / (rod_mass + bob_mass);
  auto shifted = [&](double m, const Vector3d& p) {  // parallel axis theorem
    const Vector3d d = p - com;
    return Matrix3d(m * (d.squaredNorm() * Matrix3d::Identity() - d * d.transpose()));
  };
  b.SetInertia("pendulum", rod_mass + bob_mass, com,
               SolidCylinderZ(rod_mass, 0.01, 0.32) + shifted(rod_mass, rod_com) +
                   SolidSphere(bob_mass, 0.04) + shifted(bob_mass, bob_com));
  // positive angles swing the bob toward +x, where the tendon pulls
  b.AddHinge("pivot", "pendulum", "frame", pivot, -Vector3d::UnitY(), -90, 90, 0.01);

  // the line: from the motor's spool on the base up to a guide at the beam's end, over it with a
  // little capstan friction, and down to the bob
  b.AddTendon("line", {b.Point("frame", Vector3d(0.30, 0, 0.045)),
                       b.Point("frame", Vector3d(0.30, 0, 1.125), 0.02),
                       b.Point("pendulum", Vector3d(0.045, 0, 0.70))});
  sgal::Actuator& motor = b.AddActuator("motor", "dc_motor_tendon", "line");
  SetEcceMotor(&motor);
  SetLinearElastic(&motor, 2000, 10, 0.05, 0);
  return b.Take();
}

sgal::Scene MakeTwoLinkAntagonistic() {
  Builder b("two_link_antagonistic", 1e-3, 30);
  const Vector3d shoulder(0, 0, 0), elbow(0.3, 0, 0);
  const Vector3d x = Vector3d::UnitX(), z = Vector3d::UnitZ();

  // the base holds the four motors behind the shoulder
  b.AddBody("base", sgal::BodyType::kStatic, Vector3d::Zero());
  b.AddShape("base", "motor_block", sgal::Box{Vector3d(0.1, 0.2, 0.08)}, Vector3d(-0.15, 0, 0),
             Quaterniond::Identity(), 1, 0xffffffffu, kMotorColor);
  b.AddVisual("base", "pillar", sgal::Cylinder{0.02, 0.3}, Vector3d(-0.15, 0, -0.19),
              Quaterniond::Identity(), kFrameColor);

  // links in the horizontal plane, along x at rest
  b.AddBody("upper_link", sgal::BodyType::kDynamic, shoulder);
  b.AddShape("upper_link", "upper_link", sgal::Capsule{0.02, 0.26}, Vector3d(0.15, 0, 0), ZTo(x), 2,
             0xffffffffu, kLinkColor);
  b.SetInertia("upper_link", 0.5, Vector3d(0.15, 0, 0),
               Turned(SolidCylinderZ(0.5, 0.02, 0.3), ZTo(x)));
  b.AddBody("lower_link", sgal::BodyType::kDynamic, elbow);
  b.AddShape("lower_link", "lower_link", sgal::Capsule{0.018, 0.214}, Vector3d(0.425, 0, 0), ZTo(x),
             2, 0xffffffffu, kLinkColor);
  b.SetInertia("lower_link", 0.35, Vector3d(0.425, 0, 0),
               Turned(SolidCylinderZ(0.35, 0.018, 0.25), ZTo(x)));

  // hinges about z (gravity does not turn them); positive angles toward +y
  b.AddHinge("shoulder", "upper_link", "base", shoulder, z, -90, 90, 0.02);
  b.AddHinge("elbow", "lower_link", "upper_link", elbow, z, -120, 120, 0.01);
  b.AddPulley("shoulder_pulley", "base", shoulder, z, 0.035, 0.04);
  b.AddPulley("elbow_pulley", "upper_link", elbow, z, 0.03, 0.04);

  const Vector3d left(0, 0.1, 0), right(0, -0.1, 0);
  b.AddTendon("shoulder_flexor", {b.Point("base", Vector3d(-0.09, 0.03, 0)),
                                  b.Wrap("shoulder_pulley", shoulder + left),
                                  b.Point("upper_link", Vector3d(0.12, 0.025, 0))});
  b.AddTendon("shoulder_extensor", {b.Point("base", Vector3d(-0.09, -0.03, 0)),
                                    b.Wrap("shoulder_pulley", shoulder + right),
                                    b.Point("upper_link", Vector3d(0.12, -0.025, 0))});
  b.AddTendon("elbow_flexor", {b.Point("upper_link", Vector3d(0.15, 0.025, 0)),
                               b.Wrap("elbow_pulley", elbow + left),
                               b.Point("lower_link", Vector3d(0.42, 0.023, 0))});
  b.AddTendon("elbow_extensor", {b.Point("upper_link", Vector3d(0.15, -0.025, 0)),
                                 b.Wrap("elbow_pulley", elbow + right),
                                 b.Point("lower_link", Vector3d(0.42, -0.023, 0))});
  for (const char* name :
       {"shoulder_flexor", "shoulder_extensor", "elbow_flexor", "elbow_extensor"}) {
    sgal::Actuator& a = b.AddActuator(name, "dc_motor_tendon", name);
    SetEcceMotor(&a);
    SetLinearElastic(&a, 1500, 5, 0.04, 5);
  }
  return b.Take();
}

std::vector<Model> AllModels() {
  return {{"ecce_arm.dae", MakeEcceArm()},
          {"pendulum_tendon.dae", MakePendulumTendon()},
          {"two_link_antagonistic.dae", MakeTwoLinkAntagonistic()}};
}

}  // namespace caliper::models
