#include "caliper/simulation/model_core.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"
#include "caliper/core/scratch_directory.h"
#include "caliper/logging/log.h"
#include "caliper/model_file/model_file.h"

namespace caliper::simulation {

using Clock = std::chrono::steady_clock;

const char* ToString(RunState state) {
  switch (state) {
    case RunState::kEmpty: return "EMPTY";
    case RunState::kStopped: return "STOPPED";
    case RunState::kRunning: return "RUNNING";
    case RunState::kPaused: return "PAUSED";
    case RunState::kFaulted: return "FAULTED";
  }
  return "?";
}

// Everything that belongs to one loaded scene.

ModelCore::ModelCore(physics_bullet::Options options, Limits limits, PhysicsFactory factory)
    : options_(options), limits_(limits), factory_(std::move(factory)) {}

std::unique_ptr<sgal::PhysicsScene> ModelCore::MakePhysics(const sgal::Scene& scene) const {
  return factory_ ? factory_(scene) : physics_bullet::MakeScene(scene, options_);
}

ModelCore::~ModelCore() {
  // the channels refer to the scene: remove them first
  const auto lock = Lock();
  EndRecordingLocked("the Model is shutting down");
  registry_.Clear();
}

void ModelCore::Require(bool scene_needed) const {
  if (scene_needed && !loaded_) throw NotAvailable("no scene is loaded (load one first)");
}

std::unique_lock<std::mutex> ModelCore::Lock() const {
  ++waiting_;
  std::unique_lock<std::mutex> lock(mutex_);
  --waiting_;
  return lock;
}

void ModelCore::CancelExperiment() {
  cancel_ = true;
  feeds_.NotifyRoom();  // a step waiting for a lossless consumer looks again
}

bool ModelCore::EndExperimentLocked(const std::string& request) {
  if (experiment_.empty() && step_request_ == 0) return false;
  end_request_ = "a " + request + " request ended it early";
  return !experiment_.empty();
}

void ModelCore::RequireNoExperiment() const {
  if (!experiment_.empty())
    throw NotAvailable("experiment '" + experiment_ + "' is running; wait for it to end");
}

void ModelCore::RequireIdle() const {
  RequireNoExperiment();
  if (step_request_ != 0)
    throw NotAvailable("a step request of " + std::to_string(step_request_) + " steps is running (" +
                       std::to_string(step_done_) + " done); wait for it, or stop or pause it");
}

void ModelCore::HandOverLocked(std::unique_lock<std::mutex>& lock) {
  lock.unlock();
  // a plain mutex re-taken at once starves the callers waiting for it: let each in once
  for (int spin = 0; waiting_ > 0 && spin < 1000; ++spin) std::this_thread::yield();
  lock.lock();
}

void ModelCore::RequireQueueRoomLocked(size_t adding) const {
  const size_t queued = pending_commands_.size();
  if (queued + adding > limits_.pending_writes)
    throw NotAvailable(std::to_string(queued) + " commands are waiting for " +
                       "the next step; at most " + std::to_string(limits_.pending_writes) +
                       " may wait (is the simulation stepping?)");
}

void ModelCore::FaultLocked(const std::string& reason) {
  state_ = RunState::kFaulted;
  last_error_ = reason;
  pending_commands_.clear();
  logging::Get("model").error("simulation stopped at t = %.6f s (step %llu): %s",
                              loaded_ ? loaded_->physics->time() : 0.0,
                              static_cast<unsigned long long>(loaded_ ? loaded_->physics->steps() : 0),
                              reason.c_str());
}

void ModelCore::Load(const std::string& path) {
  {
    const auto lock = Lock();
    RequireIdle();
  }
  std::vector<std::string> warnings;
  // COLLADA or URDF by the ending; throws collada::ImportError
  sgal::Scene scene = model_file::Import(path, &warnings);
  for (const auto& w : warnings) logging::Get("model").warn("%s: %s", path.c_str(), w.c_str());
  LoadScene(scene, path);
}


sgal::Scene ModelCore::ImportBytes(const std::string& file_name, const std::string& bytes) const {
  // the importer reads files (Collada-DOM opens .zae archives itself): a private copy, gone after
  const std::string base = std::filesystem::path(file_name).filename().string();
  const std::string ending = base.size() > 4 ? base.substr(base.size() - 4) : "";
  // a URDF's meshes are other files, which do not travel with it
  if (model_file::FormatOf(base) == model_file::Format::kUrdf) {
    const std::string stem = std::filesystem::path(base).stem().string();
    throw LoadError(file_name + ": a URDF cannot be sent by content (its meshes are other " +
                    "files): send it by path, or convert it with `caliper-ctl inspect " + base +
                    " --export " + stem + ".dae` and send that");
  }
  if (ending != ".dae" && ending != ".zae")
    throw LoadError(file_name + ": a scene sent by content must be named *.dae or *.zae");
  if (bytes.empty()) throw LoadError(file_name + ": the scene sent is empty");
  core::ScratchDirectory scratch("caliper-scene");
  // a plain name for the copy: the importer refuses names it would read as URIs ('#', '%')
  const std::string path = scratch.path() + "/scene" + ending;
  {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) throw LoadError("cannot write the scene to " + path);
  }
  // messages name the file as sent, not the private copy
  auto named = [&](std::string message) {
    for (size_t at = message.find(path); at != std::string::npos; at = message.find(path, at))
      message.replace(at, path.size(), base);
    return message;
  };
  std::vector<std::string> warnings;
  sgal::Scene scene;
  try {
    scene = collada::Import(path, &warnings);
  } catch (const collada::ImportError& e) {
    throw LoadError(named(e.what()));
  }
  for (const auto& w : warnings) logging::Get("model").warn("%s", named(w).c_str());
  return scene;
}

