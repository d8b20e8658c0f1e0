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

/// A per-step cache of a scene's body states, laid out as the body channels read them, shared
/// by those channels: however many are read in a step, PhysicsScene::BodyStates() runs at most
/// once, and a recorder copies neighbouring channels' values in one go (see Source). Lives on
/// the simulation thread, like the registry.
class SceneSampler : public SourceBlock {
 public:
  /// Offsets of a body's quantities within its kValuesPerBody values, in the order of its
  /// channels: position (3), orientation quaternion w x y z (4), rotation matrix row-major (9),
  /// linear velocity (3), angular velocity (3).
  static constexpr size_t kPosition = 0;
  static constexpr size_t kOrientation = 3;
  static constexpr size_t kRotation = 7;
  static constexpr size_t kLinearVelocity = 16;
  static constexpr size_t kAngularVelocity = 19;
  static constexpr size_t kValuesPerBody = 22;

  /// `scene` must outlive the sampler and the channels that use it; its number of bodies is
  /// taken now (a scene with another number of bodies needs a new sampler).
  explicit SceneSampler(const sgal::PhysicsScene& scene);

  /// Marks the cache out of date: call after every step (and after anything that moves bodies,
  /// e.g. a reset). The states are fetched again on the next read, so that a step nobody samples
  /// costs nothing.
  void Refresh() { fresh_ = false; }
  /// Fetches the states when out of date. Throws std::runtime_error when the scene no longer has
  /// the number of bodies it had when the sampler was made.
  void Update() override {
    if (!fresh_) Fetch();
  }

  /// The kValuesPerBody values of body `index` (description().bodies order); at a fixed address
  /// for the sampler's lifetime, up to date after Update().
  const double* values(size_t index) const { return values_.data() + index * kValuesPerBody; }
  /// How many times the states were fetched from the scene.
  uint64_t fetches() const { return fetches_; }

 private:
  void Fetch();

  const sgal::PhysicsScene& scene_;
  const size_t body_count_;
  bool fresh_ = false;
  uint64_t fetches_ = 0;
  std::vector<double> values_;  // body_count_ * kValuesPerBody, never resized
  std::vector<sgal::BodyState> states_;  // what the scene gave, its memory reused
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
