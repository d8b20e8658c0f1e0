#pragma once
// Registers the quantities of a running sgal::PhysicsScene as DAQ channels: every scene parameter
// as a scalar, and per body its pose and velocities. Engine-neutral (it sees only the sgal
// interface); the only part of libs/daq that knows sgal.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "caliper/daq/registry.h"
#include "caliper/sgal/physics_scene.h"

namespace caliper::daq {

/// A per-step cache of a scene's body states, shared by the body getters: however many body
/// channels are read in a step, PhysicsScene::BodyStates() runs at most once. Lives on the
/// simulation thread, like the registry.
class SceneSampler {
 public:
  /// `scene` must outlive the sampler and the channels that use it.
  explicit SceneSampler(const sgal::PhysicsScene& scene) : scene_(scene) {}

  /// Marks the cache out of date: call after every step (and after anything that moves bodies,
  /// e.g. a reset). The states are fetched again on the next read, so that a step nobody samples
  /// costs nothing.
  void Refresh() { fresh_ = false; }

  /// The state of body `index` (description().bodies order) at the current step.
  const sgal::BodyState& body(size_t index) {
    if (!fresh_) Fetch();
    return states_[index];
  }
  /// Body `index`'s rotation matrix (body to world) at the current step.
  const Eigen::Matrix3d& rotation(size_t index) {
    if (!fresh_) Fetch();
    return rotations_[index];
  }
  /// How many times the states were fetched from the scene.
  uint64_t fetches() const { return fetches_; }

 private:
  void Fetch();

  const sgal::PhysicsScene& scene_;
  bool fresh_ = false;
  uint64_t fetches_ = 0;
  std::vector<sgal::BodyState> states_;
  std::vector<Eigen::Matrix3d> rotations_;
};

/// What RegisterScene did.
struct SceneChannels {
  /// Refresh() it after every step of the scene.
  std::shared_ptr<SceneSampler> sampler;
  /// The ids registered, in registration order.
  std::vector<std::string> ids;
  /// Ids not registered because the registry already held them (e.g. a joint and a body of the
  /// same name both giving `<name>.position`; the first one registered wins).
  std::vector<std::string> skipped;
};

/// Registers under `<model_name>.`:
/// - every PhysicsScene parameter as a scalar `<model>.<param id>` with the scene's unit and
///   static flag; writable ones get a setter calling scene.SetParameter (a refused value raises
///   InvalidValue with the scene's reason);
/// - per body `<model>.<body>.position` (3x1, m, world frame), `.orientation` (4x1 unit quaternion
///   w x y z, body to world), `.rotation` (3x3 rotation matrix body to world, row-major),
///   `.linear_velocity` (3x1, m/s, of the body frame origin) and `.angular_velocity` (3x1, rad/s,
///   world frame), read through the returned sampler's per-step cache.
/// Tendon lengths, speeds and tensions and actuator states come with the parameters. `scene`
/// must outlive the channels: remove them (RemoveMatching(model_name + ".*") or Clear()) before
/// destroying it.
SceneChannels RegisterScene(Registry& registry, const std::string& model_name,
                            sgal::PhysicsScene& scene);

}  // namespace caliper::daq
