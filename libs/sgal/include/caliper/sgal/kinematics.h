#pragma once
// Forward kinematics of a scene description: where every body is when its joints stand at given
// positions. No engine: exact in double precision, for cross-checks against other readers of the
// same robot (MuJoCo) and for posing a model before it runs.

#include <map>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::sgal {

/// The position [rad or m] of each hinge and slider as the description's poses give it, with the
/// meaning PhysicsScene's `JOINT.position` has: a hinge's is the rotation of body_a's joint frame
/// relative to body_b's about their z axis, in (-pi, pi]; a slider's the displacement of body_a's
/// joint frame from body_b's along body_b's z. Other constraints are absent.
std::map<std::string, double> JointPositions(const Scene& scene);

/// World poses of every body, in description order, with each named hinge or slider at the
/// given position [rad or m] (same meaning as JointPositions).
///
/// The bodies form a tree through the hinge, slider and fixed constraints (body_a the child,
/// body_b the parent, the world when empty): a body that is no such constraint's body_a (the
/// static bodies, the bodies hinged to the world, a floating base) keeps its description pose,
/// and each child is placed from its parent through the joint's frames, exactly: body_a =
/// body_b * frame_b * motion(q) * frame_a^-1. Joints not named keep the position they have in the
/// description; the follower of a coupling that is not named follows its leader (q_follower =
/// ratio * q_leader + offset, chains of couplings in turn). Ball and generic 6-DOF constraints do
/// not place their body_a (it keeps its description pose, as a root of its own subtree); static
/// and kinematic bodies never move.
///
/// Throws std::invalid_argument naming the element for: a name that is no constraint, a named
/// constraint that is not a hinge or slider, a non-finite position, a kinematic loop (a body that
/// is body_a of two placing constraints, or a cycle of them), a coupling cycle, or a scene that
/// Validate rejects in what this needs (unknown bodies).
std::vector<Pose> ForwardKinematics(const Scene& scene,
                                    const std::map<std::string, double>& joint_positions);

}  // namespace caliper::sgal
