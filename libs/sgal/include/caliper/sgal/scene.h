#pragma once
// The engine-neutral, static description of a scene: what an importer produces, what an engine
// adapter builds its world from, what an exporter writes back. SI units throughout (m, kg, s, rad,
// N); poses are in the world frame for bodies and in the body frame for everything attached to a
// body. A description stays const while a scene runs; dynamic state lives in the engine.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace caliper::sgal {

/// A rigid transform: where a frame is and how it is turned.
struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();            // [m]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // unit quaternion

  Eigen::Isometry3d ToIsometry() const;
  static Pose FromIsometry(const Eigen::Isometry3d& t);
  /// this * other: `other` expressed in this frame, composed.
  Pose operator*(const Pose& other) const;
  Pose Inverse() const;
  /// A point given in this frame, in the parent frame.
  Eigen::Vector3d Apply(const Eigen::Vector3d& p) const { return position + orientation * p; }
};

/// Triangle mesh data shared between shapes and visuals.
struct Mesh {
  std::vector<Eigen::Vector3f> vertices;          // [m]
  std::vector<std::array<uint32_t, 3>> triangles;  // indices into vertices
  std::vector<Eigen::Vector3f> normals;           // per vertex, optional (renderer)
};

// The closed set of geometries: every engine adapter handles each of them, or fails loudly (the
// std::visit in an adapter does not compile when one is missing).
struct Box {
  Eigen::Vector3d size = Eigen::Vector3d::Ones();  // full edge lengths [m]
};
struct Sphere {
  double radius = 0.5;  // [m]
};
struct Capsule {
  double radius = 0.5;  // [m]
  double length = 1.0;  // length of the cylindrical part along z [m]
};
struct Cylinder {
  double radius = 0.5;  // [m]
  double length = 1.0;  // along z [m]
};
struct Cone {
  double radius = 0.5;  // base radius [m]
  double length = 1.0;  // along z, apex at +length/2 [m]
};
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;  // n . x = offset [m]
};
struct ConvexHull {
  std::shared_ptr<const Mesh> mesh;
};
struct TriangleMesh {
  std::shared_ptr<const Mesh> mesh;
};
using Geometry = std::variant<Box, Sphere, Capsule, Cylinder, Cone, Plane, ConvexHull, TriangleMesh>;

/// `box`, `sphere`, ... for messages.
const char* GeometryName(const Geometry& g);

/// Radius of a sphere about the geometry's origin that holds it [m]: infinite for a plane, the
/// farthest vertex for meshes.
double BoundingRadius(const Geometry& g);

struct Material {
  std::string name;
  double friction = 0.5;     // Coulomb coefficient [-]
  double restitution = 0.0;  // [-]
};

/// A collision shape attached to a body.
struct Shape {
  std::string name;
  Geometry geometry;
  Pose pose;                       // in the body frame
  uint32_t group = 1;              // collision group bits
  uint32_t mask = 0xffffffffu;     // groups it collides with
  std::string material;            // name in Scene::materials, "" for the default
};

/// What the renderer draws for a body.
struct Visual {
  std::string name;
  Geometry geometry;
  Pose pose;                                               // in the body frame
  Eigen::Vector4f color = Eigen::Vector4f(0.7f, 0.7f, 0.7f, 1.0f);  // RGBA in [0, 1]
};

enum class BodyType { kDynamic, kStatic, kKinematic };

struct Inertia {
  double mass = 1.0;                                      // [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();          // centre of mass in the body frame [m]
  Eigen::Matrix3d tensor = Eigen::Matrix3d::Identity() * 1e-3;  // about the com, body axes [kg m^2]
};

struct Body {
  std::string name;
  BodyType type = BodyType::kDynamic;
  Pose pose;  // in the world frame
  Inertia inertia;
  std::vector<Shape> shapes;
  std::vector<Visual> visuals;
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // initial [m/s]
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // initial [rad/s]
};

enum class ConstraintKind { kHinge, kSlider, kBall, kFixed, kGeneric6Dof };

/// Limits of one degree of freedom (lower > upper means free).
struct Limit {
  double lower = 1.0;   // [m] or [rad]
  double upper = -1.0;  // [m] or [rad]
  bool enabled() const { return lower <= upper; }
};

/// A joint spring-damper on one degree of freedom.
struct JointSpring {
  double stiffness = 0;  // [N/m] or [N m/rad]
  double damping = 0;    // [N s/m] or [N m s/rad]
  double rest = 0;       // [m] or [rad]
};

