#pragma once
// The Logging component's data: one file per session, the recent records in memory, duplicate
// suppression by (source, seq), and queries. No CORBA here.

#include <cstdint>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/logging/record.h"

namespace caliper::logger {

struct StoredRecord {
  uint64_t serial = 0;  ///< 1-based position in the session
  logging::Record record;
};

struct QueryFilter {
  int max_priority = logging::kDebug;  ///< keep records at least this severe
  std::string category_prefix;
  std::string component;
  std::string regex;                   ///< ECMAScript, on the message; "" for all
  int64_t from_time_us = 0;            ///< 0: no bound
  int64_t to_time_us = 0;              ///< 0: no bound
  uint64_t after_serial = 0;
  uint32_t limit = 0;                  ///< newest `limit` matches; 0: all
};

class LogStore {
 public:
  /// Opens `<directory>/caliper-YYYYmmdd-HHMMSS-<session>.log`, reusing an existing file of the
  /// same session (a restarted logger goes on with it: its records are read back so that
  /// duplicates are still recognised). Throws std::runtime_error when the file cannot be opened.
  LogStore(const std::string& directory, const std::string& session, size_t memory_records);

  /// Appends the records not stored before, in the given order; returns the newly stored ones.
  std::vector<StoredRecord> Submit(const std::vector<logging::Record>& records);

  /// Matching records from memory, oldest first. Throws std::regex_error on a bad expression.
  std::vector<StoredRecord> Query(const QueryFilter& filter) const;

  const std::string& path() const { return path_; }
  uint64_t size() const;

 private:
  void Recover();

  std::string path_;
  size_t memory_records_;
  mutable std::mutex mutex_;
  std::ofstream file_;
  std::deque<StoredRecord> recent_;
  std::map<std::string, uint64_t> last_seq_;  ///< per source
  uint64_t serial_ = 0;
};

/// The session file name for a session started at `time_us`.
std::string SessionFileName(const std::string& session, int64_t time_us);

}  // namespace caliper::logger
