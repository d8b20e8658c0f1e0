#pragma once
// The benchmark robot: a 40-body tree (a 20-body spine with two 10-body arms, 39 hinges) with 80
// tendons, as a Caliper scene, as raw Bullet (the baseline) and as MJCF for MuJoCo.

#include <Eigen/Geometry>
#include <string>

#include "caliper/sgal/scene.h"

namespace caliper::bench {

struct TreeOptions {
  bool floor = true;           // a ground plane
  bool self_contact = true;    // bodies collide with each other (not with their hinge neighbours)
  bool spanning_tendons = false;  // tendons cross two joints, over the body between (they press on it)
  std::string actuator_kind = "dc_motor_tendon";
  int bodies = 40;   // a spine of half of them and two arms of a quarter each (a multiple of 4)
  int tendons = 80;  // two per joint and two long ones, repeated with other levers or cut short
  /// Which start of the ensemble: 0 upright, k > 0 the whole tree tilted by kStartTilt about its
  /// base, about a level axis at azimuth 2 pi (k - 1) / (kStarts - 1). The tree falls and tumbles,
  /// so its cost depends on where it lands: every engine runs the same starts.
  int start = 0;
};

constexpr int kStarts = 8;
constexpr double kStartTilt = 0.01;  // [rad]

/// The rotation of start `start` (about the tree's base, see TreeOptions::start).
Eigen::Quaterniond StartTilt(int start);

/// The scene with `actuator_kind` actuators on its 80 tendons.
sgal::Scene MakeTree(const TreeOptions& options);

/// The same model as MJCF, with motors on spatial tendons.
std::string MakeTreeMjcf(const TreeOptions& options);

}  // namespace caliper::bench
