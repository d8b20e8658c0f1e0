// ModelCore's session recordings and replays (libs/recording). A recording holds the scene as it
// runs, keyframes of the engine's exact state, and every event that changed the simulation with
// the step it took effect at; replaying re-simulates from a keyframe with those events, which
// gives the recorded run again bit for bit because keyframes also reset the engine's caches in
// the recorded run (PhysicsScene::ResetCaches) exactly where the replay does.
#include <log4cpp/AppenderSkeleton.hh>
#include <log4cpp/Category.hh>
#include <log4cpp/Priority.hh>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <set>
#include <limits>
#include <cmath>
#include <fstream>
#include <iterator>

#include "caliper/collada/exporter.h"
#include "caliper/core/scratch_directory.h"
#include "caliper/logging/log.h"
#include "caliper/simulation/model_core.h"

namespace caliper::simulation {

namespace {

// the Model's own log records, into the recording while one runs
class RecordingAppender : public log4cpp::AppenderSkeleton {
 public:
  RecordingAppender() : log4cpp::AppenderSkeleton("caliper-recording") {}
  void Attach(recording::Writer* writer) {
    std::lock_guard<std::mutex> lock(mutex_);
    writer_ = writer;
  }
  void close() override {}
  bool requiresLayout() const override { return false; }
  void setLayout(log4cpp::Layout*) override {}

 protected:
  void _append(const log4cpp::LoggingEvent& e) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (writer_ == nullptr) return;
    recording::LogRecord r;
    r.time = static_cast<double>(e.timeStamp.getSeconds()) + 1e-6 * e.timeStamp.getMicroSeconds();
    r.priority = log4cpp::Priority::getPriorityName(e.priority);
    r.category = e.categoryName;
    r.component = "model";
    r.message = e.message;
    writer_->AddLog(r);
  }

 private:
  std::mutex mutex_;
  recording::Writer* writer_ = nullptr;
};

RecordingAppender& Appender() {
  // lives as long as the process: log4cpp may still be inside it on another thread
  static auto* appender = [] {
    auto* a = new RecordingAppender;
    log4cpp::Category::getInstance("caliper").addAppender(*a);
    return a;
  }();
  return *appender;
}

}  // namespace

