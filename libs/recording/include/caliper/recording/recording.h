#pragma once
// A session recording: one SQLite file (write-ahead log) holding the scene's bytes, full-state
// keyframes, every command and parameter write with the step at which it took effect, the log
// records and optionally chosen channels. Written from the simulation thread through a queue and
// committed by a writer thread at least every 0.5 s, so a killed Model loses at most that; read
// back for replay, verification, forks and CSV export. No CORBA here. The schema is in
// docs/recording.md ("The file").

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/sgal/physics_scene.h"

namespace caliper::recording {

/// A file that cannot be written or read as a recording: the message names the file and why.
/// Recordings are `.caliper` files (the Main Window's dialogs and the docs look for them).
inline constexpr const char* kExtension = ".caliper";

/// `path` with `.caliper` added when its file name has no extension; any other is kept.
std::string WithExtension(const std::string& path);

class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Channel {
  std::string id;
  std::string unit;
  uint32_t rows = 1, cols = 1;
};

/// What a recording holds about itself.
struct Header {
  std::string model_name;         // the Model's scene name (ids start with it)
  std::string scene_file_name;    // e.g. ecce_arm.dae: the format of scene version 0's bytes
  double time_step = 0;           // [s]
  uint32_t keyframe_every = 100;  // steps between keyframes
  uint32_t channels_every = 1;    // steps between channel samples (0: no channels)
  std::vector<Channel> channels;  // sampled, in this order
  uint64_t first_step = 0;        // the step the recording started at
  std::string engine;             // the engine that ran it (e.g. "bullet 3.24 float"): a replay
                                  // is exact only with the same ("" = not said)
};

/// An event that changed the simulation, taking effect before step `step` + 1 (after `step`
/// steps): kind "command" (target actuator, values {value}), "parameter" (target id, values),
/// "pull" (target body, values {px py pz tx ty tz stiffness} body frame / world [m], [N/m]),
/// "release" (no target), "edit" (target: the edit's description; the new scene is a scene
/// version at the same step, followed by a keyframe).
struct Event {
  uint64_t step = 0;
  std::string kind;
  std::string target;
  std::vector<double> values;
};

struct Keyframe {
  uint64_t step = 0;
  double time = 0;             // [s]
  uint32_t scene_version = 0;  // the scene it belongs to
  sgal::DynamicState state;
};

struct SceneVersion {
  uint32_t version = 0;
  uint64_t step = 0;           // from this step on
  std::string file_name;       // e.g. ecce_arm.dae
  std::string bytes;           // the scene file's content (COLLADA)
};

struct LogRecord {
  double time = 0;             // [s] of wall time since the epoch
  std::string priority, category, component, message;
};

struct Sample {
  uint64_t step = 0;
  double time = 0;             // [s] simulated
  std::vector<double> values;  // the channels' values, in Header::channels order, row-major
};

/// Bytes of a DynamicState and back (little-endian doubles with counts); throws RecordingError
/// for bytes that are not one.
std::string EncodeState(const sgal::DynamicState& state);
sgal::DynamicState DecodeState(const std::string& bytes);

/// Writes a recording. Calls come from the simulation thread and only queue (no disk I/O, no
/// lock held long); a writer thread commits a transaction at least every `commit_every`. A write
/// that fails (disk full, file gone) stops the recording: error() says why, later calls do
/// nothing, and the caller's simulation goes on.
class Writer {
 public:
  /// Creates `path` (refusing an existing file: RecordingError) with the header and scene
  /// version 0. `max_bytes` > 0 stops the recording, as a full disk does, when the file would
  /// grow beyond it.
  Writer(const std::string& path, const Header& header, const SceneVersion& scene,
         std::chrono::milliseconds commit_every = std::chrono::milliseconds(500),
         uint64_t max_bytes = 0);
  ~Writer();  // commits what is queued and closes
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  void AddKeyframe(const Keyframe& keyframe);
  void AddEvent(const Event& event);
  void AddScene(const SceneVersion& scene);
  void AddSample(Sample sample);
  void AddLog(const LogRecord& record);
  /// Commits everything queued now and waits for it (stop, tests).
  void Flush();
  /// "" while recording; otherwise why the recording stopped (e.g. "disk full: ...").
  std::string error() const;
  /// Whether the recording stopped (a failed write): cheap, no lock (for every step).
  bool stopped() const;
  const std::string& path() const;
  uint64_t bytes_written() const;  // the file's size at the last commit [bytes]

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a recording (read-only; a file a killed writer left is read up to its last commit).
class Reader {
 public:
  /// Throws RecordingError naming the file: missing, not SQLite, not a Caliper recording, or of
  /// a format version this build does not read.
  explicit Reader(const std::string& path);
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  const Header& header() const;
  uint64_t last_step() const;    // the last step recorded (keyframe, event or sample)
  double duration() const;       // [s] of simulated time from the first to the last step
  std::vector<SceneVersion> scenes() const;
  std::vector<uint64_t> keyframe_steps() const;
  /// The keyframe at or before `step` (RecordingError when there is none).
  Keyframe KeyframeAtOrBefore(uint64_t step) const;
  /// Events with first <= step < last, in the order they were recorded.
  std::vector<Event> Events(uint64_t first, uint64_t last) const;
  std::vector<Sample> Samples(uint64_t first, uint64_t last) const;
  std::vector<LogRecord> Log() const;
  /// Writes the channels as CSV: `time [s]` then one column per element with its unit
  /// (`arm.hand.position[0] [m]`); throws RecordingError when there are none.
  void ExportCsv(const std::string& csv_path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace caliper::recording
