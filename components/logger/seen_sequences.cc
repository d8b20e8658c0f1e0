#include "seen_sequences.h"

#include <iterator>

namespace caliper::logger {

SeenSequences::SeenSequences(size_t max_sources, size_t max_ranges)
    : max_sources_(max_sources < 1 ? 1 : max_sources),
      max_ranges_(max_ranges < 1 ? 1 : max_ranges) {}

bool SeenSequences::Contains(const std::string& source, uint64_t seq) const {
  const auto s = sources_.find(source);
  if (s == sources_.end()) return false;
  const auto& ranges = s->second.ranges;
  // the last range starting at or before seq
  auto it = ranges.upper_bound(seq);
  if (it == ranges.begin()) return false;
  --it;
  return seq <= it->second;
}

size_t SeenSequences::ranges(const std::string& source) const {
  const auto s = sources_.find(source);
  return s == sources_.end() ? 0 : s->second.ranges.size();
}

void SeenSequences::Insert(const std::string& source, uint64_t seq) {
  auto found = sources_.find(source);
  if (found == sources_.end()) {
    if (sources_.size() >= max_sources_) {
      sources_.erase(recency_.back());
      recency_.pop_back();
    }
    recency_.push_front(source);
    found = sources_.emplace(source, Source{{}, recency_.begin()}).first;
  } else {
    recency_.splice(recency_.begin(), recency_, found->second.recency);
  }
  Source& s = found->second;
  auto& ranges = s.ranges;

  // the range starting after seq, and the one before it
  auto next = ranges.upper_bound(seq);
  auto prev = next == ranges.begin() ? ranges.end() : std::prev(next);
  if (prev != ranges.end() && seq <= prev->second) return;  // already in
  const bool joins_prev = prev != ranges.end() && prev->second + 1 == seq;
  const bool joins_next = next != ranges.end() && seq + 1 == next->first;
  uint64_t first = seq;
  if (joins_prev && joins_next) {
    prev->second = next->second;
    ranges.erase(next);
    first = prev->first;
  } else if (joins_prev) {
    prev->second = seq;
    first = prev->first;
  } else if (joins_next) {
    const uint64_t last = next->second;
    ranges.erase(next);
    ranges.emplace(seq, last);
  } else {
    ranges.emplace(seq, seq);
  }
  if (ranges.size() > max_ranges_) ForgetSmallestRangeBut(&s, first);
}

void SeenSequences::ForgetSmallestRangeBut(Source* source, uint64_t keep_first) {
  auto& ranges = source->ranges;
  auto smallest = ranges.end();
  for (auto it = ranges.begin(); it != ranges.end(); ++it) {
    if (it->first == keep_first) continue;
    // the fewest seqs; among equals the lowest (the oldest for a process counting up)
    if (smallest == ranges.end() || it->second - it->first < smallest->second - smallest->first)
      smallest = it;
  }
  if (smallest != ranges.end()) ranges.erase(smallest);
}

}  // namespace caliper::logger
