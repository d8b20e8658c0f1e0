#pragma once
// The Log Viewer's records: everything received or read so far, in arrival order, with each
// record's category and component interned (so that filters decide once per distinct name), and
// records seen before (same source and seq) dropped. No Qt, no CORBA.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <unordered_map>
#include <vector>

#include "caliper/logging/record.h"

namespace caliper::log_viewer {

/// One record as the viewer keeps it.
struct Entry {
  logging::Record record;
  uint32_t category = 0;   ///< index into RecordStore::categories()
  uint32_t component = 0;  ///< index into RecordStore::components()
};

/// The records of one viewer, oldest first.
class RecordStore {
 public:
  /// Appends the records not seen before, keeping their order; returns how many were appended.
  /// A record is a duplicate when its source already delivered a seq at least as high (the
  /// Logging component's rule); records with seq 0 are never duplicates.
  size_t Append(std::vector<logging::Record> records);

  /// Forgets every record, category and component.
  void Clear();

  /// Drops the oldest `n` records (to bound memory); categories and components stay known.
  void DropOldest(size_t n);

  size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  /// The `i`-th record, oldest first.
  const Entry& entry(size_t i) const { return entries_[i]; }
  const logging::Record& record(size_t i) const { return entries_[i].record; }

  /// Distinct categories in the order they were first seen; an Entry's `category` indexes it.
  const std::vector<std::string>& categories() const { return categories_; }
  /// Distinct component instances in the order they were first seen.
  const std::vector<std::string>& components() const { return components_; }

 private:
  static uint32_t Intern(const std::string& name, std::vector<std::string>* names,
                         std::unordered_map<std::string, uint32_t>* ids);

  std::deque<Entry> entries_;
  std::vector<std::string> categories_;
  std::unordered_map<std::string, uint32_t> category_ids_;
  std::vector<std::string> components_;
  std::unordered_map<std::string, uint32_t> component_ids_;
  std::unordered_map<std::string, uint64_t> last_seq_;  ///< per source
};

}  // namespace caliper::log_viewer
