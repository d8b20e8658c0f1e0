#pragma once
// The Scene Renderer's lifecycle: while active it keeps itself registered as a SceneObserver of
// the Model: every renderer.check_interval it looks the Model up in the naming service and adds
// its observer again (the Model keeps the id of an observer it still has), so that a restarted
// Model, or one that dropped the renderer after a long stop, finds it again. What the Model sends
// lands in the SceneMailbox, which the GUI thread drains.
//
// Configuration (config/renderer.conf):
//   renderer.model            instance name of the Model (model0)
//   renderer.check_interval   how often the registration is checked [s]
//   renderer.max_fps          largest frame rate of the view [Hz]
//   renderer.width, renderer.height   size of screenshots [px]
//   renderer.show_constraint_axes     draw the hinge and slider axes (false; also over CORBA)
//   renderer.write_dir        where the screenshot operation may write ('' = $CALIPER_FILES_DIR,
//                             else nowhere); relative paths start from it

#include <chrono>
#include <string>

#include "caliper/model.hh"
#include "caliper/rtc/runtime.h"
#include "model_edit_client.h"
#include "scene_mailbox.h"

namespace caliper::renderer {

class RendererComponent : public rtc::Component {
 public:
  /// `model` receives the Model found (nil while there is none) for the GUI's scene editing.
  RendererComponent(rtc::Runtime& runtime, SceneMailbox& mailbox, ModelReference& model);
  /// Lets go of the shared reference while the ORB still runs.
  ~RendererComponent() override;
  rtc::ReturnCode OnInitialize() override;
  rtc::ReturnCode OnActivated() override;
  rtc::ReturnCode OnExecute() override;
  rtc::ReturnCode OnDeactivated() override;
  static std::vector<core::ConfigKey> ConfigKeys();

 private:
  /// Registers with the Model found under renderer.model (again: add_observer keeps the id).
  void CheckRegistration();
  void Unregister();

  rtc::Runtime& runtime_;
  SceneMailbox& mailbox_;
  ModelReference& shared_model_;
  Caliper::Scene::SceneObserver_var observer_;
  Caliper::Simulation::Model_var model_;
  CORBA::ULongLong observer_id_ = 0;
  std::chrono::steady_clock::time_point next_check_{};
  bool reported_missing_ = false;
};

}  // namespace caliper::renderer
