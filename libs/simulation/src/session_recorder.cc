#include "caliper/simulation/session_recorder.h"

#include <algorithm>
#include <chrono>
#include <limits>

namespace caliper::simulation {

SessionRecorder::SessionRecorder(const std::string& path, const recording::Header& header,
                                 const recording::SceneVersion& scene, uint64_t max_bytes,
                                 const daq::Registry& registry)
    : registry_(registry),
      channels_(header.channels),
      keyframe_every_(header.keyframe_every),
      channels_every_(header.channels_every),
      first_step_(header.first_step) {
  ResolveChannels();
  writer_ = std::make_unique<recording::Writer>(path, header, scene,
                                                std::chrono::milliseconds(500), max_bytes);
}

void SessionRecorder::AddEvent(uint64_t step, const std::string& kind, const std::string& target,
                               std::vector<double> values) {
  writer_->AddEvent({step, kind, target, std::move(values)});
}

void SessionRecorder::AddKeyframe(sgal::PhysicsScene& physics) {
  recording::Keyframe k;
  k.step = physics.steps();
  k.time = physics.time();
  k.scene_version = scene_version_;
  k.state = physics.SaveDynamicState();
  writer_->AddKeyframe(k);
  // where the keyframe falls among the events of its step: a replay restoring it applies only
  // the events after this mark
  writer_->AddEvent({k.step, "keyframe", "", {}});
  physics.ResetCaches();  // as a replay restoring this keyframe will
  last_keyframe_ = k.step;
}

void SessionRecorder::AddScene(uint64_t step, const std::string& file_name, std::string bytes) {
  writer_->AddScene({++scene_version_, step, file_name, std::move(bytes)});
}

void SessionRecorder::ResolveChannels() {
  size_t offset = 0;
  columns_.clear();
  missing_.clear();
  for (const auto& c : channels_) {
    if (registry_.Contains(c.id)) {
      columns_.emplace_back(registry_.Resolve(c.id), offset);
    } else {
      // an edit removed it (its tendon): NaN from here on
      missing_.emplace_back(offset, static_cast<size_t>(c.rows) * c.cols);
    }
    offset += static_cast<size_t>(c.rows) * c.cols;
  }
  values_ = offset;
}

void SessionRecorder::AfterStep(uint64_t step, double time) {
  if (values_ == 0 || (step - first_step_) % channels_every_ != 0) return;
  recording::Sample sample;
  sample.step = step;
  sample.time = time;
  sample.values.resize(values_);
  for (const auto& [handle, offset] : columns_) registry_.Read(handle, &sample.values[offset]);
  for (const auto& [offset, count] : missing_)
    std::fill_n(sample.values.begin() + static_cast<long>(offset), count,
                std::numeric_limits<double>::quiet_NaN());
  writer_->AddSample(std::move(sample));
}

}  // namespace caliper::simulation
