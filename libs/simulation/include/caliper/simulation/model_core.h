#pragma once
// The Model's data and simulation loop, without CORBA: the loaded scene, its physics, commands
// and parameter writes queued for the next step boundary, run control with a real-time factor,
// and snapshots for observers. Every public method is thread-safe; a step never overlaps a call.
// The concerns below live in parts it owns, each tested on its own and called with its lock held:
// Feeds (data subscriptions and the lossless wait), EditHistory (undo/redo, removed actuators,
// the selection), SessionRecorder (a recording being written), Replayer (one being replayed) and
// ExperimentRunner with ImportCache (an experiment run's checks, schedule and samples).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "caliper/core/ids.h"
#include "caliper/core/scratch_directory.h"
#include "caliper/daq/daq_scene.h"
#include "caliper/daq/recorder.h"
#include "caliper/daq/registry.h"
#include "caliper/experiment/experiment.h"
#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/recording/recording.h"
#include "caliper/sgal/edits.h"
#include "caliper/sgal/physics_scene.h"
#include "caliper/simulation/core_types.h"
#include "caliper/simulation/edit_history.h"
#include "caliper/simulation/experiment_runner.h"
#include "caliper/simulation/feeds.h"
#include "caliper/simulation/replayer.h"
#include "caliper/simulation/session_recorder.h"

namespace caliper::simulation {

enum class RunState { kEmpty, kStopped, kRunning, kPaused, kFaulted };
const char* ToString(RunState state);

/// Wall time a step request or an experiment holds the lock before letting other calls in.
constexpr std::chrono::milliseconds kSlice{10};

/// Builds the engine of a scene (tests substitute one that fails on demand).
using PhysicsFactory =
    std::function<std::unique_ptr<sgal::PhysicsScene>(const sgal::Scene& scene)>;

/// A run that could not finish: its physics faulted (NaN, explosion); the message is the report.
class RunFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A scene sent by content that cannot be loaded; the message names the file and the problem.
class LoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The largest recording a run may make [bytes]: it returns in one GIOP message (256 MiB).
constexpr size_t kMaxRecordingBytes = size_t{240} << 20;

/// What run_experiment returns: the recording and where the time went.
struct RunResult {
  experiment::Recording recording;
  uint64_t steps = 0;
  double load_wall_s = 0;  // importing and building the scene [s]
  double step_wall_s = 0;  // stepping and sampling [s]
};

struct Status {
  RunState state = RunState::kEmpty;
  std::string scene;
  double sim_time = 0;          // [s]
  uint64_t steps = 0;
  double time_step = 0;         // [s]
  double real_time_factor = 1;  // requested; 0 = as fast as possible
  double achieved_real_time_factor = 0;
  std::string last_error;
};

/// All body states and tendon states after one step, shared with observers' senders.
struct Snapshot {
  uint64_t generation = 0;  // which loaded scene
  uint64_t step = 0;
  double time = 0;          // [s]
  std::vector<sgal::BodyState> bodies;
  std::vector<sgal::TendonState> tendons;
};

/// Told about scenes and steps; implemented by the servant's observer senders. Called with the
/// core's lock held: must only post and return.
class CoreListener {
 public:
  virtual ~CoreListener() = default;
  virtual void OnScene(std::shared_ptr<const sgal::Scene> scene, uint64_t generation) = 0;
  virtual void OnSnapshot(std::shared_ptr<const Snapshot> snapshot) = 0;
  virtual void OnCleared() = 0;
};

class ModelCore {
 public:
  explicit ModelCore(physics_bullet::Options options = {}, Limits limits = {},
                     PhysicsFactory factory = nullptr);
  ~ModelCore();

