#pragma once
// Which (source, seq) pairs the logger has stored, for duplicate suppression. Both come from the
// client, so a record that names another process's source must not silence that process: a seq is
// a duplicate only when that very seq was stored, never because a larger one was. Memory is
// bounded: per source the stored seqs are kept as ranges (a process numbering 1, 2, 3, ... needs
// one), at most kMaxRanges of them; at most kMaxSources sources, the least recently stored
// forgotten first. What is forgotten can be stored twice, nothing is ever refused for it.

#include <cstddef>
#include <cstdint>
#include <list>
#include <map>
#include <string>
#include <unordered_map>

namespace caliper::logger {

class SeenSequences {
 public:
  /// Sources remembered; a new source beyond this forgets the one stored longest ago.
  static constexpr size_t kMaxSources = 4096;
  /// Disjoint ranges of seqs remembered per source; a new range beyond this forgets the smallest
  /// other one (a forged stray seq, rather than the range of a process's genuine records).
  static constexpr size_t kMaxRanges = 64;

  explicit SeenSequences(size_t max_sources = kMaxSources, size_t max_ranges = kMaxRanges);

  /// Whether `seq` of `source` was inserted (and not forgotten since).
  bool Contains(const std::string& source, uint64_t seq) const;
  /// Remembers `seq` of `source`.
  void Insert(const std::string& source, uint64_t seq);

  size_t sources() const { return sources_.size(); }
  /// How many disjoint ranges `source` has (0 for an unknown source).
  size_t ranges(const std::string& source) const;

 private:
  struct Source {
    std::map<uint64_t, uint64_t> ranges;  ///< first seq -> last seq, disjoint, not adjacent
    std::list<std::string>::iterator recency;
  };
  void ForgetSmallestRangeBut(Source* source, uint64_t keep_first);

  size_t max_sources_;
  size_t max_ranges_;
  std::unordered_map<std::string, Source> sources_;
  std::list<std::string> recency_;  ///< sources, most recently inserted first
};

}  // namespace caliper::logger