void ModelCore::LoadData(const std::string& file_name, const std::string& bytes) {
  {
    const auto lock = Lock();
    RequireIdle();
  }
  LoadScene(ImportBytes(file_name, bytes), file_name + " (sent by content)");
}

std::string ModelCore::ExportBytes() {
  sgal::Scene current;
  {
    const auto lock = Lock();
    Require(true);
    current = loaded_->physics->description();  // with the parameters tuned while running
  }
  return ColladaBytesOf(current);
}

RunResult ModelCore::RunExperiment(const experiment::Experiment& e, const std::string& file_name,
                                   const std::string& scene_bytes) {
  experiment::Validate(e);
  {
    const auto lock = Lock();
    RequireIdle();
    if (cancel_) throw NotAvailable("the Model is shutting down");
    experiment_ = e.name;
    end_request_.clear();
  }
  struct EndRun {
    ModelCore* core;
    ~EndRun() {
      std::lock_guard<std::mutex> lock(core->mutex_);
      core->experiment_.clear();
    }
  } end_run{this};

  RunResult result;
  const auto load_begin = Clock::now();
  const std::shared_ptr<const sgal::Scene> scene = imported_.Get(
      file_name, scene_bytes, [this](const std::string& name, const std::string& bytes) {
        return ImportBytes(name, bytes);
      });
  // build outside the lock; a fresh world and no command carried over from the last scene
  auto loaded = std::make_unique<Loaded>();
  loaded->description = scene;
  loaded->source = file_name + " (experiment " + e.name + ")";
  loaded->name = IdSafe(scene->name.empty() ? "model" : scene->name);
  loaded->physics = MakePhysics(*scene);
  std::unique_lock<std::mutex> lock(mutex_);
  if (loaded_) loaded_->commands.clear();
  EndRecordingLocked("an experiment was run");
  EndReplayLocked();
  fork_reset_every_ = 0;
  BuildLocked(std::move(loaded));
  history_.Forget();
  state_ = RunState::kPaused;
  last_error_.clear();
  result.load_wall_s = std::chrono::duration<double>(Clock::now() - load_begin).count();

  // overrides, the recorded ids and the schedule's actuators are checked before any step
  ApplyOverrides(e, registry_);
  loaded_->sampler->Refresh();
  sgal::PhysicsScene& physics = *loaded_->physics;
  ExperimentRunner run(e, registry_, loaded_->description->actuators,
                       physics.description().settings.time_step, limits_.experiment_steps,
                       kMaxRecordingBytes);
  const uint64_t steps = run.steps();
  const auto step_begin = Clock::now();
  rate_wall_ = step_begin;
  rate_sim_ = physics.time();
  run.Sample(physics.time());
  auto slice_end = Clock::now() + kSlice;
  for (uint64_t k = 1; k <= steps; ++k) {
    AwaitConsumersLocked(lock);  // the experiment flag keeps control calls out meanwhile
    run.TakeDueCommands(physics.time(), &pending_commands_);
    StepLocked();
    if (state_ == RunState::kFaulted)
      throw RunFailed("experiment '" + e.name + "' faulted at t = " + std::to_string(physics.time()) +
                      " s (step " + std::to_string(k) + "): " + last_error_);
    if (run.SampleDue(k)) run.Sample(physics.time());
    if (k % 16 == 0 && Clock::now() > slice_end) {
      // let status() and readers in between; the experiment flag keeps control calls out
      MeasureRateLocked(0.5);
      HandOverLocked(lock);
      slice_end = Clock::now() + kSlice;
      if (cancel_ || !end_request_.empty())
        throw NotAvailable("experiment '" + e.name + "' ended at t = " +
                           std::to_string(physics.time()) + " s: " +
                           (cancel_ ? "the Model is shutting down" : end_request_));
    }
  }
  result.recording = std::move(run.recording());
  result.step_wall_s = std::chrono::duration<double>(Clock::now() - step_begin).count();
  result.steps = steps;
  logging::Get("model").info("experiment %s: %llu steps in %.3f s of wall time", e.name.c_str(),
                             static_cast<unsigned long long>(steps), result.step_wall_s);
  return result;
}

void ModelCore::LoadScene(const sgal::Scene& scene, const std::string& source) {
  // build everything outside the lock: a bad scene throws here and changes nothing
  auto loaded = std::make_unique<Loaded>();
  loaded->description = std::make_shared<const sgal::Scene>(scene);
  loaded->source = source;
  loaded->name = IdSafe(scene.name.empty() ? "model" : scene.name);
  loaded->physics = MakePhysics(scene);
  const auto lock = Lock();
  RequireIdle();  // again: an experiment may have begun while this scene was built
  EndRecordingLocked("another scene was loaded");
  EndReplayLocked();
  fork_reset_every_ = 0;
  BuildLocked(std::move(loaded));
  state_ = RunState::kStopped;
  last_error_.clear();
  history_.Forget();
  history_.ClearSelection();
  logging::Get("model").notice("loaded %s: %zu bodies, %zu tendons, %zu actuators", source.c_str(),
                               scene.bodies.size(), scene.tendons.size(), scene.actuators.size());
}

