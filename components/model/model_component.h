#pragma once
// The Model component (caliper-model): owns the physics of one scene and serves it.
//
// Configuration (config/model.conf):
//   model.scene             COLLADA file loaded at start ("" = none)
//   model.real_time_factor  1 = real time, 0 = as fast as possible
//   model.autostart         start simulating once loaded and active
//   model.tendon_contact    bend tendons around bodies they would cut through
//   model.read_dirs, model.write_dir   where paths from clients may lead (model_files.h)
// The execution context drives stepping: PERIODIC ticks advance the simulation by what the
// real-time factor makes due; an EXTERNAL context steps once per tick (lock-step).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "caliper/rtc/runtime.h"
#include "caliper/simulation/model_core.h"

namespace caliper::model {

class ModelComponent : public rtc::Component {
 public:
  explicit ModelComponent(rtc::Runtime& runtime);
  ~ModelComponent() override;

  rtc::ReturnCode OnInitialize() override;
  rtc::ReturnCode OnActivated() override;
  rtc::ReturnCode OnDeactivated() override;
  rtc::ReturnCode OnFinalize() override;
  rtc::ReturnCode OnExecute() override;

  simulation::ModelCore& core() { return *core_; }
  static std::vector<core::ConfigKey> ConfigKeys();

 private:
  /// Listens to the Logging component (log.service) so that recordings hold the whole
  /// session's log, every component's records; until then the Model's own records go in. True
  /// once registered.
  bool ListenToSessionLog();
  void StopLogWatch();

  rtc::Runtime& runtime_;
  std::unique_ptr<simulation::ModelCore> core_;
  bool autostart_;
  // looks for the Logging component every 2 s until found, on a thread of its own (naming
  // lookups never run on the stepping thread)
  std::thread log_watch_;
  std::mutex log_watch_mutex_;
  std::condition_variable log_watch_wake_;
  bool log_watch_stop_ = false;
};

}  // namespace caliper::model
