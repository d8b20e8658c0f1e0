#pragma once
// A <visual_scene> instantiated: every node (also those reached through <instance_node>, once per
// instance) with its world transform in metres and Z up, and the geometry it draws.

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "document.h"
#include "import_context.h"

namespace caliper::collada::internal {

/// Geometry a node draws: an <instance_geometry> (or the <instance_controller> whose skin or
/// morph leads to it) and the <geometry>.
struct NodeGeometry {
  const Element* instance = nullptr;
  const Element* geometry = nullptr;
};

/// One instance of a <node>.
struct NodeInstance {
  const Element* node = nullptr;
  int parent = -1;  // index of the parent instance, -1 at the top
  Eigen::Affine3d parent_world = Eigen::Affine3d::Identity();  // [m], Z up
  Eigen::Affine3d world = Eigen::Affine3d::Identity();         // parent_world * local
  std::vector<NodeGeometry> geometry;
};

class VisualScene {
 public:
  explicit VisualScene(Context* context) : ctx_(*context) {}

  /// Instantiates the nodes of a <visual_scene>.
  void Build(const Element& visual_scene);

  const std::vector<NodeInstance>& nodes() const { return nodes_; }
  /// The instances of a <node> element (several when it is instanced several times).
  std::vector<int> InstancesOf(const Element* node) const;
  /// The product of a node's transform elements before `stop` (all of them when null) [m].
  Eigen::Affine3d Local(const Element& node, const Element* stop = nullptr) const;
  /// One transform element (translate, rotate, scale, matrix, lookat, skew) [m].
  Eigen::Affine3d TransformOf(const Element& t) const;
  /// Whether an element is one of the transform elements.
  static bool IsTransform(const Element& e);
  /// The world transform of the document's root frame (the up axis turned to Z).
  Eigen::Affine3d Root() const;

 private:
  void Visit(const Element& node, int parent, const Eigen::Affine3d& parent_world,
             std::vector<const Element*>* path);
  Context& ctx_;
  std::vector<NodeInstance> nodes_;
  std::multimap<const Element*, int> by_node_;
  bool warned_controller_ = false;
};

}  // namespace caliper::collada::internal
