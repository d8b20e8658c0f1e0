#pragma once
// The Log Viewer's records: everything received or read so far, in arrival order, with each
// record's category, component, host and source interned (kept once per distinct name, so that a
// million records fit in memory and filters decide once per name), and records seen before (same
// source and seq) dropped. No Qt, no CORBA.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <unordered_map>
#include <vector>

#include "caliper/logging/record.h"

namespace caliper::log_viewer {

/// One record as the viewer keeps it: the fields of a logging::Record, names as interned ids.
struct Entry {
  int64_t time_us = 0;  ///< wall-clock time of the event [us since 1970-01-01 UTC]
  uint64_t seq = 0;     ///< per source
  long pid = 0;
  std::string message;
  int priority = logging::kInfo;  ///< log4cpp priority
  uint32_t category = 0;          ///< index into RecordStore::categories()
  uint32_t component = 0;         ///< index into RecordStore::components()
  uint32_t host = 0;              ///< index into RecordStore::hosts()
  uint32_t source = 0;            ///< index into RecordStore::sources()
};

/// A list of distinct names, each with its index.
class NameTable {
 public:
  /// The index of `name`, added at the end when new.
  uint32_t Intern(const std::string& name);
  const std::vector<std::string>& names() const { return names_; }
  void Clear();

 private:
  std::vector<std::string> names_;
  std::unordered_map<std::string, uint32_t> ids_;
};

/// The records of one viewer, oldest first.
class RecordStore {
 public:
  /// Appends the records not seen before, keeping their order; returns how many were appended.
  /// A record is a duplicate when its source already delivered a seq at least as high (the
  /// Logging component's rule); records with seq 0 are never duplicates.
  size_t Append(std::vector<logging::Record> records);

  /// Forgets every record and name.
  void Clear();

  /// Drops the oldest `n` records (to bound memory); the names stay known.
  void DropOldest(size_t n);

  size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  /// The `i`-th record, oldest first.
  const Entry& entry(size_t i) const { return entries_[i]; }
  /// The `i`-th record as a logging::Record (its names copied).
  logging::Record record(size_t i) const;

  /// Distinct categories in the order they were first seen; an Entry's `category` indexes it.
  const std::vector<std::string>& categories() const { return categories_.names(); }
  /// Distinct component instances in the order they were first seen.
  const std::vector<std::string>& components() const { return components_.names(); }
  /// Distinct hosts and sources in the order they were first seen.
  const std::vector<std::string>& hosts() const { return hosts_.names(); }
  const std::vector<std::string>& sources() const { return sources_.names(); }

  /// An entry's names.
  const std::string& category(const Entry& e) const { return categories()[e.category]; }
  const std::string& component(const Entry& e) const { return components()[e.component]; }
  const std::string& host(const Entry& e) const { return hosts()[e.host]; }
  const std::string& source(const Entry& e) const { return sources()[e.source]; }

 private:
  std::deque<Entry> entries_;
  NameTable categories_;
  NameTable components_;
  NameTable hosts_;
  NameTable sources_;
  std::vector<uint64_t> last_seq_;  ///< per source id: the highest seq appended
};

}  // namespace caliper::log_viewer