void ModelCore::BuildLocked(std::unique_ptr<Loaded> loaded, bool edit) {
  const bool had_scene = loaded_ != nullptr;
  if (!edit) {
    ++restarts_;
    pull_.reset();
  }
  // the old scene's channels go first (they refer to its physics); subscriptions stay and
  // re-resolve their ids at the next step
  registry_.Clear();
  const daq::SceneChannels channels = daq::RegisterScene(registry_, loaded->name, *loaded->physics);
  loaded->sampler = channels.sampler;
  loaded->actuators.clear();
  for (const auto& a : loaded->description->actuators) loaded->actuators.insert(a.name);
  for (const auto& id : channels.skipped)
    logging::Get("model").warn("channel %s not registered: the id is taken", id.c_str());
  // every command starts at zero in the new physics, as after MuJoCo's reset: a stop, reset or
  // load that left a motor driving would move the arm the user just rewound
  loaded_ = std::move(loaded);
  ++generation_;
  if (!edit) pending_commands_.clear();
  if (had_scene)
    for (auto* l : listeners_) l->OnCleared();
  for (auto* l : listeners_) l->OnScene(loaded_->description, generation_);
  loaded_->sampler->Refresh();
  PublishLocked();
}

void ModelCore::RewindLocked() {
  fork_reset_every_ = 0;  // a rewound fork is a plain simulation again
  auto fresh = std::make_unique<Loaded>();
  fresh->description = loaded_->description;
  fresh->source = loaded_->source;
  fresh->name = loaded_->name;
  fresh->physics = MakePhysics(*fresh->description);
  BuildLocked(std::move(fresh));
  last_error_.clear();
}

void ModelCore::Start() {
  const auto lock = Lock();
  Require(true);
  RequireIdle();
  if (state_ == RunState::kFaulted)
    throw NotAvailable("the simulation stopped on a fault (" + last_error_ +
                       "); reset or stop it first");
  if (state_ == RunState::kRunning) return;
  state_ = RunState::kRunning;
  run_wall_start_ = Clock::now();
  run_sim_start_ = loaded_->physics->time();
  rate_wall_ = run_wall_start_;
  rate_sim_ = run_sim_start_;
}

void ModelCore::Pause() {
  {
    const auto lock = Lock();
    Require(true);
    if (!EndExperimentLocked("pause") && state_ == RunState::kRunning)
      state_ = RunState::kPaused;  // a step request ends paused
  }
  feeds_.NotifyRoom();  // a step waiting for a lossless consumer ends
}

void ModelCore::Stop() {
  {
    const auto lock = Lock();
    Require(true);
    if (!EndExperimentLocked("stop")) {
      EndRecordingLocked("the simulation was stopped (rewound)");
      // a step request running sees the new scene generation and ends without another step
      if (replay_)
        RestoreReplayLocked(replay_->first_step());  // the replay's start
      else
        RewindLocked();
      state_ = RunState::kStopped;
    }
  }
  feeds_.NotifyRoom();  // a step waiting for a lossless consumer ends
}

void ModelCore::Reset() {
  const auto lock = Lock();
  Require(true);
  RequireIdle();
  const RunState keep = state_ == RunState::kFaulted ? RunState::kStopped : state_;
  EndRecordingLocked("the simulation was reset (rewound)");
  if (replay_)
    RestoreReplayLocked(replay_->first_step());
  else
    RewindLocked();
  state_ = keep;
  // pacing and the achieved factor start again from the rewound time
  run_wall_start_ = Clock::now();
  run_sim_start_ = loaded_->physics->time();
  rate_wall_ = run_wall_start_;
  rate_sim_ = run_sim_start_;
}

void ModelCore::RequireCanStepLocked() const {
  Require(true);
  RequireIdle();
  if (state_ == RunState::kRunning) throw NotAvailable("the simulation is running; pause it to step");
  if (state_ == RunState::kFaulted)
    throw NotAvailable("the simulation stopped on a fault (" + last_error_ + "); reset it first");
}

uint64_t ModelCore::StepNow(uint64_t n) {
  auto lock = Lock();
  RequireCanStepLocked();
  return StepRequestLocked(lock, n);
}

uint64_t ModelCore::ControlCycle(const std::vector<std::pair<std::string, double>>& commands,
                                 uint64_t n, const char* const* ids, size_t count,
                                 std::vector<daq::Shape>* shapes, std::vector<double>* values) {
  auto lock = Lock();
  RequireCanStepLocked();
  // ids it cannot read are refused before anything changes
  SampleIntoLocked(ids, count, shapes, values);
  if (!commands.empty()) SetCommandsLocked(commands);
  const uint64_t steps = StepRequestLocked(lock, n);
  SampleIntoLocked(ids, count, shapes, values);
  return steps;
}

