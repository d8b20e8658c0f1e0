#pragma once
// The URDF robots of the reference corpus (corpus/urdf/SOURCES.md) and what their files declare.
// Every number was counted from the files themselves with Python's xml.etree (not with liburdfdom,
// Caliper or MuJoCo), so the importer and MuJoCo are both checked against the files:
//
// | robot  | links | joints: rev cont prism fixed | moving | no <inertial> | declared mass [kg] |
// | UR5    | 11    | 6 0 0 4                      | 6      | 1 (world)     | 20.9939            |
// | Panda  | 13    | 7 0 2 3 (1 mimic)            | 9      | 0             | 17.451901          |
// | Kinova | 13    | 3 3 0 6                      | 6      | 0             | 4.83784            |
// | PR2    | 82    | 25 4 1 51 (10 mimic)         | 30     | 14            | 257.164323         |
// | iiwa   | 8     | 7 0 0 0                      | 7      | 0             | 17.5               |
// | R2D2   | 16    | 2 5 1 7                      | 8      | 0             | 65.25              |
//
// - Links without <inertial>: UR5's root "world" and PR2's 14 frames (optical, LED, tool and finger
//   tip frames); every one of them hangs on a fixed joint, none is the child of a moving joint,
//   so merging fixed joints leaves no body without a declared inertial. Their mass is 0 kg.
// - Links with <mass value="0">: UR5 base, ee_link, tool0; Panda panda_link8, panda_hand_tcp;
//   Kinova base, j2s6s200_end_effector; iiwa lbr_iiwa_link_0 (its root, fixed to the world). All
//   but the iiwa root are merged into a parent with mass.
// - Bodies after merging fixed joints: one per moving joint plus the root body.
// - UR5's root is a link named "world" (no <inertial>, Gazebo's convention for the world itself)
//   with base_link (4 kg) fixed to it and base (0 kg) fixed to base_link.
// - Mesh files: UR5 and Panda COLLADA visuals and STL collisions; Kinova COLLADA only; PR2 STL
//   only; iiwa OBJ visuals and STL collisions; R2D2 primitives and 2 STL files.
// - panda_collision.urdf is panda.urdf with primitive collision shapes (capsules, spheres) and
//   COLLADA visuals; same links, joints and masses.

#include <ostream>

namespace caliper::testing {

struct CorpusRobot {
  const char* name;
  const char* path;  // below corpus/urdf
  int links;
  int revolute, continuous, prismatic, fixed;
  int mimic;                   // joints with <mimic> (followers)
  int links_without_inertial;  // all on fixed joints (see above)
  double declared_mass;        // sum of every <mass value> [kg]
  const char* root;            // the link without a parent
  const char* base;            // the static body: the root, or the link fixed to "world"
  const char* zero_mass[3];    // links other than the base with <mass value="0">
  int moving() const { return revolute + continuous + prismatic; }
  int joints() const { return moving() + fixed; }
  int merged_bodies() const { return moving() + 1; }  // the base and one per moving joint
};

// GoogleTest prints a parameter by its name rather than its bytes.
inline void PrintTo(const CorpusRobot& robot, std::ostream* os) { *os << robot.name; }

inline constexpr CorpusRobot kCorpusRobots[] = {
    {"UR5",
     "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf",
     11,
     6,
     0,
     0,
     4,
     0,
     1,
     20.9939,
     "world",
     "base_link",
     {"base", "ee_link", "tool0"}},
    {"Panda",
     "example-robot-data/robots/panda_description/urdf/panda.urdf",
     13,
     7,
     0,
     2,
     3,
     1,
     0,
     17.451901,
     "panda_link0",
     "panda_link0",
     {"panda_link8", "panda_hand_tcp"}},
    {"PandaCollision",
     "example-robot-data/robots/panda_description/urdf/panda_collision.urdf",
     13,
     7,
     0,
     2,
     3,
     1,
     0,
     17.451901,
     "panda_link0",
     "panda_link0",
     {"panda_link8", "panda_hand_tcp"}},
    {"Kinova",
     "example-robot-data/robots/kinova_description/robots/kinova.urdf",
     13,
     3,
     3,
     0,
     6,
     0,
     0,
     4.83784,
     "base",
     "base",
     {"j2s6s200_end_effector"}},
    {"PR2",
     "example-robot-data/robots/pr2_description/urdf/pr2.urdf",
     82,
     25,
     4,
     1,
     51,
     10,
     14,
     257.164323,
     "base_footprint",
     "base_footprint",
     {}},
    {"KukaIiwa",
     "bullet3-data/kuka_iiwa/model.urdf",
     8,
     7,
     0,
     0,
     0,
     0,
     0,
     17.5,
     "lbr_iiwa_link_0",
     "lbr_iiwa_link_0",
     {}},
    {"R2D2", "bullet3-data/r2d2.urdf", 16, 2, 5, 1, 7, 0, 0, 65.25, "base_link", "base_link", {}},
};

}  // namespace caliper::testing
