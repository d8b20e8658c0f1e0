#pragma once
// Pieces of the small scenes the physics tests build: a static base to hang things on, and a
// joint between two bodies whose frames are turned alike (its axis is their z).

#include <string>

#include "caliper/sgal/scene.h"

namespace caliper::testing {

/// A scene named `name` holding only a static body "base".
inline sgal::Scene SceneOnStaticBase(const std::string& name) {
  sgal::Scene s;
  s.name = name;
  sgal::Body base;
  base.name = "base";
  base.type = sgal::BodyType::kStatic;
  s.bodies.push_back(base);
  return s;
}

/// A joint `name` of `kind` holding `body_a` to `body_b`: its frame in body_a at body_a's origin,
/// in body_b at `position_in_b` [m], both turned by `orientation` (which puts the joint's axis,
/// z, where the test wants it).
inline sgal::Constraint Joint(const std::string& name, sgal::ConstraintKind kind,
                              const std::string& body_a, const std::string& body_b,
                              const Eigen::Quaterniond& orientation,
                              const Eigen::Vector3d& position_in_b = Eigen::Vector3d::Zero()) {
  sgal::Constraint c;
  c.name = name;
  c.kind = kind;
  c.body_a = body_a;
  c.body_b = body_b;
  c.frame_a.orientation = orientation;
  c.frame_b.position = position_in_b;
  c.frame_b.orientation = orientation;
  return c;
}

}  // namespace caliper::testing
