#include "scene_mailbox.h"

namespace caliper::renderer {

std::string SceneIdentity(const render_coin::SceneDescription& scene) {
  std::string id = scene.name;
  for (const render_coin::Body& body : scene.bodies) id += '\n' + body.name;
  return id;
}

void SceneMailbox::SetSettings(const ViewSettings& settings) {
  std::lock_guard<std::mutex> lock(mutex_);
  settings_ = settings;
  settings_changed_ = true;
}

bool SceneMailbox::TakeSettingsChanged() {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool changed = settings_changed_;
  settings_changed_ = false;
  return changed;
}

ViewSettings SceneMailbox::settings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return settings_;
}

void SceneMailbox::PutScene(render_coin::SceneDescription scene) {
  std::lock_guard<std::mutex> lock(mutex_);
  scene_ = std::make_unique<render_coin::SceneDescription>(std::move(scene));
  poses_.clear();
  tendons_.clear();
  ++scenes_;
}

void SceneMailbox::PutCleared() {
  std::lock_guard<std::mutex> lock(mutex_);
  cleared_ = true;
  scene_.reset();
  poses_.clear();
  tendons_.clear();
}

void SceneMailbox::PutTransforms(uint64_t update, double sim_time,
                                 const std::vector<uint32_t>& indices,
                                 const std::vector<render_coin::Pose>& poses,
                                 std::vector<render_coin::TendonState> tendons) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (size_t i = 0; i < indices.size() && i < poses.size(); ++i) poses_[indices[i]] = poses[i];
  for (auto& t : tendons) tendons_[t.tendon_index] = std::move(t);
  update_ = update;
  sim_time_ = sim_time;
  ++transforms_;
}

PendingUpdate SceneMailbox::Take() {
  std::lock_guard<std::mutex> lock(mutex_);
  PendingUpdate out;
  out.cleared = cleared_;
  cleared_ = false;
  out.scene = std::move(scene_);
  for (const auto& [index, pose] : poses_) {
    out.body_indices.push_back(index);
    out.body_poses.push_back(pose);
  }
  poses_.clear();
  for (auto& entry : tendons_) out.tendons.push_back(std::move(entry.second));
  tendons_.clear();
  out.update = update_;
  out.sim_time = sim_time_;
  return out;
}

}  // namespace caliper::renderer