  /// Imports and builds a scene (COLLADA or URDF, model_file::Import) outside the lock, then
  /// swaps it in. On failure throws std::runtime_error with the importer's or the engine's
  /// message and keeps the old scene.
  void Load(const std::string& path);
  /// The same for a description built in memory (tests, generators).
  void LoadScene(const sgal::Scene& scene, const std::string& source);
  /// Loads a scene sent by content: `file_name` (its ending: .dae or .zae) names it in messages.
  /// A .urdf is refused (its meshes would not come with it), saying how to send it instead.
  void LoadData(const std::string& file_name, const std::string& bytes);
  /// The scene with its current parameters as the bytes of a .dae file.
  std::string ExportBytes();
  /// Loads `scene_bytes` afresh (any earlier state or command is forgotten, so that the same
  /// experiment gives the same bits on any host), applies the overrides, steps as fast as
  /// possible with the schedule, sampling `record` at t = 0 and every N steps. Other control
  /// calls get NotAvailable meanwhile, except stop and pause, which end the run early (it then
  /// throws NotAvailable saying so); status() shows it RUNNING. Throws LoadError,
  /// UnknownId, InvalidValue, or RunFailed when the physics faults. Ends PAUSED at the last step.
  RunResult RunExperiment(const experiment::Experiment& experiment, const std::string& file_name,
                          const std::string& scene_bytes);

  void Start();
  void Pause();
  void Stop();   // pause and rewind (every actuator command back to 0)
  void Reset();  // rewind (every actuator command back to 0), keep the run state
  /// Runs n steps now and returns how many ran: n, or fewer when a stop or pause ended it early
  /// or the physics faulted. It lets other calls in between slices of kSlice: reads are answered,
  /// commands and parameter writes queue for the next step, stop and pause end it; another step,
  /// start, load, reset or a time-step change meanwhile gets NotAvailable saying what runs.
  /// NotAvailable while running or faulted.
  uint64_t StepNow(uint64_t n);
  /// One lock-step control cycle under one lock: checks the ids (LimitExceeded, UnknownId) and
  /// the commands (SetCommands' errors) and StepNow's preconditions before anything changes,
  /// applies the commands (none: allowed in a replay too), runs StepNow's request of `n` steps
  /// and reads the `count` ids at `ids` after them, before another client can step or write,
  /// into `shapes` and `values` as SampleInto does. Returns the steps taken.
  uint64_t ControlCycle(const std::vector<std::pair<std::string, double>>& commands, uint64_t n,
                        const char* const* ids, size_t count, std::vector<daq::Shape>* shapes,
                        std::vector<double>* values);
  void SetTimeStep(double seconds);
  void SetRealTimeFactor(double factor);
  Status status() const;
  /// The Model is shutting down: a running experiment ends at its next slice, later ones are
  /// refused, both with NotAvailable.
  void CancelExperiment();

  /// Advances a RUNNING simulation by what is due at the real-time factor, or by at most
  /// `budget` of wall time when running as fast as possible. Called by the execution context.
  void Advance(std::chrono::steady_clock::duration budget);
  /// One step if RUNNING (lock-step with an external execution context).
  void Tick();

  // scene editing (idl/caliper/editing.idl has the meaning)
  struct EditStatus {
    uint64_t revision = 0;
    std::string last, undo, redo;
  };
  /// Makes an edit against the scene as loaded (plus earlier edits) and applies it to that scene
  /// and to the running engine's copy (its tuned parameters stay), checking both with
  /// sgal::Validate and the engine's build; the dynamic state carries over. Throws
  /// sgal::EditError (refused, nothing changed) or NotAvailable (no scene, an experiment runs).
  EditStatus Edit(const std::function<sgal::SceneEdit(const sgal::Scene&)>& make);
  EditStatus Undo();
  EditStatus Redo();
  EditStatus edit_status() const;
  /// A spring on a moving body's point (body frame) towards a world target from the next step;
  /// stiffness 0 takes the body's mass times (2 pi 2 Hz)^2. Damping is critical for the mass.
  /// A lease: a pull not renewed (called again) within Limits::pull_lease of wall time ends by itself.
  /// Throws sgal::EditError for a body that does not move, a stiffness above mass / dt^2 (the
  /// spring would be unstable), or a point or target beyond the engine's max_distance.
  void Pull(const std::string& body, const Eigen::Vector3d& point, const Eigen::Vector3d& target,
            double stiffness_n_per_m);
  void ReleasePull();
  struct Selection {
    std::string kind, name;
    uint32_t index = 0;
    uint64_t revision = 0;
  };
  /// What a GUI picked (kind body, tendon, path_point, obstacle, constraint, or "" for nothing);
  /// throws sgal::EditError for an unknown kind or a name the scene lacks.
  void Select(const std::string& kind, const std::string& name, uint32_t index);
  Selection selection() const;

