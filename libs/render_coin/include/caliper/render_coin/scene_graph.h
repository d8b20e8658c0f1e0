#pragma once
// The Inventor scene of a Caliper model: one separator per body with a transform updated from the
// Model's poses, its visuals in their COLLADA colours, translucent wrap obstacles, tendons as lines
// through their path points coloured by tension (blue low .. red high) with a legend, a ground
// grid and world axes. Coin3D types appear only as forward declarations.
//
// Not thread-safe: build, update and render from the GUI thread.

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "caliper/render_coin/scene_description.h"

class SoCamera;
class SoSeparator;

namespace caliper::render_coin {

/// Initializes Coin's database once (idempotent); enough for building graphs without a display.
void InitializeCoin();

/// `local` (in the frame `pose`) in the world [m].
void ToWorld(const Pose& pose, const double local[3], double world[3]);
/// `world` in the frame `pose` [m].
void ToLocal(const Pose& pose, const double world[3], double local[3]);

/// What a ray through a pixel met: a pickable entity and the point where it met it [m, world].
struct Hit {
  Entity entity;
  double point[3] = {0, 0, 0};
};

class SceneGraph {
 public:
  /// Calls InitializeCoin(). The graph starts empty (grid and axes only).
  SceneGraph();
  ~SceneGraph();
  SceneGraph(const SceneGraph&) = delete;
  SceneGraph& operator=(const SceneGraph&) = delete;

  /// Replaces the model content (bodies, obstacles, tendons) with `scene`.
  void Build(const SceneDescription& scene);
  /// Removes the model content.
  void Clear();
  /// Moves bodies: poses[i] is the world pose of body indices[i]; unknown indices are ignored.
  void SetBodyPoses(const std::vector<uint32_t>& indices, const std::vector<Pose>& poses);
  /// Redraws the listed tendons through their points, coloured by tension on the current scale.
  void SetTendons(const std::vector<TendonState>& tendons);

  /// Shows or hides the axes of the hinge (cyan) and slider (orange) constraints: a short line
  /// along the z axis of frame_a on body_a, moving with the body. Hidden by default; the setting
  /// outlives Build() and Clear().
  void SetConstraintAxesVisible(bool on);
  bool constraint_axes_visible() const;
  /// Hinge and slider axes in the current scene (drawn or not).
  size_t constraint_axis_count() const;

  size_t body_count() const;
  size_t tendon_count() const;
  /// World pose of a body as last set.
  Pose body_pose(size_t index) const;
  /// Tension that maps to full red [N]: the largest seen so far, at least 1 N.
  double tension_scale() const { return tension_scale_; }
  /// The legend's text, e.g. "tendon tension  0 N (blue) .. 12.5 N (red)".
  std::string legend_text() const;
  /// Colour of a tendon as last drawn (rgb in [0, 1]).
  std::array<float, 3> tendon_color(size_t index) const;
  /// Blue (0) .. purple .. red (1); fractions are clamped.
  static std::array<float, 3> TensionColor(double fraction);

  /// Axis-aligned world bounds of the bodies; false when there are none.
  bool BodyBounds(std::array<double, 3>* min, std::array<double, 3>* max) const;

  /// Frames all bodies, keeping the viewing direction; `aspect` = width / height.
  void ViewAll(double aspect);
  void SetCamera(const CameraPose& camera);
  /// Sets the camera's near and far distances to enclose everything drawn (an interactive viewer
  /// adjusts them only when it draws; offscreen renders call this).
  void FitClippingPlanes();
  CameraPose camera_pose() const;

  /// The description last built (empty after Clear()).
  const SceneDescription& scene() const;
  /// The state last received of tendon `index`; nullptr before any.
  const TendonState* tendon_state(size_t index) const;
  /// Index of the body `name` in scene().bodies; -1 when there is none.
  int body_index(const std::string& name) const;
  /// Current world pose of body `name`; the identity for "" (the world). False when unknown.
  bool BodyPose(const std::string& name, Pose* pose) const;

  /// The entities under pixel (x, y) (from the top left) of a width x height view, nearest first
  /// (the same entity may appear more than once). Bodies, tendons, path points (markers drawn
  /// at the declared attachments and via points) and obstacles are pickable; the grid is not.
  std::vector<Hit> Pick(double x, double y, int width, int height) const;
  /// The ray through pixel (x, y) of a width x height view: origin and unit direction [world].
  void Ray(double x, double y, int width, int height, double origin[3], double direction[3]) const;
  /// The camera's unit viewing direction [world].
  std::array<double, 3> view_direction() const;

  /// Highlights one entity (kind "" for none); kept across Build() while it exists.
  void SetHighlight(const Entity& entity);
  const Entity& highlight() const;
  /// Draws the marker of path element `index` of `tendon` at `local` (its body's frame [m]),
  /// nullptr: at its declared place.
  void SetPathPointMarker(const std::string& tendon, uint32_t index, const double* local);
  /// Where the marker of that path element is drawn (its body's frame [m]); false if none.
  bool PathPointMarker(const std::string& tendon, uint32_t index, double local[3]) const;
  /// Draws obstacle `name` at `pose` (its body's frame), nullptr: at its declared pose.
  void SetObstacleMarker(const std::string& name, const Pose* pose);
  /// A line from `local` on body `body` (it moves with the body) to `target` [m, world];
  /// body < 0 hides it.
  void SetPullLine(int body, const double local[3], const double target[3]);
  bool pull_line_visible() const;
  /// A line of text at the top left of the view (what is selected, why an edit was refused).
  void SetStatus(const std::string& text);
  std::string status_text() const;
  /// Markers of path points (attachments and via points; wraps have none) in the scene.
  size_t path_point_count() const;

  /// What viewers show: the camera, the content and the legend (owned by this graph).
  SoSeparator* root() const;
  SoCamera* camera() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double tension_scale_ = 1.0;
};

}  // namespace caliper::render_coin
