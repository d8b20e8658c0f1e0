#pragma once
// CORBA face of the Model: converts, forwards to ModelCore, and runs one sender thread per
// observer and per data subscriber so that the simulation never waits on the network.

#include <atomic>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "caliper/model.hh"
#include "caliper/rtc/rtobject_servant.h"
#include "model_core.h"

namespace caliper::model {

/// Sends scene, cleared and transform updates to one SceneObserver from its own thread. Only the
/// latest snapshot is kept: a slow observer receives coalesced updates.
class ObserverSender : public CoreListener {
 public:
  explicit ObserverSender(Caliper::Scene::SceneObserver_ptr observer);
  ~ObserverSender() override;
  void OnScene(std::shared_ptr<const sgal::Scene> scene, uint64_t generation) override;
  void OnSnapshot(std::shared_ptr<const Snapshot> snapshot) override;
  void OnCleared() override;
  bool dead() const { return dead_; }
  /// Updates sent and snapshots replaced before they were sent.
  uint64_t sent() const { return sent_; }
  uint64_t coalesced() const { return coalesced_; }

 private:
  void Run();

  Caliper::Scene::SceneObserver_var observer_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool cleared_ = false;
  std::shared_ptr<const sgal::Scene> scene_;
  uint64_t scene_generation_ = 0;
  std::shared_ptr<const Snapshot> snapshot_;
  std::atomic<bool> dead_{false};
  std::atomic<uint64_t> sent_{0};
  std::atomic<uint64_t> coalesced_{0};
  std::thread thread_;
};

/// Delivers one subscription's batches to its DataConsumer from its own thread.
class ConsumerSender {
 public:
  ConsumerSender(ModelCore& core, uint64_t subscription, Caliper::Daq::DataConsumer_ptr consumer);
  ~ConsumerSender();
  bool dead() const { return dead_; }

 private:
  void Run();
  ModelCore& core_;
  uint64_t subscription_;
  Caliper::Daq::DataConsumer_var consumer_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> dead_{false};
  std::thread thread_;
};

class ModelServant : public virtual POA_Caliper::Simulation::Model, public rtc::RTObjectServant {
 public:
  ModelServant(rtc::Runtime& runtime, ModelCore& core);
  ~ModelServant() override;

  // SimulationControl
  void load_scene(const char* path) override;
  void load_scene_data(const char* file_name, const Caliper::Simulation::Octets& data) override;
  void start() override;
  void pause() override;
  void stop() override;
  void reset() override;
  CORBA::ULong step(CORBA::ULong n) override;
  void set_time_step(CORBA::Double seconds) override;
  void set_real_time_factor(CORBA::Double factor) override;
  Caliper::Simulation::SimulationStatus* status() override;
  // SceneManagement
  Caliper::Scene::Description* scene_description() override;
  void save_scene(const char* path) override;
  Caliper::Simulation::Octets* export_scene() override;
  // ExperimentRunner
  Caliper::Simulation::Recording* run_experiment(
      const Caliper::Simulation::Experiment& run) override;
  // MotorControl
  Caliper::Simulation::ActuatorInfoSeq* actuators() override;
  void set_command(const char* actuator, CORBA::Double value) override;
  void set_commands(const Caliper::Simulation::CommandSeq& commands) override;
  Caliper::Simulation::ActuatorStateSeq* actuator_states() override;
  // ParameterAccess
  Caliper::Daq::ChannelInfoSeq* list(const char* pattern) override;
  Caliper::Daq::ValueSeq* get(const Caliper::Scene::StringSeq& ids) override;
  void set(const char* id, const Caliper::Daq::Value& value) override;
  // DataAcquisition
  Caliper::Daq::ChannelInfoSeq* channels(const char* pattern) override;
  Caliper::Daq::ValueSeq* sample(const Caliper::Scene::StringSeq& ids) override;
  CORBA::ULongLong subscribe(const Caliper::Scene::StringSeq& ids, CORBA::ULong every_n_steps,
                             Caliper::Daq::DataConsumer_ptr consumer) override;
  void unsubscribe(CORBA::ULongLong subscription) override;
  // ObserverRegistry
  CORBA::ULongLong add_observer(Caliper::Scene::SceneObserver_ptr observer) override;
  void remove_observer(CORBA::ULongLong id) override;

 private:
  void DropDead();

  ModelCore& core_;
  std::mutex mutex_;
  std::map<uint64_t, std::unique_ptr<ObserverSender>> observers_;
  std::map<uint64_t, std::unique_ptr<ConsumerSender>> consumers_;
  uint64_t next_observer_ = 1;
};

/// The scene description as viewers receive it.
Caliper::Scene::Description* ToIdl(const sgal::Scene& scene);

}  // namespace caliper::model
