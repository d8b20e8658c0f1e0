#pragma once
// Tendon path geometry, engine-free: the polyline a tendon follows through its attachment and via
// points and around declared wrap obstacles (spheres, cylinders), its length, and the forces a
// tension exerts on the bodies along it. SI units.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::actuators {

/// A wrap obstacle placed in the world for the current body poses.
struct WorldObstacle {
  sgal::ObstacleKind kind = sgal::ObstacleKind::kCylinder;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // cylinder axis = pose z
  double radius = 0.01;  // [m]
  double length = 0.05;  // [m], cylinders
};

/// One element of a tendon path in world coordinates.
struct WorldElement {
  sgal::PathElement::Kind kind = sgal::PathElement::Kind::kPoint;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // kPoint: world position [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // kPoint: world velocity; kWrap: velocity of the obstacle's origin [m/s]
  int body = -1;           // body the point or obstacle is fixed to (-1: the world)
  double friction = 0;     // kPoint: capstan coefficient [-]
  WorldObstacle obstacle;  // kWrap
  std::optional<Eigen::Vector3d> side;  // kWrap: side point in world coordinates
};

/// A point of the evaluated path.
struct PathPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world [m]
  int body = -1;          // body that takes the force at this point (-1: the world)
  double friction = 0;    // capstan coefficient at this point [-]
  bool on_wrap = false;   // tangent or arc point on a wrap obstacle
  bool contact = false;   // inserted where the tendon presses on a body it is not routed over
};

struct PathGeometry {
  std::vector<PathPoint> points;  // in order from the first attachment to the last
  double length = 0;              // [m] (arcs measured exactly, not by their samples)
  double speed = 0;               // lengthening speed [m/s] (from the point velocities)
};

/// The force on one body at one path point.
struct PointForce {
  int body = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world [m]
  Eigen::Vector3d force = Eigen::Vector3d::Zero();     // world [N]
};

/// Evaluates one tendon's path. Keeps, per wrap element, which side the tendon took last time, so
/// that a path does not jump between sides from one step to the next.
class TendonPath {
 public:
  /// Path through the elements (points, with wraps between two points).
  PathGeometry Evaluate(const std::vector<WorldElement>& elements);
  /// The same into *path, reusing its storage (no allocation once it has grown: the engine's
  /// every step).
  void Evaluate(const std::vector<WorldElement>& elements, PathGeometry* path);
  /// The side each wrap took at the last evaluation (the state carried from step to step).
  const std::vector<int>& wrap_sides() const { return wrap_side_; }
  void set_wrap_sides(std::vector<int> sides) { wrap_side_ = std::move(sides); }

 private:
  std::vector<int> wrap_side_;  // per wrap element: 0 not wrapping, +1 / -1 side taken
};

/// The length of the straight pieces between consecutive points [m]: a path of points alone, as
/// TendonPath::Evaluate measures it (an engine that places such a path's points itself measures it
/// with this).
double StraightLength(const std::vector<PathPoint>& points);

/// The forces a tension [N] (at the actuator end, the first point) exerts: each point is pulled
/// toward its neighbours. With capstan friction at a point the tension changes there by
/// exp(-+mu alpha), alpha the angle the path turns, depending on the sliding direction
/// (`speed` > 0: the tendon is pulled out toward the first point). Forces on the world (-1)
/// are included too, so that all forces sum to zero when no friction acts.
std::vector<PointForce> PathForces(const PathGeometry& path, double tension);
/// The same into *forces, reusing its storage.
void PathForces(const PathGeometry& path, double tension, std::vector<PointForce>* forces);

}  // namespace caliper::actuators
