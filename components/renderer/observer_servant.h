#pragma once
// The renderer's SceneObserver: converts what the Model sends into plain descriptions and leaves
// them in the mailbox for the GUI thread. Never throws a C++ exception to the ORB.

#include "caliper/observer.hh"
#include "scene_mailbox.h"

namespace caliper::renderer {

class ObserverServant : public virtual POA_Caliper::Scene::SceneObserver {
 public:
  explicit ObserverServant(SceneMailbox& mailbox) : mailbox_(mailbox) {}
  void on_scene(const Caliper::Scene::Description& scene) override;
  void on_transforms(CORBA::ULongLong update, CORBA::Double sim_time,
                     const Caliper::Scene::BodyTransformSeq& changed,
                     const Caliper::Scene::TendonStateSeq& tendons) override;
  void on_scene_cleared() override;

 private:
  SceneMailbox& mailbox_;
};

/// The plain mirror of an IDL frame.
render_coin::Pose FromIdl(const Caliper::Scene::Frame& frame);
/// The plain mirror of an IDL scene description.
render_coin::SceneDescription FromIdl(const Caliper::Scene::Description& scene);

}  // namespace caliper::renderer