/// A joint between body_a and body_b (or the world when body_b is empty). Each side's frame is
/// given in that body's frame; hinges turn and sliders slide about/along the frames' z axis. The
/// joint position is the rotation (or displacement) of body_a's frame relative to body_b's, so
/// body_b is the parent: positive angles turn body_a counter-clockwise about z.
struct Constraint {
  std::string name;
  ConstraintKind kind = ConstraintKind::kHinge;
  std::string body_a;
  std::string body_b;
  Pose frame_a;
  Pose frame_b;
  // hinge and slider use index 0; generic 6-DOF: 0-2 translation x, y, z, 3-5 rotation x, y, z
  std::array<Limit, 6> limits;
  std::array<JointSpring, 6> springs;
  // Coulomb (dry) friction of each degree of freedom, in the limits' order: the most torque [N m]
  // (rotations) or force [N] (translations) the joint resists motion with; 0 = none
  std::array<double, 6> friction{};
  bool collide_connected = false;  // whether the two bodies still collide with each other
};

/// A coupling q_follower = ratio * q_leader + offset between two joints (COLLADA <formula>).
struct Coupling {
  std::string leader;
  std::string follower;
  double ratio = 1.0;
  double offset = 0.0;
};

enum class ObstacleKind { kSphere, kCylinder };

/// A declared wrap surface a tendon may wrap around.
struct WrapObstacle {
  std::string name;
  std::string body;
  ObstacleKind kind = ObstacleKind::kCylinder;
  Pose pose;            // in the body frame; cylinders along z
  double radius = 0.01;  // [m]
  double length = 0.05;  // cylinders [m]
};

/// One element of a tendon path: a point fixed in a body, or a wrap around an obstacle (between
/// the points before and after it).
struct PathElement {
  enum class Kind { kPoint, kWrap };
  Kind kind = Kind::kPoint;
  std::string body;                                   // kPoint: the body ("" = world)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // kPoint: in the body frame [m]
  double friction = 0;                                // kPoint: capstan coefficient at a via point
  std::string obstacle;                               // kWrap: WrapObstacle name
  std::optional<Eigen::Vector3d> side;                // kWrap: side point in the obstacle's body frame
};

struct Tendon {
  std::string name;
  std::vector<PathElement> path;  // at least two points
  double radius = 0.001;          // for drawing and for contact with bodies [m]
  bool collide_with_bodies = true;  // go around bodies that are not declared obstacles
};

/// An actuator or passive element acting along a tendon. `kind` selects the model in
/// libs/actuators (dc_motor_tendon, ligament, hill_muscle, ...); new kinds register there.
struct Actuator {
  std::string name;
  std::string kind;
  std::string tendon;
  std::map<std::string, double> parameters;   // SI values, names as the kind declares them
  std::map<std::string, std::string> options;  // e.g. curves = thelen2003, elastic = zener
};

struct SimulationSettings {
  double time_step = 1e-3;     // [s]
  int solver_iterations = 10;  // constraint solver iterations per step
  double world_scale = 1.0;    // engine units per metre (keeps small robots in Bullet's range)
};

/// A sensor that reports a scene parameter late, as a DAQ channel on hardware does: a controller,
/// the DAQ and recordings read the parameter `id` as it was round(delay / time_step) steps ago
/// (0 to 1000 steps; 0 reads the value of the last completed step), and `<id>.undelayed` as it
/// is now. Before the scene has stepped that far the sensor reads the value it had at load, as if
/// constant since ever. An engine refuses (std::invalid_argument, at load or when the time step
/// changes) an id its Parameters() does not list, a model parameter (is_static), an id delayed
/// twice, a negative or non-finite delay, or one of more than 1000 steps.
struct MeasurementDelay {
  std::string id;    // a parameter id as PhysicsScene::Parameters() lists it, e.g. motor.current
  double delay = 0;  // [s]
};

struct Scene {
  std::string name;
  std::string source;  // file it came from, for messages
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);  // [m/s^2]
  SimulationSettings settings;
  std::vector<Material> materials;
  std::vector<Body> bodies;
  std::vector<Constraint> constraints;
  std::vector<Coupling> couplings;
  std::vector<WrapObstacle> obstacles;
  std::vector<Tendon> tendons;
  std::vector<Actuator> actuators;
  std::vector<MeasurementDelay> measurement_delays;  // channels read late

  const Body* FindBody(const std::string& name) const;
  const Tendon* FindTendon(const std::string& name) const;
  const WrapObstacle* FindObstacle(const std::string& name) const;
  int BodyIndex(const std::string& name) const;  // -1 when absent
};

/// Problems of a scene that no engine can simulate: dangling names, non-positive masses on dynamic
/// bodies, inertia tensors that are not symmetric positive definite, tendons with fewer than two
/// points, non-finite numbers. Each message names the element. Empty when the scene is sound.
std::vector<std::string> Validate(const Scene& scene);

}  // namespace caliper::sgal