  // session recordings (libs/recording; idl/caliper/recording.idl has the meaning)
  struct RecordOptions {
    uint32_t keyframe_every = 100;       // steps between keyframes
    uint32_t channels_every = 1;         // steps between samples of `channels`
    std::vector<std::string> channels;   // ids sampled (none: keyframes and events only)
    uint64_t max_bytes = 0;              // stop (as on a full disk) beyond this size; 0: none
  };
  struct RecordStatus {
    bool recording = false;
    std::string path;
    uint64_t first_step = 0, steps = 0, bytes = 0;
    std::string error;  // why the last recording stopped early ("" when it did not)
  };
  /// Records from the present step into a new file at `path` (the caller checks where it may
  /// write): the scene as it runs, a keyframe now and every keyframe_every steps, every command,
  /// parameter write, pull and edit with its step, the channels and the Model's log. A load,
  /// stop or reset ends it. Throws NotAvailable (no scene, already recording, replaying),
  /// UnknownId (a channel), InvalidValue (options), recording::RecordingError (the file).
  RecordStatus StartRecording(const std::string& path, const RecordOptions& options);
  RecordStatus StopRecording();
  RecordStatus recording_status() const;
  struct ReplayStatus {
    bool replaying = false;
    std::string path;
    uint64_t first_step = 0, last_step = 0, step = 0;
    double start_time = 0, end_time = 0, time = 0;  // [s]
  };
  /// Loads a recording to play it: its scene at its first keyframe, paused. Start, pause, step
  /// and the real-time factor play it (re-simulating with its events, which reproduces it bit for
  /// bit); it pauses at its end. Commands, parameter writes and edits are refused until Fork().
  /// Throws LoadError or recording::RecordingError naming the file and why.
  ReplayStatus OpenReplay(const std::string& path);
  /// OpenReplay of a recording sent by content: a private copy named after `file_name` (its last
  /// component) is kept while it is the replay. Throws as OpenReplay, and
  /// recording::RecordingError when the copy cannot be written.
  ReplayStatus OpenReplayData(const std::string& file_name, const std::string& bytes);
  /// Goes to the step nearest `time_s` (clamped to the recording): its keyframe, then at most
  /// keyframe_every - 1 steps.
  ReplayStatus Seek(double time_s);
  ReplayStatus replay_status() const;
  /// Leaves the replay where it stands: the Model simulates on from there as any other.
  void Fork();
  /// The engine's dynamic state now (exact numbers included).
  sgal::DynamicState dynamic_state() const;
  /// Called by a replay where each periodic keyframe was taken (after its step's earlier events,
  /// before the cache reset), with the engine as it stands there (verification).
  using KeyframeHook = std::function<void(uint64_t step, const sgal::PhysicsScene& physics)>;
  void SetReplayKeyframeHook(KeyframeHook hook);
  /// A record of the session's log (any component's) for the recording, if one runs.
  void AddSessionLog(const recording::LogRecord& record);
  /// `on`: the session log comes through AddSessionLog (the Logging component); otherwise
  /// recordings take the Model's own records.
  void UseSessionLog(bool on);

