#pragma once
// What the CORBA threads hand to the GUI thread: the latest scene and the poses and tendon states
// received since the GUI last looked, merged (a pose or tendon state replaces the older one). No
// CORBA, no Qt, no Coin: the servant converts, the GUI applies.

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/render_coin/scene_description.h"

namespace caliper::renderer {

/// Everything to apply, in this order: clear, scene, poses, tendons.
struct PendingUpdate {
  bool cleared = false;
  std::unique_ptr<render_coin::SceneDescription> scene;
  std::vector<uint32_t> body_indices;
  std::vector<render_coin::Pose> body_poses;
  std::vector<render_coin::TendonState> tendons;
  uint64_t update = 0;    // the Model's update counter of the latest transforms
  double sim_time = 0;    // [s]
  bool empty() const { return !cleared && !scene && body_indices.empty() && tendons.empty(); }
};

/// How the GUI draws, from the component's configuration.
struct ViewSettings {
  double max_fps = 30;  // [Hz]
  int width = 1024;     // screenshot size [px]
  int height = 768;
  bool show_constraint_axes = false;  // as configured; show_constraint_axes() overrides it
};

/// What tells one scene from another for framing: its name and its bodies' names. An edited
/// scene (tendons, obstacles, shapes changed) keeps it, so the view does not jump.
std::string SceneIdentity(const render_coin::SceneDescription& scene);

/// Thread-safe; any number of producers, one consumer.
class SceneMailbox {
 public:
  void SetSettings(const ViewSettings& settings);
  ViewSettings settings() const;
  /// True once after each SetSettings(): the GUI applies what it takes over from them.
  bool TakeSettingsChanged();
  /// A new scene replaces whatever was pending.
  void PutScene(render_coin::SceneDescription scene);
  void PutCleared();
  void PutTransforms(uint64_t update, double sim_time, const std::vector<uint32_t>& indices,
                     const std::vector<render_coin::Pose>& poses,
                     std::vector<render_coin::TendonState> tendons);
  /// Takes everything pending (possibly nothing).
  PendingUpdate Take();
  /// Scenes and transform calls received so far.
  uint64_t scenes_received() const { return scenes_; }
  uint64_t transforms_received() const { return transforms_; }

 private:
  mutable std::mutex mutex_;
  ViewSettings settings_;
  bool settings_changed_ = false;
  bool cleared_ = false;
  std::unique_ptr<render_coin::SceneDescription> scene_;
  std::map<uint32_t, render_coin::Pose> poses_;
  std::map<uint32_t, render_coin::TendonState> tendons_;
  uint64_t update_ = 0;
  double sim_time_ = 0;
  std::atomic<uint64_t> scenes_{0}, transforms_{0};
};

}  // namespace caliper::renderer
