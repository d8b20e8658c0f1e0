#pragma once
// What the renderer draws, without CORBA: a mirror of Caliper::Scene::Description and
// Caliper::Scene::TendonState (idl/caliper/observer.idl). Lengths in metres.

#include <cstdint>
#include <string>
#include <vector>

namespace caliper::render_coin {

/// A rigid transform: position [m] and unit quaternion (w, x, y, z).
struct Pose {
  double p[3] = {0, 0, 0};     // position [m]
  double q[4] = {1, 0, 0, 0};  // orientation, w x y z
};

enum class ShapeKind { kBox, kSphere, kCapsule, kCylinder, kCone, kPlane, kConvexHull, kTriangleMesh };

/// dims: box sx sy sz (full edges); sphere r; capsule, cylinder, cone r length (along z; a
/// capsule's length is that of its cylinder); plane nx ny nz offset. Meshes index
/// SceneDescription::meshes (-1 for none).
struct Shape {
  ShapeKind kind = ShapeKind::kBox;
  std::vector<double> dims;
  int mesh = -1;
};

struct Mesh {
  std::vector<float> vertices;      // x y z ... [m]
  std::vector<uint32_t> triangles;  // three vertex indices per triangle
  std::vector<float> normals;       // per vertex, may be empty
};

struct Visual {
  std::string name;
  Shape geometry;
  Pose pose;                          // in the body frame
  float rgba[4] = {0.7f, 0.7f, 0.7f, 1.0f};  // colour and opacity
};

struct Body {
  std::string name;
  Pose pose;  // world frame
  bool moving = true;
  double mass = 0;  // [kg] (0 for a body that does not move)
  std::vector<Visual> visuals;
};

/// A wrap obstacle of the tendons, attached to a body.
struct Obstacle {
  std::string name;
  std::string body;    // name of the body it moves with ("" for the world)
  std::string kind;    // sphere, cylinder
  Pose pose;           // in the body frame; a cylinder's axis is z
  double radius = 0;   // [m]
  double length = 0;   // [m]
};

/// A joint between two bodies; hinge and slider axes are drawn (SceneGraph::SetConstraintAxesVisible).
struct Constraint {
  std::string name;
  std::string kind;    // hinge, slider, ball, fixed, generic_6dof
  std::string body_a;  // the body the axis is drawn on and moves with
  std::string body_b;  // "" for the world
  Pose frame_a;        // in body_a's frame; the axis is z
  Pose frame_b;        // in body_b's frame
};

/// One declared element of a tendon's path: a point fixed in a body, or a wrap around an obstacle.
struct PathPoint {
  std::string body;         // the body the point is fixed in ("" = the world)
  double p[3] = {0, 0, 0};  // in the body's frame [m]
  std::string obstacle;     // non-empty: a wrap around this obstacle (body and p unused)
};

struct Tendon {
  std::string name;
  double radius = 0;            // [m]
  std::vector<PathPoint> path;  // attachments, via points and wraps, in order
};

/// Something a user can pick: kind "body", "tendon", "path_point", "obstacle" or "" (nothing);
/// `index` is the path element of a path_point.
struct Entity {
  std::string kind;
  std::string name;
  uint32_t index = 0;
  bool operator==(const Entity& o) const {
    return kind == o.kind && name == o.name && index == o.index;
  }
  bool operator!=(const Entity& o) const { return !(*this == o); }
};

struct SceneDescription {
  std::string name;
  std::vector<Body> bodies;
  std::vector<Mesh> meshes;
  std::vector<Constraint> constraints;
  std::vector<Obstacle> obstacles;
  std::vector<Tendon> tendons;
};

/// The current path and tension of one tendon.
struct TendonState {
  uint32_t tendon_index = 0;   // into SceneDescription::tendons
  std::vector<double> points;  // x y z ... of the path, world frame [m]
  double length = 0;           // [m]
  double tension = 0;          // [N]
};

/// Where the camera is: looks from `position` at `look_at` with `up` upward.
struct CameraPose {
  double position[3] = {1, -1, 1};   // [m]
  double look_at[3] = {0, 0, 0};     // [m]
  double up[3] = {0, 0, 1};
  double height_angle = 0.785398;    // vertical field of view [rad]
};

}  // namespace caliper::render_coin
