#include "csv_recording.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace caliper::ctl {

namespace {

std::string UnitSuffix(const std::string& unit) { return " [" + (unit.empty() ? "-" : unit) + "]"; }

}  // namespace

std::string CsvHeader(const std::vector<RecordedChannel>& channels) {
  std::string header = "time [s]";
  for (const auto& c : channels) {
    const std::string unit = UnitSuffix(c.unit);
    if (c.rows == 1 && c.cols == 1) {
      header += "," + c.id + unit;
    } else if (c.rows == 1 || c.cols == 1) {
      for (uint32_t i = 0; i < c.rows * c.cols; ++i)
        header += "," + c.id + "[" + std::to_string(i) + "]" + unit;
    } else {
      for (uint32_t r = 0; r < c.rows; ++r)
        for (uint32_t k = 0; k < c.cols; ++k)
          header += "," + c.id + "[" + std::to_string(r) + "][" + std::to_string(k) + "]" + unit;
    }
  }
  return header;
}

CsvRecording::CsvRecording(std::ostream& out, std::vector<RecordedChannel> channels,
                           double end_time)
    : out_(out), channels_(std::move(channels)), end_time_(end_time) {
  for (const auto& c : channels_) width_ += static_cast<size_t>(c.rows) * c.cols;
  out_ << CsvHeader(channels_) << "\n";
}

void CsvRecording::NoteGap(uint64_t first, uint64_t last) {
  missing_ += last - first + 1;
  if (!gaps_.empty()) gaps_ += ", ";
  gaps_ +=
      first == last ? std::to_string(first) : std::to_string(first) + "-" + std::to_string(last);
}

bool CsvRecording::Add(uint64_t batch, const double* times, size_t count, const double* data,
                       size_t values_per_sample) {
  if (done_) return true;
  if (values_per_sample != width_) {
    error_ = "a batch holds " + std::to_string(values_per_sample) + " values per sample, " +
             std::to_string(width_) + " expected (was the scene reloaded?)";
    done_ = true;
    return true;
  }
  if (batch > next_batch_) NoteGap(next_batch_, batch - 1);
  if (batch >= next_batch_) next_batch_ = batch + 1;
  // times within a part per billion of the end count as reaching it (sums of time steps)
  const double tolerance = 1e-9 * std::max(1.0, std::abs(end_time_));
  std::ostringstream rows;
  // the shortest text that reads back as the same double: files compare bit for bit
  auto put = [&rows](double v) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, v).ptr;
    rows.write(text, end - text);
  };
  for (size_t i = 0; i < count; ++i) {
    const double t = times[i];
    if (!std::isnan(last_time_) && t <= last_time_) {
      std::ostringstream why;
      why << "the simulated time went back from " << last_time_ << " s to " << t
          << " s (reset, stop or load): the recording ends there";
      error_ = why.str();
      done_ = true;
      break;
    }
    if (t > end_time_ + tolerance) {
      done_ = true;
      break;
    }
    put(t);
    for (size_t k = 0; k < width_; ++k) {
      rows << ",";
      put(data[i * width_ + k]);
    }
    rows << "\n";
    if (std::isnan(first_time_)) first_time_ = t;
    last_time_ = t;
    ++samples_;
    if (t >= end_time_ - tolerance) {
      done_ = true;
      break;
    }
  }
  out_ << rows.str();
  return done_;
}

}  // namespace caliper::ctl