std::string ColladaBytesOf(const sgal::Scene& scene) {
  core::ScratchDirectory scratch("caliper-scene");
  const std::string path = scratch.path() + "/scene.dae";
  collada::Export(scene, path);
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void ModelCore::RequireNotReplaying(const char* what) const {
  if (replay_)
    throw NotAvailable(std::string(what) + ": the Model replays " + replay_->path() +
                       "; fork it first (caliper-ctl replay --fork) to change the simulation");
}

void ModelCore::RecordEventLocked(const std::string& kind, const std::string& target,
                                  std::vector<double> values) {
  if (!recorder_session_ || !loaded_) return;
  recorder_session_->AddEvent(loaded_->physics->steps(), kind, target, std::move(values));
}

void ModelCore::EndRecordingLocked(const std::string& why) {
  if (!recorder_session_) return;
  Appender().Attach(nullptr);
  const std::string path = recorder_session_->writer().path();
  // the last step recorded, so that a replay plays to here (samples and keyframes may end before)
  RecordEventLocked("end", why, {});
  recorder_session_->writer().Flush();
  last_recording_bytes_ = recorder_session_->writer().bytes_written();
  last_recording_error_ = recorder_session_->writer().error();
  recorder_session_.reset();  // commits and closes
  logging::Get("model").notice("recording %s ended: %s", path.c_str(), why.c_str());
}

ModelCore::RecordStatus ModelCore::StartRecording(const std::string& path,
                                                  const RecordOptions& options) {
  const auto lock = Lock();
  Require(true);
  RequireNoExperiment();
  if (recorder_session_)
    throw NotAvailable("already recording to " + recorder_session_->writer().path() +
                       "; stop that first");
  RequireNotReplaying("record");
  // a seek re-simulates up to one interval while holding the Model: keep it short
  if (options.keyframe_every < 1 || options.keyframe_every > kMaxKeyframeEvery)
    throw InvalidValue("keyframe_every must be in [1, " + std::to_string(kMaxKeyframeEvery) +
                       "] steps (a seek re-simulates up to one interval)");
  if (!options.channels.empty() && options.channels_every < 1)
    throw InvalidValue("channels_every must be at least 1 step");
  // the disk a client may fill: bounded by the Model, whatever the client asks
  if (options.max_bytes > limits_.recording_bytes)
    throw InvalidValue("max_bytes " + std::to_string(options.max_bytes) + ": a recording takes at "
                       "most " + std::to_string(limits_.recording_bytes) + " bytes");
  if (options.channels.size() > limits_.ids_per_call)
    throw InvalidValue(std::to_string(options.channels.size()) + " channels; a recording takes at "
                       "most " + std::to_string(limits_.ids_per_call));
  recording::Header header;
  header.model_name = loaded_->name;
  header.time_step = loaded_->physics->description().settings.time_step;
  header.keyframe_every = options.keyframe_every;
  header.channels_every = options.channels.empty() ? 0 : options.channels_every;
  header.first_step = loaded_->physics->steps();
  header.engine = physics_bullet::EngineId();
  for (const auto& id : options.channels) {
    if (!registry_.Contains(id)) throw UnknownId("record: unknown id '" + id + "'", id);
    const daq::ChannelInfo& info = registry_.Info(id);
    header.channels.push_back({id, info.unit, info.shape.rows, info.shape.cols});
  }
  // the scene as the engine runs it (tuned parameters included), as a COLLADA file
  recording::SceneVersion scene;
  scene.version = 0;
  scene.step = header.first_step;
  scene.file_name = loaded_->name + ".dae";
  scene.bytes = ColladaBytesOf(loaded_->physics->description());
  header.scene_file_name = scene.file_name;
  recorder_session_ = std::make_unique<SessionRecorder>(
      path, header, scene,
      options.max_bytes != 0 ? options.max_bytes : limits_.recording_bytes, registry_);
  last_recording_error_.clear();
  // the pull and the commands in force are part of the keyframe or recorded now
  if (pull_)
    RecordEventLocked("pull", loaded_->physics->description().bodies.at(pull_->body).name,
                      {pull_->point.x(), pull_->point.y(), pull_->point.z(), pull_->target.x(),
                       pull_->target.y(), pull_->target.z(), pull_->stiffness, pull_->damping});
  recorder_session_->AddKeyframe(*loaded_->physics);
  if (!session_log_) Appender().Attach(&recorder_session_->writer());
  logging::Get("model").notice("recording to %s from step %llu (keyframes every %u steps, %zu "
                               "channels)",
                               path.c_str(), static_cast<unsigned long long>(header.first_step),
                               options.keyframe_every, options.channels.size());
  RecordStatus s;
  s.recording = true;
  s.path = path;
  s.first_step = header.first_step;
  return s;
}

ModelCore::RecordStatus ModelCore::StopRecording() {
  const auto lock = Lock();
  RecordStatus s;
  if (!recorder_session_) {
    s.error = last_recording_error_;
    return s;
  }
  s.path = recorder_session_->writer().path();
  s.first_step = recorder_session_->first_step();
  s.steps = loaded_ ? loaded_->physics->steps() - s.first_step : 0;
  EndRecordingLocked("stopped");
  s.error = last_recording_error_;
  s.bytes = last_recording_bytes_;
  return s;
}

ModelCore::RecordStatus ModelCore::recording_status() const {
  const auto lock = Lock();
  RecordStatus s;
  s.error = last_recording_error_;
  if (!recorder_session_) return s;
  const recording::Writer& writer = recorder_session_->writer();
  s.recording = writer.error().empty();
  s.path = writer.path();
  s.first_step = recorder_session_->first_step();
  s.steps = loaded_ ? loaded_->physics->steps() - s.first_step : 0;
  s.bytes = writer.bytes_written();
  if (!s.recording) s.error = writer.error();
  return s;
}

void ModelCore::BeforeStepLocked() {
  sgal::PhysicsScene& physics = *loaded_->physics;
  const uint64_t step = physics.steps();
  if (recorder_session_) {
    SessionRecorder& r = *recorder_session_;
    if (r.writer().stopped()) {
      // a full disk or a vanished file: the recording ends, the simulation goes on
      logging::Get("model").error("%s", r.writer().error().c_str());
      EndRecordingLocked("write failed");
      return;
    }
    if (r.KeyframeDue(step)) r.AddKeyframe(physics);
  }
  if (fork_reset_every_ != 0 && !recorder_session_ && step % fork_reset_every_ == 0)
    physics.ResetCaches();
  if (replay_ && replay_->BeforeStep(step, physics, registry_, loaded_->commands) ==
                     Replayer::Due::kEdit) {
    // the edited scene and its keyframe at this step
    RestoreReplayLocked(step);
    BeforeStepLocked();  // the events after that keyframe's mark
  }
}

void ModelCore::AfterStepLocked() {
  if (recorder_session_)
    recorder_session_->AfterStep(loaded_->physics->steps(), loaded_->physics->time());
  if (replay_ && loaded_->physics->steps() >= replay_->last_step() &&
      state_ == RunState::kRunning) {
    state_ = RunState::kPaused;  // the end of the recording
    logging::Get("model").notice("replay of %s: at its end (t = %.3f s)", replay_->path().c_str(),
                                 loaded_->physics->time());
  }
}

void ModelCore::RestoreReplayLocked(uint64_t step) {
  const Replayer::Start start =
      replay_->StartAt(step, [this](const std::string& file_name, const std::string& bytes) {
        return ImportBytes(file_name, bytes);
      });
  auto loaded = std::make_unique<Loaded>();
  loaded->description = start.scene;
  loaded->source = replay_->path() + " (replay)";
  loaded->name = replay_->header().model_name;
  loaded->physics = MakePhysics(*start.scene);
  // as an edit does: a step request playing on goes on across a replayed edit
  BuildLocked(std::move(loaded), /*edit=*/true);
  replay_->Restore(start, *loaded_->physics, registry_);
  loaded_->sampler->Refresh();
  PublishLocked();
}

ModelCore::ReplayStatus ModelCore::ReplayStatusLocked() const {
  ReplayStatus s;
  if (!replay_) return s;
  s.replaying = true;
  s.path = replay_->path();
  s.first_step = replay_->first_step();
  s.last_step = replay_->last_step();
  s.step = loaded_ ? loaded_->physics->steps() : 0;
  s.start_time = replay_->start_time();
  s.end_time = s.start_time + (s.last_step - s.first_step) * replay_->header().time_step;
  s.time = loaded_ ? loaded_->physics->time() : 0;
  return s;
}

ModelCore::ReplayStatus ModelCore::OpenReplay(const std::string& path) {
  auto replay = std::make_unique<Replayer>(path);
  const auto lock = Lock();
  RequireIdle();
  if (recorder_session_) EndRecordingLocked("a replay was opened");
  std::unique_ptr<Replayer> previous = std::move(replay_);
  replay_ = std::move(replay);
  fork_reset_every_ = 0;
  try {
    RestoreReplayLocked(replay_->first_step());
  } catch (...) {
    replay_ = std::move(previous);
    throw;
  }
  history_.ClearUndo();
  state_ = RunState::kPaused;
  last_error_.clear();
  // a copy sent by content before goes once this replay is another file
  if (replay_copy_ && path.rfind(replay_copy_->path() + "/", 0) != 0) {
    previous.reset();
    replay_copy_.reset();
  }
  logging::Get("model").notice("replaying %s: %.3f s of %s", path.c_str(), replay_->duration(),
                               replay_->header().model_name.c_str());
  return ReplayStatusLocked();
}

ModelCore::ReplayStatus ModelCore::OpenReplayData(const std::string& file_name,
                                                  const std::string& bytes) {
  const std::string name = std::filesystem::path(file_name).filename().string();
  if (name.empty() || name == "." || name == "..")
    throw recording::RecordingError("a recording sent by content needs a file name, got '" +
                                    file_name + "'");
  {
    const auto lock = Lock();
    RequireIdle();  // before writing up to a message's worth of copy for nothing
  }
  auto copy = std::make_unique<core::ScratchDirectory>("caliper-replay");
  const std::string path = copy->path() + "/" + name;
  {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush())
      throw recording::RecordingError(name + " (sent by content): cannot write its copy " + path);
  }
  const ReplayStatus status = OpenReplay(path);
  const auto lock = Lock();
  if (replay_ && replay_->path() == path) replay_copy_ = std::move(copy);
  return status;
}

