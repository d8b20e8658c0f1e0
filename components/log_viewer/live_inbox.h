#pragma once
// The Log Viewer's inbox of live records: what the listener is pushed and what the queries answer,
// merged in session order without repeats (by the logger's serial), across registrations and
// logger restarts. No Qt, no CORBA.

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/logging/record.h"

namespace caliper::log_viewer {

/// A record as the Logging component stored it.
struct LiveRecord {
  uint64_t serial = 0;  ///< 1-based position in the logger's session
  logging::Record record;
};

/// Where the listener servant and the worker's queries put records; shared with the servant so
/// that a call still in flight after the LogLink is gone finds it alive.
class LiveInbox {
 public:
  /// A new registration with a logger whose session log is `session_file`: records are buffered
  /// until Synced(). A different session file than before starts the serials afresh.
  void BeginSync(const std::string& session_file);
  /// The answer to the query made after registering: taken with everything buffered meanwhile.
  void Synced(std::vector<LiveRecord> records);
  /// Records pushed by the logger (from an ORB thread).
  void Push(std::vector<LiveRecord> records);
  /// Records are no longer accepted (the listener is unregistered or the logger is gone).
  void Stop();
  /// Serial of the last record taken in; queries ask for what comes after it.
  uint64_t last_serial() const;
  /// The records taken in since the last call.
  std::vector<logging::Record> Take();

 private:
  void AcceptLocked(std::vector<LiveRecord>& records);

  mutable std::mutex mutex_;
  enum class State { kStopped, kSyncing, kLive } state_ = State::kStopped;
  std::string session_file_;
  uint64_t last_serial_ = 0;
  std::vector<LiveRecord> buffer_;        ///< pushed while syncing
  std::vector<logging::Record> pending_;  ///< for the GUI
};

}  // namespace caliper::log_viewer
