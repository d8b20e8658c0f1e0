#pragma once
// One session recording being replayed (libs/recording): its file and events, where the replay
// stands among them, and each of its scene versions imported once. A replay re-simulates from a
// keyframe with the recorded events and resets the engine's caches where the recorded run did
// (at every keyframe_every steps and at every restored keyframe), which gives the recorded run
// again bit for bit. Building the engine of a scene version is the owner's: it asks StartAt for
// the keyframe and its scene, builds and registers the engine, then calls Restore.
//
// Threading: not thread-safe. ModelCore owns one while it replays and calls it with its lock
// (ModelCore::mutex_) held.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "caliper/daq/registry.h"
#include "caliper/recording/recording.h"
#include "caliper/sgal/physics_scene.h"
#include "caliper/sgal/scene.h"

namespace caliper::simulation {

/// The widest keyframe interval a recording may have [steps]: a seek re-simulates up to one
/// interval while holding the Model.
constexpr uint32_t kMaxKeyframeEvery = 1000;

/// The reading side of a session recording; see the file's comment for the threading.
class Replayer {
 public:
  /// Told where each periodic keyframe was taken (after its step's earlier events, before the
  /// cache reset), with the engine as it stands there.
  using KeyframeHook = std::function<void(uint64_t step, const sgal::PhysicsScene& physics)>;
  /// Imports a scene sent as the bytes of a file named `file_name` (throws what the importer does).
  using Importer =
      std::function<sgal::Scene(const std::string& file_name, const std::string& bytes)>;

  /// Where a restore starts: a keyframe and the scene version it names.
  struct Start {
    recording::Keyframe keyframe;
    std::shared_ptr<const sgal::Scene> scene;  // that version, imported
    uint64_t scene_step = 0;                   // the step the version begins at
  };

  /// What BeforeStep found among the events due.
  enum class Due {
    kApplied,  // every event due was applied (and the caches reset when due)
    kEdit,     // a replayed edit: the owner restores at the step (StartAt, Restore) and calls again
  };

  /// Opens `path` with all its events. Throws recording::RecordingError naming the file: one it
  /// cannot read, keyframes more than kMaxKeyframeEvery steps apart, or another engine than
  /// physics_bullet::EngineId() (its replay would not give the recording again).
  explicit Replayer(const std::string& path);
  Replayer(const Replayer&) = delete;
  Replayer& operator=(const Replayer&) = delete;

  /// The keyframe at or before `step` with its scene version, which `import` turns into a scene
  /// the first time only. Throws recording::RecordingError for a version the file lacks.
  Start StartAt(uint64_t step, const Importer& import);
  /// Brings `physics`, just built from start.scene (its channels in `registry`), to the keyframe:
  /// the parameter writes of its scene version before the keyframe's mark, its dynamic state,
  /// the pull in force, a cache reset; the events after the mark come with the steps. Throws
  /// recording::RecordingError for a keyframe without a mark or one that does not fit the scene.
  void Restore(const Start& start, sgal::PhysicsScene& physics, daq::Registry& registry);
  /// Before step `step` + 1 (`step` = physics.steps()): applies the events due (commands also
  /// into `commands`, the last command per actuator; parameter writes through `registry`), calls
  /// the keyframe hook at each keyframe mark, and resets the caches every keyframe_every steps.
  /// Stops at an edit, returning Due::kEdit.
  Due BeforeStep(uint64_t step, sgal::PhysicsScene& physics, daq::Registry& registry,
                 std::map<std::string, double>& commands);
  /// The step nearest `time_s` [s], clamped to the recording.
  uint64_t StepNearest(double time_s) const;
  /// The step of the keyframe at or before `step`.
  uint64_t KeyframeStepAtOrBefore(uint64_t step) const;

  void set_keyframe_hook(KeyframeHook hook) { keyframe_hook_ = std::move(hook); }
  /// The file replayed.
  const std::string& path() const { return path_; }
  const recording::Header& header() const { return reader_->header(); }
  /// Simulated time from the first to the last step [s].
  double duration() const { return reader_->duration(); }
  /// The step the recording started at.
  uint64_t first_step() const { return reader_->header().first_step; }
  /// The last step recorded (keyframe, event or sample).
  uint64_t last_step() const { return reader_->last_step(); }
  /// Steps between the recording's periodic keyframes (and cache resets).
  uint32_t keyframe_every() const { return keyframe_every_; }
  /// Simulated time at the first step [s].
  double start_time() const;
  /// Simulated time at the last step [s].
  double end_time() const;
  /// The event the next BeforeStep applies first (an index into the file's events).
  size_t next_event() const { return next_; }

 private:
  std::unique_ptr<recording::Reader> reader_;
  std::string path_;
  std::vector<recording::Event> events_;  // all, in order
  std::vector<recording::SceneVersion> scenes_;
  size_t next_ = 0;                   // the next event to apply
  uint64_t last_reset_ = UINT64_MAX;  // the step caches were last reset at
  uint32_t keyframe_every_ = 100;     // [steps]
  // each scene version imported once (a seek then builds only the engine)
  std::map<uint32_t, std::shared_ptr<const sgal::Scene>> imported_;
  KeyframeHook keyframe_hook_;
};

}  // namespace caliper::simulation
