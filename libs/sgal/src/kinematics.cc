#include "caliper/sgal/kinematics.h"

#include <cmath>
#include <functional>
#include <stdexcept>

namespace caliper::sgal {

namespace {

using Eigen::Isometry3d;

bool OneDof(const Constraint& c) {
  return c.kind == ConstraintKind::kHinge || c.kind == ConstraintKind::kSlider;
}

bool Places(const Constraint& c) { return OneDof(c) || c.kind == ConstraintKind::kFixed; }

const char* KindName(ConstraintKind k) {
  static const char* const kNames[] = {"hinge", "slider", "ball", "fixed", "generic 6-DOF"};
  return kNames[static_cast<int>(k)];
}

/// The position of a hinge or slider from the poses of its two bodies (world when index < 0),
/// as BulletScene::UpdateJoints measures it.
double MeasuredPosition(const Constraint& c, const Isometry3d& pose_a, const Isometry3d& pose_b) {
  const Isometry3d fa = pose_a * c.frame_a.ToIsometry();
  const Isometry3d fb = pose_b * c.frame_b.ToIsometry();
  if (c.kind == ConstraintKind::kHinge) {
    const Eigen::Matrix3d rel = fb.linear().transpose() * fa.linear();
    return std::atan2(rel(1, 0), rel(0, 0));
  }
  return fb.linear().col(2).dot(fa.translation() - fb.translation());
}

/// body_a's joint frame relative to body_b's at position q.
Isometry3d Motion(const Constraint& c, double q) {
  Isometry3d m = Isometry3d::Identity();
  if (c.kind == ConstraintKind::kHinge)
    m.linear() = Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  else if (c.kind == ConstraintKind::kSlider)
    m.translation() = Eigen::Vector3d(0, 0, q);
  return m;
}

int BodyOf(const Scene& scene, const std::string& name, const Constraint& c) {
  if (name.empty()) return -1;
  const int index = scene.BodyIndex(name);
  if (index < 0)
    throw std::invalid_argument("forward kinematics: constraint '" + c.name + "': no body '" +
                                name + "'");
  return index;
}

}  // namespace

std::map<std::string, double> JointPositions(const Scene& scene) {
  std::map<std::string, double> positions;
  for (const auto& c : scene.constraints) {
    if (!OneDof(c)) continue;
    const int a = BodyOf(scene, c.body_a, c), b = BodyOf(scene, c.body_b, c);
    const Isometry3d pose_a = a < 0 ? Isometry3d::Identity() : scene.bodies[a].pose.ToIsometry();
    const Isometry3d pose_b = b < 0 ? Isometry3d::Identity() : scene.bodies[b].pose.ToIsometry();
    positions[c.name] = MeasuredPosition(c, pose_a, pose_b);
  }
  return positions;
}

std::vector<Pose> ForwardKinematics(const Scene& scene,
                                    const std::map<std::string, double>& joint_positions) {
  const std::string who =
      "forward kinematics of '" + (scene.source.empty() ? scene.name : scene.source) + "': ";
  std::map<std::string, const Constraint*> by_name;
  for (const auto& c : scene.constraints) by_name[c.name] = &c;
  for (const auto& [name, q] : joint_positions) {
    const auto it = by_name.find(name);
    if (it == by_name.end()) throw std::invalid_argument(who + "no joint '" + name + "'");
    if (!OneDof(*it->second))
      throw std::invalid_argument(who + "joint '" + name + "' is a " + KindName(it->second->kind) +
                                  "; only hinges and sliders take a position");
    if (!std::isfinite(q))
      throw std::invalid_argument(who + "joint '" + name + "': position is not finite");
  }

  // the position of every hinge and slider: given, else following its leader, else as described
  const std::map<std::string, double> described = JointPositions(scene);
  std::map<std::string, const Coupling*> leader_of;
  for (const auto& k : scene.couplings) {
    for (const std::string* n : {&k.leader, &k.follower}) {
      const auto it = by_name.find(*n);
      if (it == by_name.end())
        throw std::invalid_argument(who + "coupling of '" + k.follower + "': no joint '" + *n +
                                    "'");
      if (!OneDof(*it->second))
        throw std::invalid_argument(who + "coupling of '" + k.follower + "': joint '" + *n +
                                    "' is a " + KindName(it->second->kind) +
                                    "; couplings join hinges and sliders");
    }
    if (!leader_of.emplace(k.follower, &k).second)
      throw std::invalid_argument(who + "joint '" + k.follower + "' follows two couplings");
  }
  std::map<std::string, double> position;
  std::map<std::string, bool> resolving;
  std::function<double(const std::string&)> resolve = [&](const std::string& name) -> double {
    if (const auto done = position.find(name); done != position.end()) return done->second;
    double q;
    if (const auto given = joint_positions.find(name); given != joint_positions.end()) {
      q = given->second;
    } else if (const auto coupled = leader_of.find(name); coupled != leader_of.end()) {
      if (resolving[name])
        throw std::invalid_argument(who + "couplings form a cycle through joint '" + name + "'");
      resolving[name] = true;
      const Coupling& k = *coupled->second;
      q = k.ratio * resolve(k.leader) + k.offset;
    } else {
      q = described.at(name);
    }
    position[name] = q;
    return q;
  };

  // the tree: each body's placing constraint (the one whose body_a it is)
  const size_t n = scene.bodies.size();
  std::vector<const Constraint*> parent_joint(n, nullptr);
  std::vector<int> parent(n, -1);
  for (const auto& c : scene.constraints) {
    if (!Places(c)) continue;
    const int a = BodyOf(scene, c.body_a, c), b = BodyOf(scene, c.body_b, c);
    if (a < 0) throw std::invalid_argument(who + "constraint '" + c.name + "' has no body_a");
    if (scene.bodies[a].type != BodyType::kDynamic) continue;  // static and kinematic stay put
    if (a == b)
      throw std::invalid_argument(who + "constraint '" + c.name + "' joins body '" + c.body_a +
                                  "' to itself");
    if (parent_joint[a] != nullptr)
      throw std::invalid_argument(who + "kinematic loop: body '" + c.body_a +
                                  "' is the child (body_a) of both '" + parent_joint[a]->name +
                                  "' and '" + c.name + "'");
    parent_joint[a] = &c;
    parent[a] = b;
  }

  std::vector<Isometry3d> world(n);
  enum class State { kNew, kPlacing, kPlaced };
  std::vector<State> state(n, State::kNew);
  std::function<const Isometry3d&(int)> place = [&](int i) -> const Isometry3d& {
    if (state[i] == State::kPlaced) return world[i];
    if (state[i] == State::kPlacing)
      throw std::invalid_argument(who + "kinematic loop: the constraints through body '" +
                                  scene.bodies[i].name + "' form a cycle");
    state[i] = State::kPlacing;
    const Constraint* c = parent_joint[i];
    if (c == nullptr) {
      world[i] = scene.bodies[i].pose.ToIsometry();
    } else {
      const Isometry3d parent_pose = parent[i] < 0 ? Isometry3d::Identity() : place(parent[i]);
      const double q = OneDof(*c) ? resolve(c->name) : 0.0;
      world[i] =
          parent_pose * c->frame_b.ToIsometry() * Motion(*c, q) * c->frame_a.ToIsometry().inverse();
    }
    state[i] = State::kPlaced;
    return world[i];
  };
  std::vector<Pose> poses(n);
  for (size_t i = 0; i < n; ++i) poses[i] = Pose::FromIsometry(place(static_cast<int>(i)));
  return poses;
}

}  // namespace caliper::sgal
