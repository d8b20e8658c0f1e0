#pragma once
// The Logging component's data: one file per session, the recent records in memory, duplicate
// suppression by (source, seq), and queries. No CORBA here.
//
// Everything in a record comes from a client, so the store bounds what one client can cost the
// others: a message is kept to kMaxMessageBytes (the rest cut, with a marker saying how much), the
// other text fields to kMaxFieldBytes; a forged (source, seq) suppresses only that exact seq
// (SeenSequences); a query compiles its regular expression with logging::MessagePattern (RE2,
// linear time), matches without holding the store's lock, and returns at most kMaxQueryRecords.

#include <cstdint>
#include <deque>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/logging/record.h"
#include "seen_sequences.h"

namespace caliper::logger {

/// Longest message stored [bytes]; a longer one is cut and ends with TruncationMarker.
constexpr size_t kMaxMessageBytes = 16 * 1024;
/// Longest category, component, host or source stored [bytes]; cut the same way.
constexpr size_t kMaxFieldBytes = 256;
/// Most records one query returns (the newest matches); a filter's `limit` of 0 or more means this.
constexpr uint32_t kMaxQueryRecords = 10000;

/// What ends a text that was cut: "… [truncated N bytes]".
std::string TruncationMarker(size_t cut_bytes);

/// `text` if it has at most `max_bytes`, else its start (never half a UTF-8 character) followed
/// by TruncationMarker, at most `max_bytes` in all.
std::string Truncate(const std::string& text, size_t max_bytes);

struct StoredRecord {
  uint64_t serial = 0;  ///< 1-based position in the session
  logging::Record record;
};

struct QueryFilter {
  int max_priority = logging::kDebug;  ///< keep records at least this severe
  std::string category_prefix;
  std::string component;
  std::string regex;         ///< RE2 syntax, searched in the message; "" for all
  int64_t from_time_us = 0;  ///< 0: no bound
  int64_t to_time_us = 0;    ///< 0: no bound
  uint64_t after_serial = 0;
  uint32_t limit = 0;  ///< newest `limit` matches; 0: kMaxQueryRecords
};

class LogStore {
 public:
  /// Opens `<directory>/caliper-YYYYmmdd-HHMMSS-<session>.log`, reusing an existing file of the
  /// same session (a restarted logger goes on with it: its records are read back so that
  /// duplicates are still recognised). Throws std::runtime_error when the file cannot be opened.
  /// Memory keeps the newest `memory_records` records, and at most about `memory_bytes` of them
  /// (the file keeps all).
  LogStore(const std::string& directory, const std::string& session, size_t memory_records,
           size_t memory_bytes = kDefaultMemoryBytes);
  static constexpr size_t kDefaultMemoryBytes = size_t{256} << 20;

  /// Appends the records not stored before, in the given order, their texts bounded (see
  /// Truncate); returns the newly stored ones.
  std::vector<StoredRecord> Submit(const std::vector<logging::Record>& records);

  /// The newest matching records from memory (at most the filter's limit, at most
  /// kMaxQueryRecords), oldest first. Throws logging::PatternError for a regular expression RE2
  /// refuses or one longer than logging::kMaxPatternBytes. The store's lock is held only while the
  /// candidates are picked, never while the regular expression runs.
  std::vector<StoredRecord> Query(const QueryFilter& filter) const;

  /// Called by Query between releasing the lock and matching (tests show with it that records
  /// can be submitted while a query matches).
  void set_before_match(std::function<void()> hook) { before_match_ = std::move(hook); }

  const std::string& path() const { return path_; }
  uint64_t size() const;

 private:
  void Recover();
  /// Keeps `record` for queries, dropping the oldest beyond the bounds.
  void Remember(std::shared_ptr<const StoredRecord> record);

  std::string path_;
  size_t memory_records_;
  size_t memory_bytes_;
  size_t recent_bytes_ = 0;  ///< BytesOf every record in recent_
  mutable std::mutex mutex_;
  std::ofstream file_;
  /// shared with the queries that copied them: a query holds the lock only to copy pointers
  std::deque<std::shared_ptr<const StoredRecord>> recent_;
  SeenSequences seen_;
  uint64_t serial_ = 0;
  std::function<void()> before_match_;
};

/// The session file name for a session started at `time_us`.
std::string SessionFileName(const std::string& session, int64_t time_us);

}  // namespace caliper::logger