  // scene and actuators
  std::shared_ptr<const sgal::Scene> description() const;  // nullptr when empty
  void Save(const std::string& path);
  struct ActuatorInfo {
    std::string name, kind, tendon, command_unit;
  };
  std::vector<ActuatorInfo> Actuators() const;
  /// Queued for the next step boundary; UnknownId / InvalidValue checked now.
  void SetCommands(const std::vector<std::pair<std::string, double>>& commands);
  struct ActuatorState {
    std::string name;
    double command = 0, tension = 0;
  };
  std::vector<ActuatorState> ActuatorStates() const;

  // channels (parameters and states) through the DAQ registry
  std::vector<daq::ChannelInfo> Channels(const std::string& pattern) const;
  std::vector<daq::Reading> Sample(const std::vector<std::string>& ids) const;
  /// Sample() into flat buffers, without a copy of each id (daq::Registry::SampleInto): what a
  /// controller's `get` reads every cycle. The same checks and exceptions.
  void SampleInto(const char* const* ids, size_t count, std::vector<daq::Shape>* shapes,
                  std::vector<double>* values) const;
  /// Applied at once, between two steps even while running (the lock makes it a step boundary),
  /// after the commands still queued; a bad shape, a non-finite value and the engine's own
  /// refusal (a negative mass, a bound) are raised to the caller.
  void SetChannel(const std::string& id, const std::vector<double>& values);
  /// Subscriptions outlive scene reloads: ids that vanish are reported stale.
  ///
  /// `lossless_wait` > 0 makes a lossless subscription: before each step of a lock-step or
  /// as-fast-as-possible run (StepNow, Tick, Advance at a factor of 0, RunExperiment) the stepping
  /// waits, with the lock released, until its queue has room for one more step's batches; a
  /// consumer that takes none for `lossless_wait` is ended (Unsubscribe with the reason). Advance
  /// at a real-time factor > 0 never waits: a full queue drops its oldest batch, counted.
  uint64_t Subscribe(const std::vector<std::string>& ids, uint32_t every_n_steps,
                     size_t batch_steps,
                     std::chrono::milliseconds lossless_wait = std::chrono::milliseconds(0));
  /// Ends a subscription (nothing when there is none); a non-empty `reason` says why the Model,
  /// not its client, ended it: logged, and given by SubscriptionStatus afterwards.
  void Unsubscribe(uint64_t subscription, const std::string& reason = "");
  /// Throws UnknownId, saying why the Model ended it when it did.
  FeedStatus SubscriptionStatus(uint64_t subscription) const;
  /// Batches taken by a sender but not delivered (a failed push): counted as dropped.
  void NoteUndelivered(uint64_t subscription, uint64_t batches, uint64_t samples);
  /// Called, with the core's lock held, when the stepping begins to wait for the consumer of a
  /// lossless subscription (its sender should push now): must only post and return.
  void SetConsumerWake(std::function<void(uint64_t subscription)> wake);
  /// For the subscribers' sender threads (it never waits for the model's lock). `gone` tells
  /// whether the subscription no longer exists (the Model ended it, or its client did).
  /// `dropped_samples` gets how many samples its full queue dropped so far. When nothing is
  /// queued and the Model rests (not running, no step request: paused, stopped, between the
  /// requests of a lock-step client), the partial batch goes out: a sender polling every P ms
  /// delivers every sample within P ms of the last step, in whole batches while steps go on.
  std::vector<daq::Batch> TakeBatches(uint64_t subscription, bool* gone = nullptr,
                                      uint64_t* dropped_samples = nullptr);
  bool WaitForBatches(uint64_t subscription, std::chrono::milliseconds timeout);

  void AddListener(CoreListener* listener);
  void RemoveListener(CoreListener* listener);

  /// Model name used as the prefix of channel ids (the scene's name, made id-safe).
  std::string model_name() const;

