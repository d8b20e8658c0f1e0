#pragma once
// A command's way to an actuator, delayed by whole time steps: what a motor driver's bus or a
// muscle's nerve takes before it acts on a command. Private to libs/actuators; every commanded
// kind holds one (dc_motor_tendon, hill_muscle), with the parameter `command_delay` [s] and the
// state `delayed_command`.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace caliper::actuators {

class CommandDelay {
 public:
  /// The most time steps a command may be delayed by (100 s at 1 ms): a bound against a typo, not
  /// against memory. The line holds as many commands as the delay has steps (and its state as
  /// many values), so that a state without a delay stays small and a long one fits.
  static constexpr int kMaxSteps = 100000;

  /// The delay [s]; throws std::invalid_argument "parameter 'command_delay' ..." when it is
  /// negative or not finite, or longer than kMaxSteps at the time step already known.
  void SetDelay(double seconds);
  double delay() const { return delay_; }
  /// The engine's time step [s]; throws std::invalid_argument when the delay would take more
  /// than kMaxSteps of it.
  void SetTimeStep(double dt);

  /// Empties the line: the actuator has followed `command` since ever.
  void Reset(double command);
  /// A command given before the next step; a later one before the same step replaces it.
  void Issue(double command) {
    if (delay_ == 0 && count_ == 0) {
      delayed_ = command;  // no delay: followed from the next step on, as its state shows at once
      return;
    }
    Queue(command);
  }
  /// At the start of a step of dt [s]: the command the actuator follows through it (the last
  /// one issued at least the delay's steps ago). Throws as SetTimeStep() for a dt not told
  /// before that makes the delay too long.
  double Take(double dt) {
    if (count_ > 0) Release(dt);
    ++steps_;
    return delayed_;
  }
  /// The command followed in the last step taken; without a delay (and nothing in flight from
  /// an earlier one), the last command issued.
  double delayed() const { return delayed_; }

  /// How many values SaveState() may write: 3 and two per place in the line, which has the
  /// delay's steps and two more. It changes with SetDelay() and SetTimeStep() alone.
  std::size_t StateSize() const { return 3 + 2 * pending_.size(); }
  /// Writes the step count, the delayed command, the count and the commands in flight (each
  /// one's step issued and value); the values after them (up to StateSize()) are left as they
  /// are.
  void SaveState(double* out) const;
  /// Whether `n` values hold what SaveState() wrote with a line of any length: 3 and two per
  /// place, a count of commands in flight that is a whole number and whose commands fit.
  static bool Readable(const double* in, std::size_t n);
  /// Reads back what SaveState() wrote, under this delay or another: of commands that a longer
  /// line held, those due at the next step but the newest are dropped, as they would never be
  /// followed. A count of commands out of range empties the line.
  void RestoreState(const double* in);

  /// What one step changes, for putting that step back (the engine saves it before every step):
  /// Take() only moves the line's start past the commands it releases and leaves them in place,
  /// so the step count, the command followed, the start and the count put it back, however
  /// many commands are in flight. SaveState() copies each of them: a 10 s delay under a command
  /// every 1 ms step is 20,000 values. Between the two calls only Take() runs, at the time step
  /// SetTimeStep() last told (another would refit the line: RestoreStepState() then throws
  /// std::logic_error). Five values.
  void SaveStepState(double* out) const;
  void RestoreStepState(const double* in);

 private:
  struct Pending {
    std::int64_t issued;  // the step before which it was given
    double value;
  };
  static int Steps(double delay, double dt);  // throws beyond the line
  void Queue(double command);                 // into the line
  void Release(double dt);                    // what is due at this step leaves the line
  // the place of the k-th command from the oldest, 0 <= k < the line's length (no division: this
  // runs for every command in flight in SaveState and Queue)
  std::size_t Slot(int k) const {
    const std::size_t i = static_cast<std::size_t>(head_ + k);
    return i < pending_.size() ? i : i - pending_.size();
  }
  // the line to the delay's steps and two more, keeping the commands that will be followed
  void Fit();

  double delay_ = 0;                                        // [s]
  double time_step_ = 0;                                    // the engine's, once told [s]
  int delay_steps_ = 0;                                     // delay_ in steps of time_step_
  std::vector<Pending> pending_ = std::vector<Pending>(2);  // a ring, oldest at head_
  int head_ = 0;
  int count_ = 0;
  std::int64_t steps_ = 0;  // steps taken since Reset
  double delayed_ = 0;      // the command followed
  std::int64_t refits_ = 0;  // lines Fit() laid out anew (what a step's state cannot put back)
};

}  // namespace caliper::actuators
