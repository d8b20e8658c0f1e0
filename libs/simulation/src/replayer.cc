#include "caliper/simulation/replayer.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::simulation {

namespace {

// a recorded pull on `scene`: body, point, target, stiffness, damping (critical for the body's
// mass when an older file left it out)
sgal::Pull PullOf(const recording::Event& e, const sgal::Scene& scene) {
  sgal::Pull pull;
  pull.body = scene.BodyIndex(e.target);
  pull.point = {e.values.at(0), e.values.at(1), e.values.at(2)};
  pull.target = {e.values.at(3), e.values.at(4), e.values.at(5)};
  pull.stiffness = e.values.at(6);
  pull.damping = e.values.size() > 7
                     ? e.values[7]
                     : 2 * std::sqrt(pull.stiffness * scene.bodies.at(pull.body).inertia.mass);
  return pull;
}

}  // namespace

Replayer::Replayer(const std::string& path)
    : reader_(std::make_unique<recording::Reader>(path)), path_(path) {
  const uint64_t last = reader_->last_step();
  events_ = reader_->Events(0, last + 1);
  scenes_ = reader_->scenes();
  keyframe_every_ = reader_->header().keyframe_every;
  // a seek re-simulates from the keyframe before it while holding the Model: a file whose
  // keyframes lie far apart would hold it that long
  uint64_t previous = reader_->header().first_step, widest = 0;
  for (uint64_t k : reader_->keyframe_steps()) {
    widest = std::max(widest, k - std::min(k, previous));
    previous = k;
  }
  widest = std::max(widest, last - std::min(last, previous));
  if (widest > kMaxKeyframeEvery)
    throw recording::RecordingError(path + ": its keyframes lie up to " + std::to_string(widest) +
                                    " steps apart; a replay takes at most " +
                                    std::to_string(kMaxKeyframeEvery));
  const std::string& engine = reader_->header().engine;
  if (!engine.empty() && engine != physics_bullet::EngineId())
    throw recording::RecordingError(path + " was recorded with " + engine + "; this build runs " +
                                    physics_bullet::EngineId() +
                                    ": its replay would not give the recording again");
}

Replayer::Start Replayer::StartAt(uint64_t step, const Importer& import) {
  Start start;
  start.keyframe = reader_->KeyframeAtOrBefore(step);
  const recording::Keyframe& k = start.keyframe;
  const recording::SceneVersion* version = nullptr;
  for (const auto& v : scenes_)
    if (v.version == k.scene_version) version = &v;
  if (version == nullptr)
    throw recording::RecordingError(path_ + ": keyframe at step " + std::to_string(k.step) +
                                    " names scene version " + std::to_string(k.scene_version) +
                                    ", which the file lacks");
  std::shared_ptr<const sgal::Scene>& cached = imported_[version->version];
  if (!cached)
    cached = std::make_shared<const sgal::Scene>(import(version->file_name, version->bytes));
  start.scene = cached;
  start.scene_step = version->step;
  return start;
}

void Replayer::Restore(const Start& start, sgal::PhysicsScene& physics, daq::Registry& registry) {
  const recording::Keyframe& k = start.keyframe;
  // the keyframe's mark among the events: what came before it is in the keyframe's state or
  // (parameter writes, the pull) applied here; what came after is applied by the steps
  size_t mark = 0;
  bool marked = false;
  for (size_t i = 0; i < events_.size(); ++i)
    if (events_[i].kind == "keyframe" && events_[i].step == k.step) {
      mark = i;
      marked = true;
    }
  if (!marked)
    throw recording::RecordingError(path_ + ": the keyframe at step " + std::to_string(k.step) +
                                    " has no mark among the events (a damaged file)");
  // parameter writes since the scene version began are not in a keyframe: apply them first
  for (size_t i = 0; i < mark; ++i) {
    const auto& e = events_[i];
    if (e.kind == "parameter" && e.step >= start.scene_step) registry.Set(e.target, e.values);
  }
  try {
    physics.RestoreDynamicState(k.state);
  } catch (const std::exception& e) {
    throw recording::RecordingError(
        path_ + ": the keyframe at step " + std::to_string(k.step) + " does not fit its scene " +
        "(a recording of another scene version or another Caliper build): " + e.what());
  }
  // the pull in force then
  const recording::Event* pull = nullptr;
  for (size_t i = 0; i < mark; ++i) {
    const auto& e = events_[i];
    // across scene versions: a pull held through an edit goes on in the edited scene
    if (e.kind == "pull" || e.kind == "release") pull = &e;
  }
  if (pull != nullptr && pull->kind == "pull") physics.SetPull(PullOf(*pull, *start.scene));
  physics.ResetCaches();
  last_reset_ = k.step;
  next_ = mark + 1;
}

Replayer::Due Replayer::BeforeStep(uint64_t step, sgal::PhysicsScene& physics,
                                   daq::Registry& registry,
                                   std::map<std::string, double>& commands) {
  for (; next_ < events_.size() && events_[next_].step <= step; ++next_) {
    const recording::Event& e = events_[next_];
    if (e.kind == "keyframe" && keyframe_hook_) keyframe_hook_(step, physics);
    if (e.kind == "keyframe" || e.kind == "end") continue;
    if (e.kind == "command") {
      physics.SetCommand(e.target, e.values.at(0));
      commands[e.target] = e.values.at(0);
    } else if (e.kind == "parameter") {
      registry.Set(e.target, e.values);
    } else if (e.kind == "pull") {
      physics.SetPull(PullOf(e, physics.description()));
    } else if (e.kind == "release") {
      physics.ClearPull();
    } else if (e.kind == "edit") {
      return Due::kEdit;  // the edited scene and its keyframe at this step
    }
  }
  if (step % keyframe_every_ == 0 && step != last_reset_) {
    physics.ResetCaches();
    last_reset_ = step;
  }
  return Due::kApplied;
}

uint64_t Replayer::StepNearest(double time_s) const {
  const uint64_t first = first_step(), last = last_step();
  const double start = start_time();
  const double end = start + (last - first) * reader_->header().time_step;
  const double clamped = std::min(std::max(time_s, start), end);
  return std::min(last, first + static_cast<uint64_t>(
                                    std::llround((clamped - start) / reader_->header().time_step)));
}

uint64_t Replayer::KeyframeStepAtOrBefore(uint64_t step) const {
  return reader_->KeyframeAtOrBefore(step).step;
}

double Replayer::start_time() const { return reader_->KeyframeAtOrBefore(first_step()).time; }

double Replayer::end_time() const {
  return start_time() + (last_step() - first_step()) * reader_->header().time_step;
}

}  // namespace caliper::simulation
