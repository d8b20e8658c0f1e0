#pragma once
// The Main Window's connection to the Model: a worker thread (client::Worker) that finds `model0`
// in the naming service, polls its status and the watched parameter values, and runs the queued
// commands. The GUI only reads snapshots and queues commands, so a dead or slow Model never
// blocks it. No Qt here; CORBA stays in the .cc file.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/client/worker.h"

namespace caliper::main_window {

/// The Model's SimulationStatus, without CORBA.
struct ModelStatus {
  std::string state;                     ///< EMPTY, STOPPED, RUNNING, PAUSED, FAULTED
  std::string scene;                     ///< file of the loaded scene
  double sim_time = 0;                   ///< simulated time [s]
  std::uint64_t steps = 0;               ///< steps since the scene was loaded or reset
  double time_step = 0;                  ///< [s]
  double real_time_factor = 0;           ///< requested: 1 real time, 0 as fast as possible
  double achieved_real_time_factor = 0;  ///< measured over the last second
  std::string last_error;                ///< why the simulation last stopped, if it did
};

/// One of the Model's parameter or state channels.
struct Channel {
  std::string id;     ///< e.g. pendulum_tendon.pendulum.mass
  std::string unit;   ///< SI unit, "" for none
  unsigned rows = 1;  ///< shape of the value
  unsigned cols = 1;
  bool writable = false;
  bool is_static = false;  ///< a parameter (true) or a state changing every step (false)
  std::string description;
  bool scalar() const { return rows == 1 && cols == 1; }
};

/// A component bound in the naming service, with its lifecycle state.
struct ComponentInfo {
  std::string instance;  ///< e.g. model0
  std::string path;      ///< host.host_cxt/model0.rtc
  std::string state;     ///< CREATED, INACTIVE, ACTIVE, ERROR or UNREACHABLE
};

/// One element of a tendon's declared path (Scene::PathPoint without CORBA).
struct PathPointInfo {
  std::string body;  ///< the body it is fixed in ("" = the world)
  double x_m = 0;    ///< position in the body's frame [m]
  double y_m = 0;
  double z_m = 0;
  std::string obstacle;  ///< non-empty: a wrap around this obstacle (no position)
};

/// A collision shape of a body, in the order set_shape_dims indexes them.
struct ShapeInfo {
  std::string name;
  std::string kind;          ///< box, sphere, capsule, cylinder, cone, plane, convex_hull, ...
  std::vector<double> dims;  ///< as Scene::ShapeGeometry's dims of its kind [m]
};

struct BodyInfo {
  std::string name;
  bool moving = false;
  std::vector<ShapeInfo> shapes;
};

struct ObstacleInfo {
  std::string name;
  std::string body;
  std::string kind;                      ///< sphere or cylinder
  double position_m[3] = {0, 0, 0};      ///< in the body's frame [m]
  double orientation[4] = {1, 0, 0, 0};  ///< unit quaternion w x y z, kept by an edit
  double radius_m = 0;
  double length_m = 0;
};

struct TendonInfo {
  std::string name;
  double radius_m = 0;
  std::vector<PathPointInfo> path;
};

struct ActuatorInfo {
  std::string name;
  std::string kind;
  std::string tendon;  ///< the tendon it acts along
};

/// A registered actuator kind with its parameters' defaults (SI units).
struct ActuatorKindInfo {
  std::string kind;
  std::vector<std::string> parameters;
  std::vector<double> defaults;
  std::vector<std::string> units;
};

/// What the editing panels show of the loaded scene, read again after every edit.
struct SceneInfo {
  std::string name;      ///< the scene's name, as its file gives it ("ECCE Arm")
  std::string daq_name;  ///< the first part of its DAQ ids, the Model's id-safe name ("ecce_arm")
  std::vector<BodyInfo> bodies;
  std::vector<ObstacleInfo> obstacles;
  std::vector<TendonInfo> tendons;
  std::vector<ActuatorInfo> actuators;
  std::vector<std::string> constraints;
  /// the delayed channels' delays [s], by their DAQ ids (scene.channel)
  std::map<std::string, double> sensor_delays_s;
  const BodyInfo* FindBody(const std::string& n) const;
  const ObstacleInfo* FindObstacle(const std::string& n) const;
  const TendonInfo* FindTendon(const std::string& n) const;
};

/// The Model's edit history (SceneEditing::EditStatus).
struct EditInfo {
  std::uint64_t revision = 0;  ///< grows by one with every edit, undo and redo
  std::string last;            ///< what the last edit, undo or redo did
  std::string undo;            ///< what undo would revert ("" = nothing)
  std::string redo;            ///< what redo would apply again ("" = nothing)
};

/// What a GUI selected on the Model (SceneEditing::Selection).
struct SelectionInfo {
  std::string kind;  ///< body, tendon, path_point, obstacle, constraint or "" (none)
  std::string name;
  unsigned index = 0;          ///< the path element of a path_point
  std::uint64_t revision = 0;  ///< grows by one with every select()
};

/// The Model's recording (SessionRecording::RecordStatus without CORBA).
struct RecordInfo {
  bool recording = false;
  std::string path;  ///< on the Model's host
  std::uint64_t first_step = 0;
  std::uint64_t steps = 0;  ///< recorded so far
  std::uint64_t bytes = 0;  ///< the file's size at its last commit
  std::string error;        ///< why the last recording stopped early ("" when it did not)
};

/// The Model's replay (SessionRecording::ReplayStatus without CORBA).
struct ReplayInfo {
  bool replaying = false;
  std::string path;
  std::uint64_t first_step = 0;
  std::uint64_t last_step = 0;
  std::uint64_t step = 0;
  double start_time = 0;  ///< [s]
  double end_time = 0;    ///< [s]
  double time = 0;        ///< [s]
};

/// What the GUI reads: a copy of everything the worker last learnt.
struct Snapshot {
  bool connected = false;
  std::string connection_message;  ///< why no Model is reachable (when not connected)
  ModelStatus status;
  std::uint64_t channels_version = 0;  ///< changes whenever `channels` is listed anew
  std::vector<Channel> channels;
  std::map<std::string, double> values;   ///< latest values of the watched scalar ids
  std::string last_error;                 ///< the latest failed command's message
  std::uint64_t error_serial = 0;         ///< counts failed commands
  std::string last_notice;                ///< what a finished command has to say (warnings)
  std::uint64_t notice_serial = 0;        ///< counts notices
  std::uint64_t commands_done = 0;        ///< counts finished commands (failed or not)
  bool naming_reachable = false;          ///< the naming service answered the last listing
  std::uint64_t components_version = 0;   ///< counts the listings of `components`
  std::vector<ComponentInfo> components;  ///< everything bound in the naming service
  bool editing = false;                   ///< the Model answered edit_status()
  EditInfo edit;                          ///< the Model's edit history
  SelectionInfo selection;                ///< the Model's shared selection
  std::uint64_t scene_version = 0;        ///< changes whenever `scene` is read anew
  SceneInfo scene;                        ///< the loaded scene, as edited
  std::vector<ActuatorKindInfo> actuator_kinds;
  std::uint64_t commands_queued = 0;  ///< counts queued commands (see commands_done)
  bool recordings = false;            ///< the Model answered recording_status()
  RecordInfo record;                  ///< the Model's recording
  ReplayInfo replay;                  ///< the Model's replay
  std::string write_dir;              ///< file_access().write_dir ("" = none)
};

/// The worker and its command queue. Every method returns at once.
class ModelLink {
 public:
  struct Options {
    std::string nameservice;            ///< corbaname::HOST:PORT; "" for the default
    std::string instance = "model0";    ///< the Model's instance name
    int call_timeout_ms = 1500;         ///< every short call (status, list, get, set, start, ...)
    int long_call_timeout_ms = 120000;  ///< load_scene and step, which take as long as their work
    int poll_period_ms = 200;           ///< status and values
    int reconnect_period_ms = 1000;     ///< looking the Model up again while none is reachable
    int components_period_ms = 1000;    ///< listing the naming service's components
  };