void ModelCore::EndReplayLocked() {
  replay_.reset();
  replay_copy_.reset();  // a copy sent by content goes with its replay
}

ModelCore::ReplayStatus ModelCore::Seek(double time_s) {
  auto lock = Lock();
  if (!replay_) throw NotAvailable("seek: no replay is open (caliper-ctl replay FILE)");
  RequireIdle();
  if (!std::isfinite(time_s)) throw InvalidValue("seek: the time is not finite");
  const uint64_t target = replay_->StepNearest(time_s);
  const RunState keep = state_;
  // from the current state when the target lies ahead within a keyframe interval, else from the
  // keyframe at or before it
  const uint64_t at = loaded_->physics->steps();
  const uint64_t keyframe = replay_->KeyframeStepAtOrBefore(target);
  if (!(target >= at && keyframe <= at)) RestoreReplayLocked(target);
  while (loaded_->physics->steps() < target && state_ != RunState::kFaulted) StepLocked();
  state_ = keep == RunState::kRunning ? RunState::kRunning : RunState::kPaused;
  run_wall_start_ = std::chrono::steady_clock::now();
  run_sim_start_ = loaded_->physics->time();
  return ReplayStatusLocked();
}

ModelCore::ReplayStatus ModelCore::replay_status() const {
  const auto lock = Lock();
  return ReplayStatusLocked();
}