uint64_t ModelCore::StepRequestLocked(std::unique_lock<std::mutex>& lock, uint64_t n) {
  if (n == 0) return 0;
  step_request_ = n;
  step_done_ = 0;
  end_request_.clear();
  struct EndRequest {
    ModelCore* core;
    ~EndRequest() { core->step_request_ = 0; }  // the lock is held again when it ends
  } end_request{this};
  const uint64_t generation = restarts_;
  rate_wall_ = Clock::now();
  rate_sim_ = loaded_->physics->time();
  auto slice_end = rate_wall_ + kSlice;
  std::string ended;
  while (step_done_ < n) {
    // a replay's step request ends at the recording's end, as a replay running there pauses
    if (replay_ && loaded_->physics->steps() >= replay_->last_step()) break;
    // a lossless consumer is let catch up; a stop, pause or shutdown meanwhile ends the request
    if (AwaitConsumersLocked(lock) &&
        (restarts_ != generation || !end_request_.empty() || cancel_)) {
      ended = cancel_ ? "the Model is shutting down" : end_request_;
      break;
    }
    StepLocked();
    if (state_ == RunState::kFaulted) break;
    ++step_done_;
    if ((step_done_ & 15) == 0 && step_done_ < n && Clock::now() > slice_end) {
      MeasureRateLocked(0.5);
      HandOverLocked(lock);
      // a stop rewound (a new generation), a pause asked to end, or the Model is going
      if (restarts_ != generation || !end_request_.empty() || cancel_) {
        ended = cancel_ ? "the Model is shutting down" : end_request_;
        break;
      }
      slice_end = Clock::now() + kSlice;
    }
  }
  const uint64_t ran = step_done_;
  if (restarts_ == generation && state_ != RunState::kFaulted) {
    state_ = RunState::kPaused;
    // writes that came during the request and found no step after them take effect now, as
    // they do when nothing steps
    if (!pending_commands_.empty()) {
      ApplyPendingLocked();
      loaded_->sampler->Refresh();
    }
  }
  if (!ended.empty())
    logging::Get("model").notice("step request of %llu steps ended after %llu: %s",
                                 static_cast<unsigned long long>(n),
                                 static_cast<unsigned long long>(ran), ended.c_str());
  return ran;
}

void ModelCore::SetTimeStep(double seconds) {
  if (!(seconds > 0 && seconds <= 0.1) || !std::isfinite(seconds))
    throw InvalidValue("time step " + std::to_string(seconds) + " s: must be in (0, 0.1] s");
  const auto lock = Lock();
  Require(true);
  RequireIdle();
  RequireNotReplaying("set_time_step");
  // a recording maps time to steps with one time step
  if (seconds != loaded_->physics->description().settings.time_step)
    EndRecordingLocked("the time step changed");
  loaded_->physics->SetParameter("simulation.time_step", seconds);
}

void ModelCore::SetRealTimeFactor(double factor) {
  if (!(factor >= 0) || !std::isfinite(factor))
    throw InvalidValue("real-time factor " + std::to_string(factor) +
                       ": must be >= 0 (1 real time, 0 as fast as possible)");
  const auto lock = Lock();
  real_time_factor_ = factor;
  if (loaded_) {
    run_wall_start_ = Clock::now();
    run_sim_start_ = loaded_->physics->time();
  }
}

Status ModelCore::status() const {
  const auto lock = Lock();
  Status s;
  const bool running =
      state_ == RunState::kRunning || !experiment_.empty() || step_request_ != 0;
  s.state = running ? RunState::kRunning : state_;
  s.real_time_factor = experiment_.empty() ? real_time_factor_ : 0;
  s.achieved_real_time_factor = running ? achieved_rtf_ : 0;
  s.last_error = last_error_;
  if (loaded_) {
    s.scene = loaded_->source;
    s.sim_time = loaded_->physics->time();
    s.steps = loaded_->physics->steps();
    s.time_step = loaded_->physics->description().settings.time_step;
  }
  return s;
}

void ModelCore::ApplyPendingLocked() {
  for (const auto& [name, value] : pending_commands_) {
    loaded_->physics->SetCommand(name, value);
    loaded_->commands[name] = value;
    if (recorder_session_) RecordEventLocked("command", name, {value});  // no allocation else
  }
  pending_commands_.clear();
}

void ModelCore::StepLocked() {
  // commands and parameter writes take effect at this step boundary, in the order they came
  // Any exception ends here, as a NaN does: the engine stays at the start of the failing step
  // (PhysicsScene::Step promises it) and the Model says FAULTED with the reason; nothing escapes
  // to the execution context or the caller.
  try {
    ApplyPendingLocked();
    ExpirePullLocked();
    BeforeStepLocked();  // a replayed edit may swap the engine: take it afterwards
    loaded_->physics->Step();
  } catch (const sgal::SimulationFault& fault) {
    FaultLocked(fault.what());
    return;
  } catch (const std::exception& e) {
    FaultLocked(std::string("the physics step failed: ") + e.what());
    return;
  } catch (...) {
    FaultLocked("the physics step failed with an exception of unknown type");
    return;
  }
  try {
    loaded_->sampler->Refresh();
    AfterStepLocked();
    feeds_.OnStep(loaded_->physics->steps(), loaded_->physics->time());
    PublishLocked();
  } catch (const std::exception& e) {
    FaultLocked(std::string("after step ") + std::to_string(loaded_->physics->steps()) +
                ", sampling or publishing failed: " + e.what());
  }
}

void ModelCore::PublishLocked() {
  if (listeners_.empty() || !loaded_) return;
  auto snapshot = std::make_shared<Snapshot>();
  snapshot->generation = generation_;
  snapshot->step = loaded_->physics->steps();
  snapshot->time = loaded_->physics->time();
  snapshot->bodies = loaded_->physics->BodyStates();
  snapshot->tendons = loaded_->physics->TendonStates();
  for (auto* l : listeners_) l->OnSnapshot(snapshot);
}

