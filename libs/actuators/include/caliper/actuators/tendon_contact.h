#pragma once
// Tendons that never pass through the skeleton: where a path segment would cut through a body
// that is not one of its declared wrap obstacles, the path is bent around the body's surface, as a
// taut string would be. Stateless and engine-free: an engine supplies the shapes near a segment
// (by a scan of the shapes' bounding balls or a broadphase), this computes the detour points. SI
// units.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <optional>
#include <vector>

#include "caliper/actuators/tendon_path.h"
#include "caliper/sgal/scene.h"

namespace caliper::actuators {

/// A collision shape placed in the world.
struct WorldShape {
  const sgal::Geometry* geometry = nullptr;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  int body = -1;
  /// sgal::BoundingRadius of the geometry about the pose's origin [m], infinite for planes; an
  /// engine sets it once per shape (PrepareShape). Negative: not known, computed at each use.
  double bounding_radius = -1;
  /// Convex hulls and meshes: their local bounding box as (centre, half extents) [m], set once
  /// by PrepareShape; without it each test reads every vertex again.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> mesh_box;
};

/// Sets what does not change as the shape moves (bounding radius, a mesh's box), once per shape
/// after its geometry is set.
void PrepareShape(WorldShape* shape);

/// The part of the segment a + t (b - a), t in [0, 1], inside the shape grown by `margin`, or
/// nothing. Exact for box, sphere, capsule, cylinder, cone (as its bounding cylinder) and plane;
/// convex hulls and meshes are taken by their local bounding box.
std::optional<std::pair<double, double>> SegmentInside(const WorldShape& shape,
                                                       const Eigen::Vector3d& a,
                                                       const Eigen::Vector3d& b, double margin);

/// Appends the shapes whose bounds come within `pad` of the box around a-b (an engine's
/// broadphase query). The shapes are the engine's, not copies: they must stay in place until
/// WrapAroundBodies returns.
using ShapeQuery = std::function<void(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      double pad, std::vector<const WorldShape*>* out)>;

struct ContactOptions {
  double margin = 0.001;  ///< tendon radius: how far the path stays from surfaces [m]
  int max_depth = 3;      ///< bisections per crossing: up to 2^depth - 1 points per body
  /// Spheres and capsules: the taut string's exact shortest way around the shape, with its exact
  /// length (closed form for a sphere and for a capsule crossed over one cap; Newton's method on
  /// where the string crosses the end circles for a capsule crossed over both caps), drawn as a
  /// polygon whose edges touch the surface and turn by at most 45 degrees. Taken when no other
  /// shape cuts it; otherwise, and for other shapes and crossings, the bisection.
  bool exact_wraps = true;
  /// Reach of the detour points beyond a segment: 2.1 times the largest shape's bounding radius,
  /// grown by twice the margin [m]. One query per routed segment with this padding serves the
  /// whole refinement; an exact wrap that would reach farther is left to the bisection.
  double detour_reach = 0.1;
};

/// Bends a path around every body it would pass through, except the bodies the segment's own
/// routed end points (attachments, via points, declared wraps) sit on. Inserted points are marked
/// `contact` and carry the body they press on. Returns the number of inserted points; `path`
/// (points and length) is updated in place.
int WrapAroundBodies(PathGeometry* path, const ShapeQuery& query, const ContactOptions& options);

/// Buffers WrapAroundBodies reuses from call to call, so that a step allocates nothing once they
/// have grown to the largest path (one per engine is enough: calls do not overlap).
struct ContactScratch {
  /// A shape the query gave for one segment, with what the search tests first, packed.
  struct Candidate {
    Eigen::Vector3d centre;  ///< the shape's origin in the world [m]
    double reach2;           ///< (bounding radius + margin)^2 [m^2], infinite for planes
    double reach;            ///< bounding radius + margin [m]
    double distance2;        ///< squared distance of the centre from the routed segment [m^2]
    int body;
    const WorldShape* shape;
  };
  std::vector<PathPoint> points;          // the bent path being built
  std::vector<const WorldShape*> shapes;  // the query's answer for one segment
  std::vector<Candidate> candidates;      // the same, packed
  std::vector<Candidate> near;            // those the detours built so far can come near
  /// An exact wrap in `points`: its pieces run from point `first` to point `last`; its exact
  /// length [m].
  struct Wrapped {
    size_t first, last;
    double length;
  };
  std::vector<Wrapped> wrapped;  // in order
};

/// The same, with the caller's buffers. `path->points` and `scratch->points` may be swapped.
int WrapAroundBodies(PathGeometry* path, const ShapeQuery& query, const ContactOptions& options,
                     ContactScratch* scratch);

/// What one tendon's last full searches proved, so that a later step can skip a search whose
/// answer is known: a routed segment that cleared every shape by `clearance` still clears them
/// all while its ends and the shapes together have moved less than that. One per tendon, kept
/// by the engine; it never changes a result, only saves work (an empty one is always right).
struct ContactMemory {
  struct Segment {
    Eigen::Vector3d a, b;                ///< the routed ends when the clearance was measured [m]
    int exclude_a = -3, exclude_b = -3;  ///< the bodies the segment may touch (its ends' bodies)
    /// How much farther than its bounding ball (grown by the margin) every shape not in `near`
    /// was from the segment, less a rounding allowance [m]; negative when the segment pressed
    /// on a body (nothing is skipped then).
    double clearance = -1;
    double travel = 0;  ///< the shapes' travel (see WrapAroundBodies) when measured [m]
    /// The shapes the query gave nearer than `clearance`, with their own clearance and origin
    /// when measured [m]: they are followed by their own displacement against the segment's (a
    /// tree that falls or swings as a whole keeps its segments proven), the rest by `travel`.
    struct Near {
      const WorldShape* shape;
      double clearance;
      Eigen::Vector3d centre;
    };
    std::vector<Near> near;
    /// The planes it may touch: no clearance bounds them, they are tested at every step.
    std::vector<const WorldShape*> planes;
  };
  std::vector<Segment> segments;
  double margin = -1;  ///< the margin the clearances hold for [m]
  /// Forgets everything (after the shapes were built again or replaced).
  void Clear() {
    segments.clear();
    margin = -1;
  }
};

/// The same, skipping the search of every routed segment that `memory` proves clear, and
/// remembering what the full searches prove. `travel` [m] bounds how far any shape's origin can
/// have moved: it must never decrease and must grow by at least each shape's displacement
/// between calls (an engine sums the largest displacement at each refresh of the poses). Planes
/// (infinite bounding radius) are tested at every call instead. The query must give every
/// plane and every shape whose bounding ball comes within `pad` of the box around the segment,
/// as ShapeQuery says, and the shapes must stay in place while the memory holds them.
int WrapAroundBodies(PathGeometry* path, const ShapeQuery& query, const ContactOptions& options,
                     ContactScratch* scratch, ContactMemory* memory, double travel);

}  // namespace caliper::actuators