void ModelCore::Fork() {
  const auto lock = Lock();
  if (!replay_) throw NotAvailable("fork: no replay is open");
  const std::string path = replay_->path();
  loaded_->source = path + " (forked at t = " + std::to_string(loaded_->physics->time()) + " s)";
  fork_reset_every_ = replay_->keyframe_every();  // as the recorded run did, so it goes on alike
  EndReplayLocked();
  loaded_->physics->ClearPull();  // a replayed pull ends: its client was the recording
  if (state_ == RunState::kRunning) state_ = RunState::kPaused;
  logging::Get("model").notice("forked from %s at t = %.3f s: simulating on", path.c_str(),
                               loaded_->physics->time());
}

void ModelCore::SetReplayKeyframeHook(KeyframeHook hook) {
  const auto lock = Lock();
  if (!replay_) throw NotAvailable("no replay is open");
  replay_->set_keyframe_hook(std::move(hook));
}

void ModelCore::AddSessionLog(const recording::LogRecord& record) {
  const auto lock = Lock();
  if (recorder_session_) recorder_session_->writer().AddLog(record);
}

void ModelCore::UseSessionLog(bool on) {
  const auto lock = Lock();
  session_log_ = on;
  if (recorder_session_) Appender().Attach(on ? nullptr : &recorder_session_->writer());
}

