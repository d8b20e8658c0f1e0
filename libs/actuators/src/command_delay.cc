#include "command_delay.h"

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
}

void CommandDelay::SetTimeStep(double dt) {
  delay_steps_ = Steps(delay_, dt);
  time_step_ = dt;
}

void CommandDelay::Reset(double command) {
  head_ = count_ = 0;
  steps_ = 0;
  delayed_ = command;
}

void CommandDelay::Queue(double command) {
  if (count_ > 0) {
    Pending& back = pending_[(head_ + count_ - 1) % kCapacity];
    if (back.issued == steps_) {
      back.value = command;
      return;
    }
  }
  // the line never overflows: a step leaves at most delay_steps_ <= kMaxSteps commands in it,
  // and one more arrives before the next
  pending_[(head_ + count_) % kCapacity] = {steps_, command};
  ++count_;
}

void CommandDelay::Release(double dt) {
  if (dt != time_step_) SetTimeStep(dt);  // a caller that did not say its time step first
  while (count_ > 0 && steps_ - pending_[head_].issued >= delay_steps_) {
    delayed_ = pending_[head_].value;
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
}

void CommandDelay::SaveState(double* out) const {
  out[0] = static_cast<double>(steps_);
  out[1] = delayed_;
  out[2] = count_;
  // only the commands in flight: the engine saves every actuator before each step (for a
  // rollback), and a line is mostly empty
  for (int k = 0; k < count_; ++k) {
    const Pending& p = pending_[(head_ + k) % kCapacity];
    out[3 + 2 * k] = static_cast<double>(p.issued);
    out[4 + 2 * k] = p.value;
  }
}

void CommandDelay::RestoreState(const double* in) {
  steps_ = static_cast<std::int64_t>(in[0]);
  delayed_ = in[1];
  head_ = 0;
  count_ = in[2] >= 0 && in[2] <= kCapacity ? static_cast<int>(in[2]) : 0;
  for (int k = 0; k < count_; ++k)
    pending_[k] = {static_cast<std::int64_t>(in[3 + 2 * k]), in[4 + 2 * k]};
}

}  // namespace caliper::actuators
