#include "stream_watch.h"

#include <algorithm>
#include <cmath>

namespace caliper::plotter {

double QuietThreshold(double silence_s, uint32_t every_n_steps, double time_step) {
  const double interval = std::max<uint32_t>(1, every_n_steps) * std::max(0.0, time_step);
  return std::max(silence_s, 3 * interval + std::max(kModelBatchPeriod, interval));
}

void StreamWatch::Start(double sim_time, uint32_t every_n_steps, Clock::time_point now) {
  every_n_steps_ = every_n_steps;
  watch_time_ = sim_time;
  watch_wall_ = now;
  last_poll_ = now;
  quiet_for_ = 0;
}

bool StreamWatch::Quiet(bool running, double sim_time, double time_step, double last_sample,
                        Clock::time_point last_batch, Clock::time_point now) {
  // a sample newer than the last sign of life is one
  if (!std::isnan(last_sample) && last_sample <= sim_time && last_batch > watch_wall_) {
    watch_time_ = last_sample;
    watch_wall_ = last_batch;
  }
  const double threshold = QuietThreshold(silence_s_, every_n_steps_, time_step);
  const Clock::time_point start = poll_start_.value_or(now);
  poll_start_.reset();
  const double since_poll = std::chrono::duration<double>(start - last_poll_).count();
  last_poll_ = now;
  // rewound, or this process was not running for longer than the threshold: watch from here
  if (sim_time < watch_time_ || since_poll > threshold) {
    watch_time_ = sim_time;
    watch_wall_ = now;
  }
  quiet_for_ = sim_time - watch_time_;
  const double quiet_wall = std::chrono::duration<double>(now - watch_wall_).count();
  return running && quiet_for_ > threshold && quiet_wall > threshold;
}

bool BatchSequence::Take(uint64_t number) {
  if (number < next_ && next_ - number <= kLateBatches) {
    ++late_;
    return false;
  }
  if (number >= next_) missing_ += number - next_;
  // the last number there is stays the next one (no wrap to 0)
  next_ = number == UINT64_MAX ? number : number + 1;
  return true;
}

}  // namespace caliper::plotter
