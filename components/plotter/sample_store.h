#pragma once
// The Graph Plotter's data: one time line of samples and a value column per plotted quantity
// (series), held in ring buffers of a fixed capacity (the oldest sample goes when a new one comes
// to a full buffer). The GUI appends the DAQ batches it receives and only reads it otherwise. No
// Qt, no CORBA.
//
// A series is an id of the Model's data acquisition (`pendulum_tendon.pivot.position`) or one
// element of a vector or matrix id (`pendulum_tendon.pendulum.position[2]`,
// `pendulum_tendon.frame.rotation[0][1]`): its key. Series added later hold NaN for the samples
// taken before; a stale series (its id vanished from the Model) gets NaN from then on.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace caliper::plotter {

/// The parts of a series key: `a.b[2]` is id `a.b` with indices {2}; `a.b[1][0]` has {1, 0}.
struct KeyParts {
  std::string id;  ///< the DAQ id
  std::vector<unsigned>
      indices;  ///< none for the whole (scalar) id, one for a vector, two for a matrix
};

/// Splits a key into its id and element indices (a malformed suffix stays part of the id).
KeyParts SplitKey(const std::string& key);

/// Where the element a key names sits within a `rows` x `cols` value (row-major); -1 when the
/// key does not fit the shape (e.g. no index for a vector, an index out of range).
long ElementOffset(const KeyParts& key, unsigned rows, unsigned cols);

/// One plotted quantity.
struct SeriesInfo {
  std::string key;     ///< e.g. pendulum_tendon.pivot.position
  std::string unit;    ///< SI unit, "" for none (or unknown)
  bool stale = false;  ///< the Model no longer has the id: no new values arrive
};

/// Time line and value columns in ring buffers.
class SampleStore {
 public:
  /// Samples kept per series by default (about 17 min at 1 kHz; 8 MB per series).
  static constexpr size_t kDefaultCapacity = 1'000'000;

  /// Where a series' value sits within one sample of a batch.
  struct Column {
    size_t series = 0;  ///< index of the series
    size_t offset = 0;  ///< index of its value within a sample
  };

  /// What one Append did.
  struct AppendResult {
    size_t appended = 0;    ///< samples added
    size_t duplicates = 0;  ///< samples skipped: their time equals the last one held
    bool rewound = false;   ///< a time went back (reset, reload, a new Model): the samples
                            ///< held before were dropped and the buffer started anew
  };

  /// Throws std::invalid_argument for a zero capacity.
  explicit SampleStore(size_t capacity = kDefaultCapacity);

  /// Samples kept per series.
  size_t capacity() const { return capacity_; }
  /// Changes the capacity, keeping the newest samples. Throws std::invalid_argument for zero.
  void SetCapacity(size_t samples);

  /// Adds a series (NaN for the samples held now) and returns its index; an existing key returns
  /// its index (and takes `unit` when that is not empty).
  size_t AddSeries(const std::string& key, const std::string& unit = "");
  /// Removes a series and its values; indices of later series move down by one. False when the
  /// key is unknown.
  bool RemoveSeries(const std::string& key);
  /// The index of a series, or -1.
  long Find(const std::string& key) const;
  /// Number of series.
  size_t series_count() const { return series_.size(); }
  /// A series' key, unit and stale mark; throws std::out_of_range.
  const SeriesInfo& series(size_t index) const { return series_.at(index); }
  /// Sets a series' unit; throws std::out_of_range.
  void SetUnit(size_t index, const std::string& unit);
  /// Marks a series stale (its id vanished from the Model) or live again; throws std::out_of_range.
  void SetStale(size_t index, bool stale);

  /// Appends `count` samples taken at `times` [s] (ascending); sample i holds
  /// `values_per_sample` values at data[i * values_per_sample ...], of which `columns` say which
  /// belong to which series. Series without a column get NaN. A time equal to the last one held
  /// is a duplicate and skipped; an earlier time starts the buffer anew (see AppendResult).
  /// Throws std::invalid_argument for a column outside the sample or an unknown series.
  AppendResult Append(const double* times, size_t count, const double* data,
                      size_t values_per_sample, const std::vector<Column>& columns);

  /// Drops every sample; the series stay.
  void Clear();

  /// Samples held, at most capacity().
  size_t size() const { return size_; }
  /// No sample held.
  bool empty() const { return size_ == 0; }
  /// Time of sample `i` (0 is the oldest held) [s].
  double time(size_t i) const { return times_[Physical(i)]; }
  /// Value of series `s` at sample `i` (NaN where it has none).
  double value(size_t s, size_t i) const { return values_[s][Physical(i)]; }
  /// Oldest and newest time held [s]; NaN when empty.
  double first_time() const;
  double last_time() const;
  /// The samples with `t0 <= time <= t1`: indices [first, last) (first == last when none).
  std::pair<size_t, size_t> IndexRange(double t0, double t1) const;

  /// Calls f(time, value) for series `s` over samples [first, last), oldest first, without the
  /// index arithmetic of time()/value() per sample.
  template <typename F>
  void ForEach(size_t s, size_t first, size_t last, F&& f) const;

  /// Changes whenever samples, series or their state change (to redraw only then).
  uint64_t version() const { return version_; }
  /// Samples appended since construction (also those overwritten or cleared since).
  uint64_t samples_appended() const { return appended_; }
  /// Samples that left a full buffer to make room for new ones.
  uint64_t samples_overwritten() const { return overwritten_; }
  /// Times the buffer started anew because the simulated time went back.
  uint64_t rewinds() const { return rewinds_; }

 private:
  size_t Physical(size_t i) const {
    const size_t p = head_ + i;
    return p < capacity_ ? p : p - capacity_;
  }
  void PushBack(double t, const double* values_per_series);
  void Reserve();

  size_t capacity_;
  size_t head_ = 0;  // physical index of the oldest sample (0 until the buffer is full)
  size_t size_ = 0;
  std::vector<double> times_;  // [s], physical order; grows up to capacity_ (reserved at once)
  std::vector<std::vector<double>> values_;  // per series, same physical order as times_
  std::vector<SeriesInfo> series_;
  uint64_t version_ = 0;
  uint64_t appended_ = 0;
  uint64_t overwritten_ = 0;
  uint64_t rewinds_ = 0;
};

template <typename F>
void SampleStore::ForEach(size_t s, size_t first, size_t last, F&& f) const {
  if (first >= last) return;
  const double* t = times_.data();
  const double* v = values_[s].data();
  // at most two contiguous runs of the ring
  size_t p = Physical(first);
  size_t n = last - first;
  while (n > 0) {
    const size_t run = std::min(n, capacity_ - p);
    const size_t end = p + run;
    for (size_t k = p; k < end; ++k) f(t[k], v[k]);
    n -= run;
    p = 0;
  }
}

}  // namespace caliper::plotter