void ModelCore::Advance(Clock::duration budget) {
  auto lock = Lock();
  if (!loaded_ || state_ != RunState::kRunning) return;
  sgal::PhysicsScene& physics = *loaded_->physics;
  const auto begin = Clock::now();
  if (real_time_factor_ > 0) {
    // the simulated time that is due now; never more than the budget's worth in one call
    const double wall = std::chrono::duration<double>(begin - run_wall_start_).count();
    const double due = run_sim_start_ + wall * real_time_factor_;
    while (physics.time() + 1e-12 < due && state_ == RunState::kRunning) {
      StepLocked();
      if (Clock::now() - begin > budget) {
        // cannot keep up: do not build a backlog, let the achieved factor show it
        run_wall_start_ = Clock::now();
        run_sim_start_ = physics.time();
        break;
      }
    }
  } else {
    // as fast as possible: as fast as the lossless consumers take the batches, too
    do {
      AwaitConsumersLocked(lock);
      if (!loaded_ || state_ != RunState::kRunning) return;
      StepLocked();
    } while (Clock::now() - begin < budget && state_ == RunState::kRunning);
  }
  MeasureRateLocked(1.0);
}

void ModelCore::MeasureRateLocked(double min_span_s) {
  const auto now = Clock::now();
  const double span = std::chrono::duration<double>(now - rate_wall_).count();
  if (span < min_span_s) return;
  achieved_rtf_ = (loaded_->physics->time() - rate_sim_) / span;
  rate_wall_ = now;
  rate_sim_ = loaded_->physics->time();
}

void ModelCore::Tick() {
  auto lock = Lock();
  if (!loaded_ || state_ != RunState::kRunning) return;
  // lock-step: a tick waits for the lossless consumers (bounded by their wait)
  if (AwaitConsumersLocked(lock) && (!loaded_ || state_ != RunState::kRunning)) return;
  StepLocked();
}

std::shared_ptr<const sgal::Scene> ModelCore::description() const {
  const auto lock = Lock();
  return loaded_ ? loaded_->description : nullptr;
}

void ModelCore::Save(const std::string& path) {
  sgal::Scene current;
  {
    const auto lock = Lock();
    Require(true);
    // the engine's copy holds the parameters tuned while running
    current = loaded_->physics->description();
  }
  collada::Export(current, path);
  logging::Get("model").notice("saved the scene with its current parameters to %s", path.c_str());
}

std::vector<ModelCore::ActuatorInfo> ModelCore::Actuators() const {
  const auto lock = Lock();
  Require(true);
  std::vector<ActuatorInfo> out;
  const auto parameters = loaded_->physics->Parameters();
  for (const auto& a : loaded_->description->actuators) {
    std::string unit;
    for (const auto& p : parameters)
      if (p.id == a.name + ".command") unit = p.unit;
    out.push_back({a.name, a.kind, a.tendon, unit});
  }
  return out;
}

void ModelCore::SetCommands(const std::vector<std::pair<std::string, double>>& commands) {
  const auto lock = Lock();
  SetCommandsLocked(commands);
}

void ModelCore::SetCommandsLocked(const std::vector<std::pair<std::string, double>>& commands) {
  Require(true);
  RequireNoExperiment();
  RequireNotReplaying("motor commands");
  if (commands.size() > limits_.ids_per_call)
    throw InvalidValue(std::to_string(commands.size()) + " commands in one call; at most " +
                       std::to_string(limits_.ids_per_call));
  for (const auto& [name, value] : commands) {
    if (loaded_->actuators.count(name) == 0)
      throw UnknownId("no actuator '" + name + "' in " + loaded_->source, name);
    if (!std::isfinite(value))
      throw InvalidValue("command for '" + name + "' is not finite");
  }
  const bool stepping = state_ == RunState::kRunning || step_request_ != 0;
  if (stepping) RequireQueueRoomLocked(commands.size());
  pending_commands_.insert(pending_commands_.end(), commands.begin(), commands.end());
  // while not stepping, the next step may be far away: apply now, between steps (after anything
  // still queued), so that the engine and its channels show the command at once
  if (!stepping) {
    ApplyPendingLocked();
    loaded_->sampler->Refresh();
  }
  for (const auto& [name, value] : commands) loaded_->commands[name] = value;
}

std::vector<ModelCore::ActuatorState> ModelCore::ActuatorStates() const {
  const auto lock = Lock();
  Require(true);
  std::vector<ActuatorState> out;
  for (const auto& a : loaded_->description->actuators) {
    ActuatorState s;
    s.name = a.name;
    // the engine's: also a command written as the `<actuator>.command` parameter
    s.command = loaded_->physics->GetParameter(a.name + ".command");
    s.tension = loaded_->physics->GetParameter(a.tendon + ".tendon.tension");
    out.push_back(s);
  }
  return out;
}

std::vector<daq::ChannelInfo> ModelCore::Channels(const std::string& pattern) const {
  if (pattern.size() > limits_.pattern_length)
    throw LimitExceeded("the pattern has " + std::to_string(pattern.size()) +
                        " characters; at most " + std::to_string(limits_.pattern_length),
                        limits_.pattern_length);
  // fnmatch(3) retries every position for each '*': its work grows with their number to the
  // power of the id's length, and it runs with the lock held
  const auto stars = static_cast<size_t>(std::count(pattern.begin(), pattern.end(), '*'));
  if (stars > limits_.pattern_stars)
    throw LimitExceeded("the pattern has " + std::to_string(stars) + " '*'; at most " +
                        std::to_string(limits_.pattern_stars),
                        limits_.pattern_stars);
  const auto lock = Lock();
  std::vector<daq::ChannelInfo> channels = registry_.List(pattern.empty() ? "*" : pattern);
  if (channels.size() > limits_.channels_per_list)
    throw LimitExceeded(std::to_string(channels.size()) + " channels match '" + pattern +
                        "'; one reply holds at most " + std::to_string(limits_.channels_per_list) +
                        ": narrow the pattern (e.g. MODEL.BODY.*)",
                        limits_.channels_per_list);
  return channels;
}

