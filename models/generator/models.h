#pragma once
// The robot models shipped in models/, built as scene descriptions. make_models writes them to
// COLLADA (models/*.dae); tests/models checks that the files still hold these scenes. SI units,
// Z up; every body has visuals with colours so that other COLLADA tools show it.

#include <string>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::models {

/// An anthropomimetic right arm in the spirit of the ECCE robot, hanging at rest: a static torso
/// with a neck post; a clavicle/scapula girdle on a sternoclavicular hinge (girdle_elevation);
/// a shoulder of two hinges (shoulder_abduction to a shoulder housing, shoulder_flexion to the
/// upper arm); elbow and wrist hinges. Ten dc_motor_tendon actuators in five antagonistic pairs
/// with linear or Zener series-elastic tendons over via points and wrap cylinders at the
/// shoulder, elbow and wrist; three ligaments; a biarticular Hill muscle (biceps).
sgal::Scene MakeEcceArm();

/// A pendulum hanging from a static frame, pulled up by one dc_motor_tendon against gravity.
sgal::Scene MakePendulumTendon();

/// A two-link arm moving in the horizontal plane (hinges about z), each joint driven by an
/// antagonistic pair of dc_motor_tendon actuators wrapping a pulley on the joint axis.
sgal::Scene MakeTwoLinkAntagonistic();

/// A shipped model: its file name in models/ and its scene.
struct Model {
  std::string file;  // e.g. ecce_arm.dae
  sgal::Scene scene;
};

/// Every shipped model.
std::vector<Model> AllModels();

}  // namespace caliper::models
