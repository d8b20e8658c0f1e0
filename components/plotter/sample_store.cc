#include "sample_store.h"

#include <cmath>
#include <stdexcept>

namespace caliper::plotter {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

KeyParts SplitKey(const std::string& key) {
  KeyParts parts;
  size_t end = key.size();
  std::vector<unsigned> reversed;
  // peel `[digits]` groups off the end, at most two
  while (reversed.size() < 2 && end >= 3 && key[end - 1] == ']') {
    const size_t open = key.rfind('[', end - 1);
    if (open == std::string::npos || open + 1 == end - 1 || open == 0) break;
    unsigned long index = 0;
    bool digits = true;
    for (size_t k = open + 1; k < end - 1; ++k) {
      if (key[k] < '0' || key[k] > '9' || index > 100'000'000) {
        digits = false;
        break;
      }
      index = index * 10 + static_cast<unsigned>(key[k] - '0');
    }
    if (!digits) break;
    reversed.push_back(static_cast<unsigned>(index));
    end = open;
  }
  parts.id = key.substr(0, end);
  parts.indices.assign(reversed.rbegin(), reversed.rend());
  return parts;
}

long ElementOffset(const KeyParts& key, unsigned rows, unsigned cols) {
  const unsigned long size = static_cast<unsigned long>(rows) * cols;
  if (size == 0) return -1;
  if (key.indices.empty()) return size == 1 ? 0 : -1;
  if (key.indices.size() == 1) {
    // a vector (either orientation) by one index; a matrix needs two
    if (rows != 1 && cols != 1) return -1;
    return key.indices[0] < size ? static_cast<long>(key.indices[0]) : -1;
  }
  if (key.indices[0] >= rows || key.indices[1] >= cols) return -1;
  return static_cast<long>(key.indices[0] * cols + key.indices[1]);
}

SampleStore::SampleStore(size_t capacity) : capacity_(capacity) {
  if (capacity == 0) throw std::invalid_argument("the buffer needs room for at least one sample");
}

void SampleStore::SetCapacity(size_t samples) {
  if (samples == 0) throw std::invalid_argument("the buffer needs room for at least one sample");
  if (samples == capacity_) return;
  // copy the newest samples out in time order
  const size_t keep = std::min(size_, samples);
  const size_t first = size_ - keep;
  // room for the whole new capacity at once: the buffer never moves while it fills
  const size_t room = keep > 0 ? samples : 0;
  std::vector<double> times;
  times.reserve(room);
  for (size_t i = first; i < size_; ++i) times.push_back(time(i));
  std::vector<std::vector<double>> values(values_.size());
  for (size_t s = 0; s < values_.size(); ++s) {
    values[s].reserve(room);
    for (size_t i = first; i < size_; ++i) values[s].push_back(value(s, i));
  }
  overwritten_ += first;
  times_ = std::move(times);
  values_ = std::move(values);
  capacity_ = samples;
  head_ = 0;
  size_ = keep;
  ++version_;
}

size_t SampleStore::AddSeries(const std::string& key, const std::string& unit) {
  const long found = Find(key);
  if (found >= 0) {
    if (!unit.empty()) SetUnit(static_cast<size_t>(found), unit);
    return static_cast<size_t>(found);
  }
  series_.push_back(SeriesInfo{key, unit, false});
  std::vector<double> values;
  values.reserve(times_.capacity());  // as much room as the time line
  values.assign(times_.size(), kNaN);
  values_.push_back(std::move(values));
  ++version_;
  return series_.size() - 1;
}

bool SampleStore::RemoveSeries(const std::string& key) {
  const long found = Find(key);
  if (found < 0) return false;
  series_.erase(series_.begin() + found);
  values_.erase(values_.begin() + found);
  ++version_;
  return true;
}

long SampleStore::Find(const std::string& key) const {
  for (size_t s = 0; s < series_.size(); ++s)
    if (series_[s].key == key) return static_cast<long>(s);
  return -1;
}

void SampleStore::SetUnit(size_t index, const std::string& unit) {
  SeriesInfo& info = series_.at(index);
  if (info.unit == unit) return;
  info.unit = unit;
  ++version_;
}

void SampleStore::SetStale(size_t index, bool stale) {
  SeriesInfo& info = series_.at(index);
  if (info.stale == stale) return;
  info.stale = stale;
  ++version_;
}

void SampleStore::PushBack(double t, const double* values_per_series) {
  if (times_.size() < capacity_) {
    // still growing: append at the end (head_ stays 0), into room for the whole capacity that
    // the first sample reserves (address space: pages are taken as samples are written), so that
    // no append ever copies the history
    if (times_.size() == times_.capacity()) Reserve();
    times_.push_back(t);
    for (size_t s = 0; s < values_.size(); ++s) values_[s].push_back(values_per_series[s]);
    ++size_;
    return;
  }
  if (size_ < capacity_) {
    // room after a Clear: physical storage exists, write behind the newest
    const size_t p = Physical(size_);
    times_[p] = t;
    for (size_t s = 0; s < values_.size(); ++s) values_[s][p] = values_per_series[s];
    ++size_;
    return;
  }
  // full: overwrite the oldest
  times_[head_] = t;
  for (size_t s = 0; s < values_.size(); ++s) values_[s][head_] = values_per_series[s];
  head_ = head_ + 1 == capacity_ ? 0 : head_ + 1;
  ++overwritten_;
}

void SampleStore::Reserve() {
  times_.reserve(capacity_);
  for (auto& v : values_) v.reserve(capacity_);
}

SampleStore::AppendResult SampleStore::Append(const double* times, size_t count, const double* data,
                                              size_t values_per_sample,
                                              const std::vector<Column>& columns) {
  for (const Column& c : columns) {
    if (c.series >= series_.size())
      throw std::invalid_argument("no series " + std::to_string(c.series) + " (there are " +
                                  std::to_string(series_.size()) + ")");
    if (c.offset >= values_per_sample)
      throw std::invalid_argument("value " + std::to_string(c.offset) + " is outside a sample of " +
                                  std::to_string(values_per_sample) + " values");
  }
  AppendResult result;
  std::vector<double> row(series_.size(), kNaN);
  for (size_t i = 0; i < count; ++i) {
    const double t = times[i];
    if (std::isnan(t)) continue;
    if (size_ > 0) {
      const double last = last_time();
      if (t == last) {
        ++result.duplicates;
        continue;
      }
      if (t < last) {
        Clear();
        ++rewinds_;
        result.rewound = true;
      }
    }
    for (const Column& c : columns) row[c.series] = data[i * values_per_sample + c.offset];
    PushBack(t, row.data());
    ++result.appended;
  }
  appended_ += result.appended;
  if (result.appended > 0 || result.rewound) ++version_;
  return result;
}

void SampleStore::Clear() {
  if (size_ == 0) return;
  if (times_.size() < capacity_) {
    // still growing: start over at the front
    times_.clear();
    for (auto& v : values_) v.clear();
    head_ = 0;
  }
  // a full buffer keeps its storage; the ring restarts at the current head
  size_ = 0;
  ++version_;
}

double SampleStore::first_time() const { return size_ == 0 ? kNaN : time(0); }

double SampleStore::last_time() const { return size_ == 0 ? kNaN : time(size_ - 1); }

std::pair<size_t, size_t> SampleStore::IndexRange(double t0, double t1) const {
  if (size_ == 0 || !(t0 <= t1)) return {0, 0};
  // binary searches over logical indices: first time >= t0, first time > t1
  auto lower = [&](double t, bool inclusive) {
    size_t lo = 0, hi = size_;
    while (lo < hi) {
      const size_t mid = lo + (hi - lo) / 2;
      const double v = time(mid);
      if (inclusive ? v < t : v <= t)
        lo = mid + 1;
      else
        hi = mid;
    }
    return lo;
  };
  const size_t first = lower(t0, true);
  const size_t last = lower(t1, false);
  return {first, std::max(first, last)};
}

}  // namespace caliper::plotter