 private:
  struct Loaded {
    std::shared_ptr<const sgal::Scene> description;  // as loaded (rewind rebuilds from it)
    std::string source;
    std::string name;                                 // id prefix
    std::unique_ptr<sgal::PhysicsScene> physics;
    std::shared_ptr<daq::SceneSampler> sampler;
    std::map<std::string, double> commands;           // last command per actuator
    std::unordered_set<std::string> actuators;        // the description's actuators' names
  };
  /// `edit`: the same scene edited (history, commands and step requests go on).
  void BuildLocked(std::unique_ptr<Loaded> loaded, bool edit = false);
  /// Changes copies of the scene as loaded and of the engine's (returning what it did), builds
  /// and checks them outside the lock, and swaps them in; see Edit.
  using Rebuild = std::function<std::string(sgal::Scene& base, sgal::Scene& current)>;
  EditStatus ApplyEdit(const Rebuild& rebuild);
  void SwapEditedLocked(std::shared_ptr<const sgal::Scene> base,
                        std::unique_ptr<sgal::PhysicsScene> physics, const std::string& what);
  EditStatus Walk(bool undo);
  EditStatus EditStatusLocked() const;
  /// Ends a pull its client stopped renewing.
  void ExpirePullLocked();
  // recording and replay (model_recording.cc)
  void RecordEventLocked(const std::string& kind, const std::string& target,
                         std::vector<double> values);
  /// Before a step: replayed events due, keyframes (recording) or cache resets (replay).
  void BeforeStepLocked();
  /// After a step: the channels' sample, the end of a replay.
  void AfterStepLocked();
  void EndRecordingLocked(const std::string& why);
  void RequireNotReplaying(const char* what) const;
  /// Rebuilds the replay's engine at keyframe `step` (its scene version, the parameter writes
  /// before it, the pull then).
  void RestoreReplayLocked(uint64_t step);
  ReplayStatus ReplayStatusLocked() const;
  /// No replay any more (a load, an experiment, a fork): its copy sent by content goes too.
  void EndReplayLocked();
  std::unique_ptr<SessionRecorder> recorder_session_;
  std::unique_ptr<core::ScratchDirectory> replay_copy_;  // a replay sent by content (outlives replay_)
  std::unique_ptr<Replayer> replay_;  // the recording replayed (none: not replaying)
  std::string last_recording_error_;
  uint64_t last_recording_bytes_ = 0;
  bool session_log_ = false;  // records come through AddSessionLog
  uint32_t fork_reset_every_ = 0;  // a fork resets caches as its recording did (0: not a fork)
  /// Applies the queued commands, in the order they came.
  void ApplyPendingLocked();
  void StepLocked();
  // StepNow's preconditions, and its request once they hold; the lock is held on return
  void RequireCanStepLocked() const;
  uint64_t StepRequestLocked(std::unique_lock<std::mutex>& lock, uint64_t n);
  void SetCommandsLocked(const std::vector<std::pair<std::string, double>>& commands);
  // `read` of `count` ids from the registry, as every read of ids is checked (at most
  // ids_per_call of them, a scene) and its unknown id reported
  template <class Read>
  auto ReadLocked(size_t count, Read&& read) const -> decltype(read());
  void SampleIntoLocked(const char* const* ids, size_t count, std::vector<daq::Shape>* shapes,
                        std::vector<double>* values) const;
  void PublishLocked();
  void RewindLocked();
  /// The achieved real-time factor over the wall time since the last measurement, once at least
  /// `min_span_s` has passed.
  void MeasureRateLocked(double min_span_s);
  void Require(bool scene_needed) const;
  /// NotAvailable while an experiment runs (the run owns the simulation).
  void RequireIdle() const;
  /// NotAvailable while an experiment runs; a step request does not count (writes queue).
  void RequireNoExperiment() const;
  /// Lets waiting calls take the lock, then takes it back (between slices of long work).
  void HandOverLocked(std::unique_lock<std::mutex>& lock);
  /// Before a step of a lock-step or as-fast-as-possible run: Feeds::AwaitRoom, which gives up
  /// on a stop, pause, load or shutdown meanwhile. True when the lock was let go meanwhile (the
  /// caller checks what changed).
  bool AwaitConsumersLocked(std::unique_lock<std::mutex>& lock);
  /// The simulation stops at the start of the failing step: FAULTED with `reason`, one error
  /// record, queued commands dropped (they were for steps that will not come).
  void FaultLocked(const std::string& reason);
  std::unique_ptr<sgal::PhysicsScene> MakePhysics(const sgal::Scene& scene) const;
  /// NotAvailable when `adding` more commands would queue more than limits_.pending_writes.
  void RequireQueueRoomLocked(size_t adding) const;
  /// Asks a running experiment to end at its next slice (stop, pause); false when none runs.
  bool EndExperimentLocked(const std::string& request);
  /// Takes the lock; every call does it this way, so that a running experiment, which lets go
  /// between slices, hands it over (a plain mutex does not: re-locking at once starves callers).
  std::unique_lock<std::mutex> Lock() const;
  sgal::Scene ImportBytes(const std::string& file_name, const std::string& bytes) const;

