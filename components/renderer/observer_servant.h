#pragma once
// The renderer's SceneObserver: converts what the Model sends into plain descriptions and leaves
// them in the mailbox for the GUI thread. Never throws a C++ exception to the ORB.
//
// Transforms older than the newest applied since the last scene are ignored: after the renderer
// was stopped (SIGSTOP, a busy machine), calls the Model gave up on (its push deadline passed)
// still arrive, on connections of their own, in any order, mixed with current ones.

#include <cstdint>
#include <mutex>

#include "caliper/observer.hh"
#include "scene_mailbox.h"

namespace caliper::renderer {

class ObserverServant : public virtual POA_Caliper::Scene::SceneObserver {
 public:
  /// The most visuals a scene may have to be drawn: Coin takes about 7 KB for each, so a scene
  /// of small visuals filling one message (256 MiB) would take tens of GB. A larger scene is not
  /// shown (the view is cleared) and the log says why.
  static constexpr size_t kMaxVisuals = 20000;

  explicit ObserverServant(SceneMailbox& mailbox) : mailbox_(mailbox) {}
  void on_scene(const Caliper::Scene::Description& scene) override;
  void on_transforms(CORBA::ULongLong update, CORBA::Double sim_time,
                     const Caliper::Scene::BodyTransformSeq& changed,
                     const Caliper::Scene::TendonStateSeq& tendons) override;
  void on_scene_cleared() override;

 private:
  SceneMailbox& mailbox_;
  std::mutex mutex_;           // orders the check of `update` with the hand-over to the mailbox
  uint64_t last_update_ = 0;  // the Model's update counter of the newest transforms applied
};

/// The plain mirror of an IDL frame.
render_coin::Pose FromIdl(const Caliper::Scene::Frame& frame);
/// The plain mirror of an IDL scene description.
render_coin::SceneDescription FromIdl(const Caliper::Scene::Description& scene);

}  // namespace caliper::renderer