template <class Read>
auto ModelCore::ReadLocked(size_t count, Read&& read) const -> decltype(read()) {
  if (count > limits_.ids_per_call)
    throw LimitExceeded(std::to_string(count) + " ids in one call; at most " +
                            std::to_string(limits_.ids_per_call) + " (split the request)",
                        limits_.ids_per_call);
  Require(true);
  try {
    return read();
  } catch (const daq::UnknownId& e) {
    throw UnknownId(e.what(), e.id());
  }
}

std::vector<daq::Reading> ModelCore::Sample(const std::vector<std::string>& ids) const {
  const auto lock = Lock();
  return ReadLocked(ids.size(), [&] { return registry_.Sample(ids); });
}

void ModelCore::SampleInto(const char* const* ids, size_t count, std::vector<daq::Shape>* shapes,
                           std::vector<double>* values) const {
  const auto lock = Lock();
  SampleIntoLocked(ids, count, shapes, values);
}

void ModelCore::SampleIntoLocked(const char* const* ids, size_t count,
                                 std::vector<daq::Shape>* shapes,
                                 std::vector<double>* values) const {
  ReadLocked(count, [&] { registry_.SampleInto(ids, count, shapes, values); });
}

void ModelCore::SetChannel(const std::string& id, const std::vector<double>& values) {
  const auto lock = Lock();
  Require(true);
  RequireNoExperiment();
  RequireNotReplaying("set");
  if (!registry_.Contains(id)) throw UnknownId("unknown id '" + id + "'", id);
  const daq::ChannelInfo& info = registry_.Info(id);
  if (!info.writable) throw InvalidValue(id + ": read-only (a state of the simulation)");
  if (values.size() != info.shape.size())
    throw InvalidValue(id + ": expected " + std::to_string(info.shape.size()) + " values (shape " +
                       info.shape.ToString() + "), got " + std::to_string(values.size()));
  for (double v : values)
    if (!std::isfinite(v)) throw InvalidValue(id + ": value is not finite");
  // holding the lock, the simulation is between two steps even while running: apply now (after
  // anything still queued, to keep the order), so that the engine's refusal (a bound, a
  // negative mass) reaches the caller instead of a log line
  ApplyPendingLocked();
  try {
    registry_.Set(id, values);
  } catch (const daq::InvalidValue& e) {
    throw InvalidValue(e.what());
  }
  RecordEventLocked("parameter", id, values);
  loaded_->sampler->Refresh();
}

uint64_t ModelCore::Subscribe(const std::vector<std::string>& ids, uint32_t every_n_steps,
                              size_t batch_steps, std::chrono::milliseconds lossless_wait) {
  const auto lock = Lock();
  Require(true);
  return feeds_.Subscribe(ids, every_n_steps, batch_steps, lossless_wait);
}

void ModelCore::Unsubscribe(uint64_t subscription, const std::string& reason) {
  {
    const auto lock = Lock();
    feeds_.Unsubscribe(subscription, reason);
  }
  feeds_.NotifyRoom();
}

FeedStatus ModelCore::SubscriptionStatus(uint64_t subscription) const {
  const auto lock = Lock();
  return feeds_.Status(subscription);
}

void ModelCore::NoteUndelivered(uint64_t subscription, uint64_t batches, uint64_t samples) {
  const auto lock = Lock();
  feeds_.NoteUndelivered(subscription, batches, samples);
}

void ModelCore::SetConsumerWake(std::function<void(uint64_t)> wake) {
  const auto lock = Lock();
  feeds_.SetConsumerWake(std::move(wake));
}

bool ModelCore::AwaitConsumersLocked(std::unique_lock<std::mutex>& lock) {
  if (feeds_.lossless() == 0) return false;
  // what ends the wait besides room: a stop, pause, load or shutdown meanwhile
  const RunState state = state_;
  const uint64_t generation = restarts_;
  return feeds_.AwaitRoom(lock, [&] {
    return state_ != state || restarts_ != generation || !end_request_.empty() || cancel_;
  });
}

std::vector<daq::Batch> ModelCore::TakeBatches(uint64_t subscription, bool* gone,
                                               uint64_t* dropped_samples) {
  bool ended = false;
  std::vector<daq::Batch> batches = feeds_.TakeBatches(subscription, &ended, dropped_samples);
  if (gone != nullptr) *gone = ended;
  if (!batches.empty() || ended) return batches;
  {
    // never waits: a step holding the lock is not resting anyway
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || state_ == RunState::kRunning || step_request_ != 0) return batches;
    if (!feeds_.Flush(subscription)) return batches;
  }
  return feeds_.TakeBatches(subscription, gone, dropped_samples);
}

bool ModelCore::WaitForBatches(uint64_t subscription, std::chrono::milliseconds timeout) {
  return feeds_.WaitForBatches(subscription, timeout);
}

