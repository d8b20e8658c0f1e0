#pragma once
// CORBA face of the Model: checks arguments, forwards to ModelCore under its lock and maps its
// exceptions to the IDL's; conversions live in model_convert.h, the senders to observers and
// subscribers in push_pool.h.

#include <atomic>
#include <cstdint>

#include "caliper/model.hh"
#include "caliper/rtc/rtobject_servant.h"
#include "caliper/simulation/model_core.h"
#include "caliper/simulation/model_files.h"
#include "push_pool.h"

namespace caliper::model {

class ModelServant : public virtual POA_Caliper::Simulation::Model, public rtc::RTObjectServant {
 public:
  ModelServant(rtc::Runtime& runtime, simulation::ModelCore& core, const PushLimits& limits = {});
  ~ModelServant() override;

  // SimulationControl
  void load_scene(const char* path) override;
  void load_scene_data(const char* file_name, const Caliper::Simulation::Octets& data) override;
  void start() override;
  void pause() override;
  void stop() override;
  void reset() override;
  CORBA::ULong step(CORBA::ULong n) override;
  Caliper::Simulation::CycleResult* control_cycle(const Caliper::Simulation::CommandSeq& commands,
                                                  CORBA::ULong n,
                                                  const Caliper::Scene::StringSeq& ids) override;
  void set_time_step(CORBA::Double seconds) override;
  void set_real_time_factor(CORBA::Double factor) override;
  Caliper::Simulation::SimulationStatus* status() override;
  // SceneManagement
  Caliper::Scene::Description* scene_description() override;
  void save_scene(const char* path) override;
  Caliper::Simulation::Octets* export_scene() override;
  Caliper::Simulation::FileAccess* file_access() override;
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
  CORBA::ULongLong subscribe_lossless(const Caliper::Scene::StringSeq& ids,
                                      CORBA::ULong every_n_steps,
                                      Caliper::Daq::DataConsumer_ptr consumer) override;
  Caliper::Daq::SubscriptionStatus subscription_status(CORBA::ULongLong subscription) override;
  // ObserverRegistry
  CORBA::ULongLong add_observer(Caliper::Scene::SceneObserver_ptr observer) override;
  void remove_observer(CORBA::ULongLong id) override;
  // SceneEditing
  Caliper::Simulation::EditStatus* move_path_point(const char* tendon, CORBA::ULong index,
                                                   const Caliper::Scene::PathPoint& point) override;
  Caliper::Simulation::EditStatus* insert_path_point(
      const char* tendon, CORBA::ULong index, const Caliper::Scene::PathPoint& point) override;
  Caliper::Simulation::EditStatus* remove_path_point(const char* tendon,
                                                     CORBA::ULong index) override;
  Caliper::Simulation::EditStatus* add_tendon(const char* tendon,
                                              const Caliper::Scene::PathPoint& from,
                                              const Caliper::Scene::PathPoint& to,
                                              CORBA::Double radius_m, const char* actuator,
                                              const char* kind) override;
  Caliper::Simulation::EditStatus* remove_tendon(const char* tendon) override;
  Caliper::Simulation::EditStatus* set_obstacle(const Caliper::Scene::Obstacle& obstacle) override;
  Caliper::Simulation::EditStatus* remove_obstacle(const char* obstacle) override;
  Caliper::Simulation::EditStatus* set_shape_dims(const char* body, CORBA::ULong index,
                                                  const Caliper::Scene::DoubleSeq& dims) override;
  Caliper::Simulation::EditStatus* set_mass(const char* body, CORBA::Double mass_kg) override;
  Caliper::Simulation::EditStatus* set_measurement_delay(const char* id,
                                                         CORBA::Double delay_s) override;
  Caliper::Scene::SensorDelaySeq* measurement_delays() override;
  Caliper::Simulation::EditStatus* undo() override;
  Caliper::Simulation::EditStatus* redo() override;
  Caliper::Simulation::EditStatus* edit_status() override;
  Caliper::Scene::VisualSeq* body_shapes(const char* body) override;
  Caliper::Simulation::ActuatorKindSeq* actuator_kinds() override;
  void pull(const char* body, const Caliper::Simulation::Vector3& point,
            const Caliper::Simulation::Vector3& target, CORBA::Double stiffness_n_per_m) override;
  void release_pull() override;
  void select(const char* kind, const char* name, CORBA::ULong index) override;
  Caliper::Simulation::Selection* current_selection() override;
  // SessionRecording
  Caliper::Simulation::RecordStatus* start_recording(
      const char* path, const Caliper::Simulation::RecordOptions& options) override;
  Caliper::Simulation::RecordStatus* stop_recording() override;
  Caliper::Simulation::RecordStatus* recording_status() override;
  Caliper::Simulation::ReplayStatus* open_replay(const char* path) override;
  Caliper::Simulation::ReplayStatus* open_replay_data(
      const char* file_name, const Caliper::Simulation::Octets& data) override;
  Caliper::Simulation::ReplayStatus* seek(CORBA::Double time) override;
  Caliper::Simulation::ReplayStatus* replay_status() override;
  void fork() override;

 private:
  /// subscribe and subscribe_lossless.
  CORBA::ULongLong Subscribe(const Caliper::Scene::StringSeq& ids, CORBA::ULong every_n_steps,
                             Caliper::Daq::DataConsumer_ptr consumer, bool lossless);

  simulation::ModelCore& core_;
  const simulation::ModelFiles files_;  // where paths from clients may lead (model.read_dirs, write_dir)
  std::atomic<uint64_t> next_observer_{1};
  PushPool pool_;  // last: its threads end before the rest goes
};

}  // namespace caliper::model
