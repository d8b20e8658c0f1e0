#pragma once
// MuJoCo's 2-link, 6-muscle planar arm (model/tendon_arm/arm26.xml in the reference corpus) rebuilt
// as an sgal scene, with its forward kinematics, so that tendon geometry and muscles can be checked
// against the numbers Debian's MuJoCo 2.2.2 computed for it (mujoco222_generated/).

#include <vector>

#include "caliper/actuators/tendon_path.h"
#include "caliper/sgal/scene.h"

namespace caliper::testing {

/// The arm26 model: bodies `upper_arm` and `forearm` (capsules, mass from MuJoCo's default density
/// 1000 kg/m^3), a static `floor`, hinges `shoulder` (upper_arm to the world) and `elbow` (forearm
/// to upper_arm) about world z, limited to 0..120 degrees with damping 0.1 N m s/rad, cylinder wrap
/// obstacles `shoulder` (r 0.1 m) and `elbow` (r 0.08 m) on the hinge axes, tendons SF, SE, EF, EE,
/// BF, BE with the XML's sites and side sites, and one `hill_muscle` (curves = mujoco) per tendon
/// with the parameters MuJoCo 2.2.2 compiled. Sgal keeps a side point in the obstacle's body frame;
/// the XML's side sites x0 (world) and x1 (upper arm) are stored there as placed at zero angles.
sgal::Scene MakeArm26();

/// The path elements of `tendon` (one of MakeArm26()'s) in world coordinates with the shoulder and
/// elbow at the given angles [rad], all at rest. Body indices are those of the scene.
std::vector<actuators::WorldElement> Arm26Elements(const sgal::Scene& scene,
                                                   const sgal::Tendon& tendon, double shoulder_rad,
                                                   double elbow_rad);

/// The same with joint speeds [rad/s]: points carry their velocities and wrap elements the
/// velocity of their obstacle's origin.
std::vector<actuators::WorldElement> Arm26Elements(const sgal::Scene& scene,
                                                   const sgal::Tendon& tendon, double shoulder_rad,
                                                   double elbow_rad, double shoulder_speed,
                                                   double elbow_speed);

}  // namespace caliper::testing