void ModelCore::AddListener(CoreListener* listener) {
  const auto lock = Lock();
  listeners_.push_back(listener);
  if (loaded_) {
    listener->OnScene(loaded_->description, generation_);
    PublishLocked();
  }
}

void ModelCore::RemoveListener(CoreListener* listener) {
  const auto lock = Lock();
  listeners_.erase(std::remove(listeners_.begin(), listeners_.end(), listener), listeners_.end());
}

std::string ModelCore::model_name() const {
  const auto lock = Lock();
  return loaded_ ? loaded_->name : "";
}

}  // namespace caliper::simulation

namespace caliper::simulation {

ModelCore::EditStatus ModelCore::ApplyEdit(const Rebuild& rebuild) {
  // Built outside the lock (a scene of meshes takes a while; steps and other clients go on),
  // then swapped in if the scene did not change meanwhile: another edit, a load or a rewind in
  // between means building again on the new scene (a few times), else a refusal.
  for (int attempt = 0;; ++attempt) {
    std::shared_ptr<const sgal::Scene> old_base;
    sgal::Scene current;
    uint64_t generation = 0;
    {
      const auto lock = Lock();
      Require(true);
      RequireNoExperiment();
      RequireNotReplaying("edit");
      old_base = loaded_->description;
      current = loaded_->physics->description();
      generation = generation_;
    }
    // the scene as loaded (what a rewind returns to) and the engine's copy (tuned parameters)
    auto base = std::make_shared<sgal::Scene>(*old_base);
    const std::string what = rebuild(*base, current);
    for (const sgal::Scene* s : {static_cast<const sgal::Scene*>(base.get()),
                                 static_cast<const sgal::Scene*>(&current)}) {
      const auto problems = sgal::Validate(*s);
      if (!problems.empty()) {
        std::string reason = what + ": the scene would not be sound:";
        for (const auto& p : problems) reason += "\n  " + p;
        throw sgal::EditError(reason);
      }
    }
    std::unique_ptr<sgal::PhysicsScene> physics;
    try {
      physics = MakePhysics(current);
    } catch (const std::exception& e) {
      throw sgal::EditError(what + ": the engine refuses the edited scene: " + e.what());
    }
    const auto lock = Lock();
    if (!loaded_ || generation_ != generation) {
      if (attempt < 4) continue;
      throw sgal::EditError(what + ": the scene kept changing while the edit was built (other "
                                   "edits, loads or rewinds); try again");
    }
    SwapEditedLocked(base, std::move(physics), what);
    return EditStatusLocked();
  }
}

void ModelCore::SwapEditedLocked(std::shared_ptr<const sgal::Scene> base,
                                 std::unique_ptr<sgal::PhysicsScene> physics,
                                 const std::string& what) {
  // the dynamic state now (the engine stepped while the edit was built), matched by name; an
  // actuator that an edit removes keeps its state and command aside, for the undo that brings
  // it back
  const sgal::Scene& current = physics->description();
  const sgal::Scene& old_scene = loaded_->physics->description();
  const sgal::DynamicState state =
      history_.CarryOver(old_scene, loaded_->physics->SaveDynamicState(), current);
  try {
    physics->RestoreDynamicState(state);
  } catch (const std::exception& e) {
    throw sgal::EditError(what + ": the state does not carry over: " + e.what());
  }
  if (pull_) {
    // the pull goes on, on the body of the same name
    const int index = current.BodyIndex(old_scene.bodies.at(pull_->body).name);
    pull_->body = index;
    if (index >= 0) physics->SetPull(*pull_);
  }
  const std::shared_ptr<const sgal::Scene> old_base = loaded_->description;
  auto loaded = std::make_unique<Loaded>();
  loaded->description = std::move(base);
  loaded->source = loaded_->source;
  loaded->name = loaded_->name;
  loaded->physics = std::move(physics);
  for (const auto& [name, value] : loaded_->commands)
    for (const auto& a : current.actuators)
      if (a.name == name) loaded->commands[name] = value;
  BuildLocked(std::move(loaded), /*edit=*/true);
  // a fault left the engine at the start of the failing step: the edit (often the undo of what
  // made it explode) may step on from there
  if (state_ == RunState::kFaulted) {
    state_ = RunState::kPaused;
    logging::Get("model").notice("the edit clears the fault (%s): paused at t = %.3f s",
                                 last_error_.c_str(), loaded_->physics->time());
    last_error_.clear();
  }
  history_.Applied(what);
  if (recorder_session_) {
    // the edited scene from this step on, and a keyframe of the engine built from it
    SessionRecorder& r = *recorder_session_;
    r.AddScene(loaded_->physics->steps(), loaded_->name + ".dae",
               ColladaBytesOf(loaded_->physics->description()));
    RecordEventLocked("edit", what, {});
    r.AddKeyframe(*loaded_->physics);
    r.ResolveChannels();  // the channels were registered anew
  }
  history_.FollowEdit(*old_base, *loaded_->description);
  logging::Get("model").notice("scene edit: %s (t = %.3f s)", what.c_str(),
                               loaded_->physics->time());
}

ModelCore::EditStatus ModelCore::EditStatusLocked() const {
  EditStatus s;
  s.revision = history_.revision();
  s.last = history_.last();
  s.undo = history_.undo_label();
  s.redo = history_.redo_label();
  return s;
}

ModelCore::EditStatus ModelCore::Edit(
    const std::function<sgal::SceneEdit(const sgal::Scene&)>& make) {
  // one edit per scene, each made against its own scene: its revert puts back exactly what
  // that scene held (the engine's copy has tuned parameters the loaded scene lacks)
  std::shared_ptr<EditHistory::Entry> entry;
  const EditStatus status = ApplyEdit([&](sgal::Scene& base, sgal::Scene& current) {
    entry = std::make_shared<EditHistory::Entry>(EditHistory::Entry{make(base), make(current)});
    entry->base.apply(base);
    entry->current.apply(current);
    return entry->base.label;
  });
  const auto lock = Lock();
  history_.Push(std::move(*entry));
  return EditStatusLocked();
}

ModelCore::EditStatus ModelCore::Undo() { return Walk(true); }

ModelCore::EditStatus ModelCore::Redo() { return Walk(false); }

ModelCore::EditStatus ModelCore::Walk(bool undo) {
  size_t depth = 0;
  const EditStatus status = ApplyEdit([&](sgal::Scene& base, sgal::Scene& current) {
    EditHistory::Entry entry;
    {
      const auto lock = Lock();
      entry = history_.Next(undo, &depth);
    }
    (undo ? entry.base.revert : entry.base.apply)(base);
    (undo ? entry.current.revert : entry.current.apply)(current);
    return (undo ? "undo " : "redo ") + entry.base.label;
  });
  const auto lock = Lock();
  history_.Walked(undo, depth);
  (void)status;
  return EditStatusLocked();
}

ModelCore::EditStatus ModelCore::edit_status() const {
  const auto lock = Lock();
  return EditStatusLocked();
}

void ModelCore::Pull(const std::string& body, const Eigen::Vector3d& point,
                     const Eigen::Vector3d& target, double stiffness_n_per_m) {
  const auto lock = Lock();
  Require(true);
  RequireNoExperiment();
  RequireNotReplaying("pull");
  const sgal::Scene& scene = loaded_->physics->description();
  const int index = scene.BodyIndex(body);
  if (index < 0) throw sgal::EditError("pull: no body '" + body + "'");
  if (scene.bodies[index].type != sgal::BodyType::kDynamic)
    throw sgal::EditError("pull: body '" + body + "' does not move");
  const double mass = scene.bodies[index].inertia.mass;
  const double dt = scene.settings.time_step;
  // stiffer than mass / dt^2 the explicit spring would swing wider each step
  const double stiffest = mass / (dt * dt);
  if (!(stiffness_n_per_m >= 0) || !std::isfinite(stiffness_n_per_m) || stiffness_n_per_m > stiffest)
    throw sgal::EditError("pull: stiffness must be in [0, " + std::to_string(stiffest) +
                          "] N/m (0: the default; stiffer than mass / time_step^2 is unstable)");
  const double reach = options_.max_distance;
  if (!point.allFinite() || !target.allFinite() || point.norm() > reach || target.norm() > reach)
    throw sgal::EditError("pull: the point and the target must be finite and within " +
                          std::to_string(reach) + " m of the origin");
  const double omega = 2 * M_PI * 2.0;  // the default spring moves the body at about 2 Hz
  sgal::Pull pull;
  pull.body = index;
  pull.point = point;
  pull.target = target;
  pull.stiffness = stiffness_n_per_m > 0 ? stiffness_n_per_m : mass * omega * omega;
  pull.damping = 2 * std::sqrt(pull.stiffness * mass);  // critical for the body alone
  try {
    loaded_->physics->SetPull(pull);
  } catch (const std::exception& e) {
    throw sgal::EditError(std::string("pull: ") + e.what());
  }
  if (!pull_ || pull_->body != index)
    logging::Get("model").info("pull on %s at %.3f %.3f %.3f m (body frame), %.1f N/m",
                               body.c_str(), point.x(), point.y(), point.z(), pull.stiffness);
  const bool changed = !pull_ || pull_->body != pull.body || pull_->point != pull.point ||
                       pull_->target != pull.target || pull_->stiffness != pull.stiffness;
  pull_ = pull;
  pull_until_ = Clock::now() + limits_.pull_lease;
  if (changed)  // a renewal of the same pull changes nothing in the simulation
    RecordEventLocked("pull", body, {point.x(), point.y(), point.z(), target.x(), target.y(),
                                     target.z(), pull.stiffness, pull.damping});
}

void ModelCore::ExpirePullLocked() {
  if (!pull_ || Clock::now() < pull_until_) return;
  logging::Get("model").notice("the pull on %s ended: not renewed for %.1f s (its client is gone?)",
                               loaded_->physics->description().bodies.at(pull_->body).name.c_str(),
                               std::chrono::duration<double>(limits_.pull_lease).count());
  pull_.reset();
  loaded_->physics->ClearPull();
  RecordEventLocked("release", "", {});
}

void ModelCore::ReleasePull() {
  const auto lock = Lock();
  if (!loaded_) return;
  if (pull_) {
    logging::Get("model").info("pull released");
    RecordEventLocked("release", "", {});
  }
  pull_.reset();
  loaded_->physics->ClearPull();
}

void ModelCore::Select(const std::string& kind, const std::string& name, uint32_t index) {
  const auto lock = Lock();
  if (!kind.empty()) Require(true);
  history_.Select(loaded_ ? loaded_->description.get() : nullptr, kind, name, index);
}

ModelCore::Selection ModelCore::selection() const {
  const auto lock = Lock();
  const EditHistory::Selection& s = history_.selection();
  return {s.kind, s.name, s.index, s.revision};
}

}  // namespace caliper::simulation