sgal::DynamicState ModelCore::dynamic_state() const {
  const auto lock = Lock();
  Require(true);
  return loaded_->physics->SaveDynamicState();
}

namespace {

// bitwise, NaN equal to NaN
bool Same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::string Number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// the first difference between two states, named (empty when there is none)
std::string Difference(const sgal::DynamicState& got, const sgal::DynamicState& recorded,
                       const sgal::Scene& scene) {
  if (!Same(got.time, recorded.time))
    return "time " + Number(got.time) + " s, recorded " + Number(recorded.time) + " s";
  if (got.engine.size() != recorded.engine.size())
    return "the engine state has " + std::to_string(got.engine.size()) + " values, recorded " +
           std::to_string(recorded.engine.size());
  constexpr size_t kPerBody = physics_bullet::kEngineValuesPerBody;
  static const char* const kParts[] = {"orientation", "orientation", "orientation",
                                       "orientation", "orientation", "orientation",
                                       "orientation", "orientation", "orientation",
                                       "position",    "position",    "position"};
  for (size_t i = 0; i < got.engine.size(); ++i) {
    if (Same(got.engine[i], recorded.engine[i])) continue;
    std::string what = "engine value " + std::to_string(i);
    if (i < scene.bodies.size() * kPerBody) {
      const size_t k = i % kPerBody;
      const std::string part = k < 12    ? kParts[k]
                               : k < 24  ? "interpolation transform"
                               : k < 27  ? "linear velocity"
                               : k < 30  ? "angular velocity"
                                         : "interpolation velocity";
      what = "body '" + scene.bodies[i / kPerBody].name + "' " + part;
    }
    return what + ": " + Number(got.engine[i]) + ", recorded " + Number(recorded.engine[i]) +
           " (differs by " + Number(got.engine[i] - recorded.engine[i]) + ")";
  }
  if (got.actuators.size() != recorded.actuators.size() ||
      got.joint_positions.size() != recorded.joint_positions.size() ||
      got.commands.size() != recorded.commands.size())
    return "the state's layout differs: " + std::to_string(got.actuators.size()) +
           " actuators, " + std::to_string(got.joint_positions.size()) + " joints; recorded " +
           std::to_string(recorded.actuators.size()) + ", " +
           std::to_string(recorded.joint_positions.size());
  for (size_t a = 0; a < got.commands.size(); ++a)
    if (!Same(got.commands[a], recorded.commands[a]))
      return "actuator '" + (a < scene.actuators.size() ? scene.actuators[a].name : "?") +
             "' command " + Number(got.commands[a]) + ", recorded " + Number(recorded.commands[a]);
  for (size_t a = 0; a < got.actuators.size(); ++a) {
    if (got.actuators[a].size() != recorded.actuators[a].size())
      return "actuator '" + (a < scene.actuators.size() ? scene.actuators[a].name : "?") +
             "' has " + std::to_string(got.actuators[a].size()) + " state values, recorded " +
             std::to_string(recorded.actuators[a].size());
    for (size_t k = 0; k < got.actuators[a].size(); ++k)
      if (!Same(got.actuators[a][k], recorded.actuators[a][k]))
        return "actuator '" + (a < scene.actuators.size() ? scene.actuators[a].name : "?") +
               "' state value " + std::to_string(k) + ": " + Number(got.actuators[a][k]) +
               ", recorded " + Number(recorded.actuators[a][k]);
  }
  for (size_t j = 0; j < got.joint_positions.size() && j < recorded.joint_positions.size(); ++j)
    if (!Same(got.joint_positions[j], recorded.joint_positions[j]))
      return "joint '" + scene.constraints.at(j).name + "' position " +
             Number(got.joint_positions[j]) + ", recorded " + Number(recorded.joint_positions[j]);
  // a recording of an older build has none: the delayed channels then went unchecked
  if (!recorded.measurements.empty()) {
    if (got.measurements.size() != recorded.measurements.size())
      return "the delayed channels hold " + std::to_string(got.measurements.size()) +
             " values, recorded " + std::to_string(recorded.measurements.size());
    for (size_t m = 0; m < got.measurements.size(); ++m)
      if (!Same(got.measurements[m], recorded.measurements[m]))
        return "delayed channel value " + std::to_string(m) + ": " + Number(got.measurements[m]) +
               ", recorded " + Number(recorded.measurements[m]);
  }
  return "";
}

}  // namespace

