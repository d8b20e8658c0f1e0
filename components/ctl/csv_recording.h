#pragma once
// `caliper-ctl record`'s file: sample batches of a DAQ subscription written as CSV, one column per
// scalar element with its unit in the header, up to an end time; gaps in batch numbers counted.
// No CORBA: the verb's DataConsumer servant hands each batch over as plain arrays.

#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

namespace caliper::ctl {

/// What one recorded id contributes: rows x cols values (row-major) in `unit` ("" for none).
struct RecordedChannel {
  std::string id;
  std::string unit;
  uint32_t rows = 1;
  uint32_t cols = 1;
};

/// The CSV header for `channels`: `time [s],a.position[0] [m],a.position[1] [m],...`. A scalar
/// is `id [unit]`, a vector `id[i] [unit]`, a matrix `id[r][c] [unit]`; no unit is `[-]`.
std::string CsvHeader(const std::vector<RecordedChannel>& channels);

class CsvRecording {
 public:
  /// Writes the header to `out` at once. Samples later than `end_time` [s] are not written
  /// (infinity: until Close).
  CsvRecording(std::ostream& out, std::vector<RecordedChannel> channels,
               double end_time = std::numeric_limits<double>::infinity());

  /// One batch: `count` samples at `times`, each `values_per_sample` values of `data`. Writes the
  /// samples up to the end time and returns whether the recording is complete (a sample at or
  /// past the end time arrived). A batch whose layout does not match the channels, or whose
  /// times go back (the simulation was rewound), ends the recording with error() set.
  bool Add(uint64_t batch, const double* times, size_t count, const double* data,
           size_t values_per_sample);

  bool done() const { return done_; }
  /// Why the recording ended early ("" when it did not).
  const std::string& error() const { return error_; }
  uint64_t samples() const { return samples_; }
  double first_time() const { return first_time_; }  // [s]; NaN before the first sample
  double last_time() const { return last_time_; }    // [s]; NaN before the first sample
  size_t values_per_sample() const { return width_; }
  /// Batches that never arrived (numbers skipped between 1 and the last one received).
  uint64_t missing_batches() const { return missing_; }
  /// The skipped ranges, e.g. "5-7, 12".
  const std::string& gaps() const { return gaps_; }

 private:
  void NoteGap(uint64_t first, uint64_t last);

  std::ostream& out_;
  std::vector<RecordedChannel> channels_;
  size_t width_ = 0;
  double end_time_;
  bool done_ = false;
  std::string error_;
  uint64_t next_batch_ = 1;
  uint64_t samples_ = 0;
  uint64_t missing_ = 0;
  std::string gaps_;
  double first_time_ = std::numeric_limits<double>::quiet_NaN();
  double last_time_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace caliper::ctl
