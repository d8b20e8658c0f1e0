#include "command_delay.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "motor_checks.h"

namespace caliper::actuators {

using motor_detail::Text;

int CommandDelay::Steps(double delay, double dt) {
  const double steps = std::round(delay / dt);
  if (steps > kMaxSteps)
    throw std::invalid_argument("parameter 'command_delay' = " + Text(delay) + " s is " +
                                Text(steps) + " time steps of " + Text(dt) + " s; at most " +
                                std::to_string(kMaxSteps) + " (" + Text(kMaxSteps * dt) +
                                " s at this time step)");
  return static_cast<int>(steps);
}

void CommandDelay::SetDelay(double seconds) {
  motor_detail::Check("command_delay", "s", seconds, motor_detail::Range::kNonNegative);
  const int steps = time_step_ > 0 ? Steps(seconds, time_step_) : 0;
  delay_ = seconds;
  delay_steps_ = steps;
  Fit();
}

void CommandDelay::SetTimeStep(double dt) {
  delay_steps_ = Steps(delay_, dt);
  time_step_ = dt;
  Fit();
}

void CommandDelay::Fit() {
  const std::size_t size = pending_.size();
  auto at = [&](int k) -> const Pending& { return pending_[Slot(k)]; };
  // of the commands due at the next step only the newest is followed (Release): the older ones
  // go. The rest were issued within the last delay_steps_ steps, one per step, and one more may
  // come before the next step.
  int first = 0;
  while (first + 1 < count_ && steps_ - at(first + 1).issued >= delay_steps_) ++first;
  const int capacity = delay_steps_ + 2;
  first = std::max(first, count_ - (capacity - 1));  // a state of another origin
  if (first == 0 && size == static_cast<std::size_t>(capacity)) return;
  std::vector<Pending> line(static_cast<std::size_t>(capacity));
  for (int k = first; k < count_; ++k) line[k - first] = at(k);
  pending_.swap(line);
  count_ -= first;
  head_ = 0;
  ++refits_;
}

void CommandDelay::Reset(double command) {
  head_ = count_ = 0;
  steps_ = 0;
  delayed_ = command;
  Fit();
}

void CommandDelay::Queue(double command) {
  if (count_ > 0) {
    Pending& back = pending_[Slot(count_ - 1)];
    if (back.issued == steps_) {
      back.value = command;
      return;
    }
  }
  // the line never overflows (Fit): a step leaves at most delay_steps_ commands in it and one
  // more arrives before the next; after Fit, the newest due one, the not yet due and one more
  pending_[Slot(count_)] = {steps_, command};
  ++count_;
}

void CommandDelay::Release(double dt) {
  if (dt != time_step_) SetTimeStep(dt);  // a caller that did not say its time step first
  while (count_ > 0 && steps_ - pending_[head_].issued >= delay_steps_) {
    delayed_ = pending_[head_].value;
    head_ = Slot(1);
    --count_;
  }
}

void CommandDelay::SaveState(double* out) const {
  out[0] = static_cast<double>(steps_);
  out[1] = delayed_;
  out[2] = count_;
  // only the commands in flight (a keyframe of a mostly empty line stays small)
  for (int k = 0; k < count_; ++k) {
    const Pending& p = pending_[Slot(k)];
    out[3 + 2 * k] = static_cast<double>(p.issued);
    out[4 + 2 * k] = p.value;
  }
}

void CommandDelay::SaveStepState(double* out) const {
  out[0] = static_cast<double>(steps_);
  out[1] = delayed_;
  out[2] = head_;
  out[3] = count_;
  out[4] = static_cast<double>(refits_);
}

void CommandDelay::RestoreStepState(const double* in) {
  if (static_cast<double>(refits_) != in[4])
    throw std::logic_error(
        "command delay: the line was laid out anew since its step state was saved (a step at a "
        "time step not told before); the step cannot be put back");
  steps_ = static_cast<std::int64_t>(in[0]);
  delayed_ = in[1];
  head_ = static_cast<int>(in[2]);
  count_ = static_cast<int>(in[3]);
}

namespace {
// the count of commands in flight a state holds, -1 when it is no count of a line
int CountIn(const double* in) {
  const double count = in[2];
  if (!(count >= 0 && count <= CommandDelay::kMaxSteps + 1) || count != std::floor(count))
    return -1;
  return static_cast<int>(count);
}
}  // namespace

bool CommandDelay::Readable(const double* in, std::size_t n) {
  // a line's state: 3 values and two per place, no more places than the longest delay has
  if (n < 3 || (n - 3) % 2 != 0 || (n - 3) / 2 > static_cast<std::size_t>(kMaxSteps) + 2)
    return false;
  const int count = CountIn(in);
  return count >= 0 && 3 + 2 * static_cast<std::size_t>(count) <= n;
}

void CommandDelay::RestoreState(const double* in) {
  steps_ = static_cast<std::int64_t>(in[0]);
  delayed_ = in[1];
  head_ = 0;
  count_ = std::max(0, CountIn(in));
  // saved under this delay: into the line as it is, no allocation; under a longer one, the line
  // may hold more than this one's, and Fit keeps what will be followed
  if (static_cast<std::size_t>(count_) > pending_.size())
    pending_.resize(static_cast<std::size_t>(count_));
  for (int k = 0; k < count_; ++k)
    pending_[k] = {static_cast<std::int64_t>(in[3 + 2 * k]), in[4 + 2 * k]};
  Fit();
}

}  // namespace caliper::actuators
