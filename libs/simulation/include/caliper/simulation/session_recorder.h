#pragma once
// One session recording being written (libs/recording): its file, the channels it samples
// resolved to registry handles (NaN for those an edit removed), the scene versions it holds, and
// its keyframes, each of which also resets the engine's caches, exactly where a replay restoring
// it will (which makes the replay bit for bit). What to record and when is the owner's: it
// validates the request, builds the header, and calls this at every event, step and edit.
//
// Threading: not thread-safe. ModelCore owns one while it records and calls it with its lock
// (ModelCore::mutex_) held; the writer itself commits on a thread of its own.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "caliper/daq/registry.h"
#include "caliper/recording/recording.h"
#include "caliper/sgal/physics_scene.h"

namespace caliper::simulation {

/// The writing side of a session recording; see the file's comment for the threading.
class SessionRecorder {
 public:
  /// Creates `path` with `header` and scene version 0 (`scene`), committing every 500 ms and
  /// stopping (as on a full disk) beyond `max_bytes`; samples header.channels every
  /// header.channels_every steps from header.first_step, read from `registry` (which must
  /// outlive it and hold every channel now). Throws recording::RecordingError for the file.
  SessionRecorder(const std::string& path, const recording::Header& header,
                  const recording::SceneVersion& scene, uint64_t max_bytes,
                  const daq::Registry& registry);
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  /// An event taking effect before step `step` + 1.
  void AddEvent(uint64_t step, const std::string& kind, const std::string& target,
                std::vector<double> values);
  /// A keyframe of `physics` as it stands, its mark among the events of its step (a replay
  /// restoring it applies only the events after the mark), then physics.ResetCaches().
  void AddKeyframe(sgal::PhysicsScene& physics);
  /// Whether a periodic keyframe is due before step `step` + 1 (and not taken there yet).
  bool KeyframeDue(uint64_t step) const {
    return step % keyframe_every_ == 0 && step != last_keyframe_;
  }
  /// An edited scene from step `step` on, as a new scene version (`bytes`: a file `file_name`).
  void AddScene(uint64_t step, const std::string& file_name, std::string bytes);
  /// Resolves the channels again after the registry changed (an edit registers them anew); a
  /// channel no longer there is recorded as NaN from now on.
  void ResolveChannels();
  /// After step `step` at simulated time `time` [s]: the channels' sample when one is due.
  void AfterStep(uint64_t step, double time);

  /// The file being written, for its path, size, log records, errors and a flush.
  recording::Writer& writer() { return *writer_; }
  const recording::Writer& writer() const { return *writer_; }
  /// The step the recording started at.
  uint64_t first_step() const { return first_step_; }
  /// The scene version the next keyframe names (0 until an edit).
  uint32_t scene_version() const { return scene_version_; }
  /// Values per channel sample (0: no channels).
  size_t values() const { return values_; }

 private:
  const daq::Registry& registry_;
  std::unique_ptr<recording::Writer> writer_;
  std::vector<recording::Channel> channels_;             // as in the file's header
  std::vector<std::pair<daq::Handle, size_t>> columns_;  // handle, first value in a sample
  std::vector<std::pair<size_t, size_t>> missing_;       // first value, count: gone (NaN)
  size_t values_ = 0;
  uint32_t keyframe_every_ = 100;  // [steps]
  uint32_t channels_every_ = 1;    // [steps]
  uint64_t first_step_ = 0;
  uint64_t last_keyframe_ = UINT64_MAX;
  uint32_t scene_version_ = 0;
};

}  // namespace caliper::simulation