  /// Uses the process's ORB (initialises one when there is none) and starts the worker.
  explicit ModelLink(Options options);
  ~ModelLink();
  ModelLink(const ModelLink&) = delete;
  ModelLink& operator=(const ModelLink&) = delete;

  Snapshot snapshot() const;

  void LoadScene(const std::string& path);
  void Start();
  void Pause();
  void Stop();
  void Reset();
  void Step(unsigned n);
  void SetTimeStep(double seconds);
  void SetRealTimeFactor(double factor);
  /// Writes a scalar parameter.
  void Set(const std::string& id, double value);
  /// The scalar ids whose values are polled (e.g. the visible rows).
  void Watch(std::vector<std::string> ids);
  /// Scene editing (SceneEditing on the Model); a refused edit's reason becomes last_error.
  void Undo();
  void Redo();
  void Select(const std::string& kind, const std::string& name, unsigned index = 0);
  void SetMass(const std::string& body, double mass_kg);
  /// Delays DAQ channel `id` by `delay_s` [s] for every reader (0 removes the delay).
  void SetMeasurementDelay(const std::string& id, double delay_s);
  void SetShapeDims(const std::string& body, unsigned index, std::vector<double> dims_m);
  void SetObstacle(const ObstacleInfo& obstacle);
  void RemoveObstacle(const std::string& obstacle);
  void MovePathPoint(const std::string& tendon, unsigned index, const PathPointInfo& point);
  void RemovePathPoint(const std::string& tendon, unsigned index);
  void RemoveTendon(const std::string& tendon);
  void AddTendon(const std::string& tendon, const PathPointInfo& from, const PathPointInfo& to,
                 double radius_m, const std::string& actuator, const std::string& kind);