  physics_bullet::Options options_;
  Limits limits_;
  PhysicsFactory factory_;
  mutable std::mutex mutex_;
  daq::Registry registry_;
  Feeds feeds_{registry_, limits_};  // after registry_, which its subscriptions read
  std::unique_ptr<Loaded> loaded_;
  uint64_t generation_ = 0;  // of the scene observers see: every load, rewind and edit
  uint64_t restarts_ = 0;    // loads and rewinds (a step request ends on one, not on an edit)
  EditHistory history_;  // undo/redo, removed actuators, the last edit, the selection
  std::chrono::steady_clock::time_point pull_until_;
  std::optional<sgal::Pull> pull_;  // carried over edits; ended by a rewind or load
  RunState state_ = RunState::kEmpty;
  std::string experiment_;  // the experiment running now ("" when none)
  std::atomic<bool> cancel_{false};     // ends the running experiment (shutting down)
  std::string end_request_;             // why the running experiment or step is to end ("" runs on)
  uint64_t step_request_ = 0;           // steps asked of the step request running now (0: none)
  uint64_t step_done_ = 0;              // of those, done so far
  mutable std::atomic<int> waiting_{0};  // calls waiting for the lock (see Lock)
  // the last scene imported from bytes: batches send the same file run after run (only
  // RunExperiment's thread uses it)
  ImportCache imported_;
  double real_time_factor_ = 1.0;
  std::string last_error_;
  std::vector<std::pair<std::string, double>> pending_commands_;
  std::vector<CoreListener*> listeners_;
  // real-time pacing: wall clock and sim time when the current run began
  std::chrono::steady_clock::time_point run_wall_start_;
  double run_sim_start_ = 0;
  // achieved real-time factor over the last second
  std::chrono::steady_clock::time_point rate_wall_;
  double rate_sim_ = 0;
  double achieved_rtf_ = 0;
};

/// A scene as the bytes of a COLLADA file with Caliper's technique (exports, recordings).
std::string ColladaBytesOf(const sgal::Scene& scene);

/// What re-simulating a recording from its start with its events gave.
struct Verification {
  uint64_t steps = 0;          // re-simulated
  uint64_t keyframes = 0;      // compared bit for bit
  uint64_t samples = 0;        // channel samples compared bit for bit
  bool identical = true;
  uint64_t divergent_step = 0;  // the first step that differs (when not identical)
  std::string detail;           // what differs there, and by how much
};
/// Replays `path` in a Model of its own and compares every keyframe and channel sample with the
/// recorded bits; stops at the first divergence. `progress` is told the step now and the last.
/// Throws recording::RecordingError (or the scene's import error) for a file it cannot replay.
Verification VerifyRecording(const std::string& path,
                             const std::function<void(uint64_t, uint64_t)>& progress = nullptr);

/// `arm_v2` from `Arm V2!`: the first part of the scene's DAQ ids (caliper/core/ids.h).
using core::IdSafe;

}  // namespace caliper::simulation
