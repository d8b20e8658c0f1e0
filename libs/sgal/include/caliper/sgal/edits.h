#pragma once
// Edits of a scene (the GUI's scene editing, done by the Model): each one made against a scene
// and carrying its own revert, so that it applies to the scene as loaded and to the running
// engine's copy alike (both hold the same names) and can be undone. No CORBA here.

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::sgal {

/// An edit that names something the scene lacks or that would be unsound; nothing changed.
class EditError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct SceneEdit {
  std::string label;                      // what it does, for the undo menu and the log
  std::function<void(Scene&)> apply;      // throws EditError when the scene lacks a name
  std::function<void(Scene&)> revert;     // undoes apply on the scene apply changed
};

/// Moves path element `index` of `tendon` to the point `to` (a point element: body, position).
SceneEdit MovePathPoint(const Scene& scene, const std::string& tendon, size_t index,
                        const PathElement& to);
/// Inserts `element` (a via point or a wrap) before path element `index` (between the ends).
SceneEdit InsertPathPoint(const Scene& scene, const std::string& tendon, size_t index,
                          const PathElement& element);
/// Removes path element `index`; a tendon keeps its two end points.
SceneEdit RemovePathPoint(const Scene& scene, const std::string& tendon, size_t index);
/// A new tendon with one actuator along it (actuator.tendon is set to the tendon's name).
SceneEdit AddTendon(const Scene& scene, const Tendon& tendon, const Actuator& actuator);
/// Removes a tendon with every actuator along it.
SceneEdit RemoveTendon(const Scene& scene, const std::string& tendon);
/// Adds the obstacle, or moves and resizes the one of that name.
SceneEdit SetObstacle(const Scene& scene, const WrapObstacle& obstacle);
/// Removes an obstacle that no tendon wraps around.
SceneEdit RemoveObstacle(const Scene& scene, const std::string& obstacle);
/// Sets the dimensions of collision shape `index` of `body` (GeometryDims' order); a visual with
/// the shape's geometry and pose follows it.
SceneEdit SetShapeDims(const Scene& scene, const std::string& body, size_t index,
                       const std::vector<double>& dims);
/// Sets a dynamic body's mass [kg]; the inertia tensor scales with it.
SceneEdit SetMass(const Scene& scene, const std::string& body, double mass_kg);
/// Delays `channel` by `delay_s` [s] (a MeasurementDelay), or changes its delay; 0 removes its
/// delay. The id as the model file names it (motor.current) or as the DAQ lists it, after the
/// scene's name (arm.motor.current). The engine checks the id when it builds the edited scene.
SceneEdit SetMeasurementDelay(const Scene& scene, const std::string& channel, double delay_s);

/// A primitive's dimensions: box sx sy sz (full edges); sphere r; capsule, cylinder, cone r length;
/// plane nx ny nz offset; empty for meshes [m].
std::vector<double> GeometryDims(const Geometry& g);
/// `g` with other dimensions (GeometryDims' order); EditError for a wrong count, a non-finite or
/// non-positive length, or a mesh.
Geometry WithDims(const Geometry& g, const std::vector<double>& dims);

}  // namespace caliper::sgal