  /// Session recordings (SessionRecording on the Model); each answer goes into the snapshot.
  /// Records to `path` (on the Model's host, into its write_dir), a keyframe every
  /// `keyframe_every` steps, no channels.
  void StartRecording(const std::string& path, unsigned keyframe_every = 100);
  void StopRecording();
  void OpenReplay(const std::string& path);
  /// Goes to the moment nearest `time_s` of the replay.
  void Seek(double time_s);
  void Fork();

  /// A lifecycle transition of a component in the naming service: `verb` is activate,
  /// deactivate, reset or exit. Needs no Model.
  void ComponentAction(const std::string& instance, const std::string& verb);

  const Options& options() const { return options_; }

  struct Impl;

 private:
  struct Command {
    std::string what;
    std::function<void(Impl&)> call;
    bool needs_model = true;
  };
  void Queue(std::string what, std::function<void(Impl&)> call, bool needs_model = true);
  /// An edit: `call` returns the Model's EditStatus, which the snapshot takes at once.
  void QueueEdit(std::string what, std::function<EditInfo(Impl&)> call);
  // on the worker thread only, from here on
  void RunCommand(const Command& command);
  /// Reads the scene, its actuators and the bodies' shapes.
  void ReadScene();
  void ListComponents();
  /// Lists the components when a component action ran or the components period passed.
  void ListComponentsIfDue();
  /// A tick: looks the Model up while there is none, then polls it.
  void Poll();
  bool LookUp();
  void PollModel(const std::vector<std::string>& watched);
  /// Lists the channels when the scene changed (or they were never listed); true when it did.
  bool ListChannels(const std::string& scene, std::vector<Channel>* channels);
  std::map<std::string, double> ReadValues(const std::vector<std::string>& watched);
  /// The edit history and the selection (false: a Model without scene editing); reads the
  /// scene again after an edit or with a new scene.
  bool ReadEditing(const ModelStatus& status, EditInfo* edit, SelectionInfo* selection);
  /// Forgets the Model after a system exception: it is looked up again.
  void Lost(const std::string& why);

  std::unique_ptr<Impl> impl_;
  Options options_;
  mutable std::mutex mutex_;  // guards the fields below
  std::vector<std::string> watched_;
  Snapshot snapshot_;
  std::unique_ptr<client::Worker> worker_;  // its hooks and jobs use everything above
};

}  // namespace caliper::main_window