Verification VerifyRecording(const std::string& path,
                             const std::function<void(uint64_t, uint64_t)>& progress) {
  Verification v;
  recording::Reader reader(path);
  const recording::Header& h = reader.header();
  const uint64_t last = reader.last_step();
  std::vector<std::string> ids;
  for (const auto& c : h.channels) ids.push_back(c.id);
  std::set<uint64_t> edits;  // their keyframes hold the state after the edit: compared after it
  for (const auto& e : reader.Events(0, last + 1))
    if (e.kind == "edit") edits.insert(e.step);
  ModelCore core;
  core.OpenReplay(path);
  // each periodic keyframe compared where the recorded run took it: after its step's earlier
  // events (a command at that step is in it), before the cache reset
  std::string keyframe_diff;
  uint64_t keyframe_step = 0;
  core.SetReplayKeyframeHook([&](uint64_t at, const sgal::PhysicsScene& physics) {
    if (!keyframe_diff.empty() || edits.count(at) != 0) return;
    const recording::Keyframe k = reader.KeyframeAtOrBefore(at);
    if (k.step != at) return;
    ++v.keyframes;
    const std::string diff = Difference(physics.SaveDynamicState(), k.state, physics.description());
    if (!diff.empty()) {
      keyframe_diff = "keyframe at step " + std::to_string(at) + " (t = " + Number(k.time) +
                      " s): " + diff;
      keyframe_step = at;
    }
  });
  uint64_t step = h.first_step;
  const uint64_t chunk = 1000;
  for (uint64_t from = step; from < last; from += chunk) {
    const std::vector<recording::Sample> samples = reader.Samples(from + 1, std::min(last, from + chunk) + 1);
    size_t next_sample = 0;
    while (step < std::min(last, from + chunk)) {
      if (core.StepNow(1) != 1)
        throw recording::RecordingError(path + ": the replay faulted at step " +
                                        std::to_string(step + 1) + ": " + core.status().last_error);
      ++step;
      ++v.steps;
      if (!keyframe_diff.empty()) {
        v.identical = false;
        v.divergent_step = keyframe_step;
        v.detail = keyframe_diff;
        return v;
      }
      while (next_sample < samples.size() && samples[next_sample].step < step) ++next_sample;
      if (next_sample < samples.size() && samples[next_sample].step == step && !ids.empty()) {
        std::vector<double> now;
        for (const auto& reading : core.Sample(ids))
          now.insert(now.end(), reading.values.begin(), reading.values.end());
        const auto& recorded = samples[next_sample].values;
        ++v.samples;
        if (now.size() != recorded.size()) {
          v.identical = false;
          v.divergent_step = step;
          v.detail = "the sample at step " + std::to_string(step) + " has " +
                     std::to_string(now.size()) + " values, recorded " +
                     std::to_string(recorded.size());
          return v;
        }
        for (size_t i = 0; i < now.size() && i < recorded.size(); ++i)
          if (!Same(now[i], recorded[i])) {
            v.identical = false;
            v.divergent_step = step;
            v.detail = "channel value " + std::to_string(i) + " at step " + std::to_string(step) +
                       ": " + Number(now[i]) + ", recorded " + Number(recorded[i]);
            return v;
          }
      }
      if (progress && step % 1000 == 0) progress(step, last);
    }
  }
  if (progress) progress(step, last);
  return v;
}

}  // namespace caliper::simulation
