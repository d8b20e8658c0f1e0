#pragma once
// The Log Viewer's inbox of live records: what the listener is pushed and what the queries answer,
// merged in session order without repeats (by the logger's serial), across registrations and
// logger restarts. A jump in the serials (the logger drops the oldest records of a listener that
// falls 100,000 behind) holds the records after it back until a query fills the gap, so that the
// records come out complete and in order. No Qt, no CORBA.

#include <cstdint>
#include <functional>
#include <map>
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
  /// The answer to the query for what follows last_serial(), made after registering: taken with
  /// everything buffered meanwhile. Serials missing before its first record are no longer held
  /// by the logger: they are skipped (and counted in lost() unless this is the session's start).
  void Synced(std::vector<LiveRecord> records);
  /// Records pushed by the logger (from an ORB thread). Records after missing serials are held
  /// back; the gap callback is called (outside the inbox's lock) when such a gap opens.
  void Push(std::vector<LiveRecord> records);
  /// Whether records are held back behind missing serials: the worker then queries everything
  /// after last_serial() and hands the answer to GapAnswered().
  bool gap_pending() const;
  /// The answer to the query for what follows `after_serial`, made because of a gap: fills it.
  /// Serials missing before the answer's first record are no longer held by the logger: they are
  /// skipped and counted in lost(). Ignored unless live and `after_serial` is still last_serial().
  void GapAnswered(uint64_t after_serial, std::vector<LiveRecord> records);
  /// Records are no longer accepted (the listener is unregistered or the logger is gone); those
  /// held back are forgotten (the next registration's query asks for them again).
  void Stop();
  /// Serial of the last record taken in (every record up to it was taken in or is lost);
  /// queries ask for what comes after it.
  uint64_t last_serial() const;
  /// Records of this session that the logger no longer held when a gap was queried.
  uint64_t lost() const;
  /// The records taken in since the last call, in session order.
  std::vector<logging::Record> Take();
  /// Called when a gap opens (the worker wakes up to query it); set before records arrive.
  void set_on_gap(std::function<void()> on_gap) { on_gap_ = std::move(on_gap); }

 private:
  void HoldLocked(std::vector<LiveRecord>& records);
  void FlushLocked();
  void SkipMissingLocked();

  mutable std::mutex mutex_;
  enum class State { kStopped, kSyncing, kLive } state_ = State::kStopped;
  std::string session_file_;
  uint64_t last_serial_ = 0;
  uint64_t lost_ = 0;
  std::vector<LiveRecord> buffer_;            ///< pushed while syncing
  std::map<uint64_t, logging::Record> held_;  ///< serial -> record, after a gap
  std::vector<logging::Record> pending_;      ///< for the GUI
  std::function<void()> on_gap_;
};

}  // namespace caliper::log_viewer
