#pragma once
// Whether a DAQ stream has gone quiet: the Model runs but no sample of the subscription has come
// for a while (e.g. the Model dropped the subscriber), so the plotter subscribes again. How long
// "a while" is depends on the subscription: one sample every n steps may leave seconds of
// simulated time between samples. And which of a stream's batches come late. No Qt, no CORBA.

#include <chrono>
#include <cstdint>
#include <optional>

namespace caliper::plotter {

/// The Model sends a subscription's samples in batches of about this much simulated time, or of
/// one sample when samples are further apart [s].
constexpr double kModelBatchPeriod = 0.05;

/// Simulated (and wall) time without a sample after which a running Model's stream counts as
/// quiet [s]: `silence_s`, or three sample intervals (`every_n_steps` * `time_step`) plus a batch
/// period when that is longer.
double QuietThreshold(double silence_s, uint32_t every_n_steps, double time_step);

/// Watches the stream of one subscription from poll to poll of the Model's status.
class StreamWatch {
 public:
  using Clock = std::chrono::steady_clock;

  /// `silence_s`: the shortest quiet spell that counts [s] (see QuietThreshold).
  explicit StreamWatch(double silence_s) : silence_s_(silence_s) {}

  /// A subscription sampling every `every_n_steps` steps was made at simulated time `sim_time`
  /// [s] and wall time `now`.
  void Start(double sim_time, uint32_t every_n_steps, Clock::time_point now);

  /// A poll starts at `now`, before its calls to the Model: the gap Quiet looks at runs from the
  /// previous Quiet to here, so that slow calls of this poll do not count as time the process
  /// did not run. Without it, Quiet's own `now` ends the gap.
  void PollStarts(Clock::time_point now) { poll_start_ = now; }

  /// One poll: the Model `running` at `sim_time` with steps of `time_step` [s]; `last_sample` is
  /// the time of the newest sample received (NaN when none), received at `last_batch`. True when
  /// the stream is quiet: the Model runs and both the simulated and the wall time since the last
  /// sign of life exceed QuietThreshold. A simulated time that went back (a reset) restarts the
  /// watch, and so does a poll that starts more than QuietThreshold after the previous one (or
  /// Start; see PollStarts): this process did not run meanwhile (SIGSTOP, a suspended laptop, a
  /// starved machine), so the batches sent to it could not be taken in yet, and the stream gets
  /// the threshold again from now before it counts as quiet.
  bool Quiet(bool running, double sim_time, double time_step, double last_sample,
             Clock::time_point last_batch, Clock::time_point now);

  /// Simulated time since the last sign of life, as of the last poll [s].
  double quiet_for() const { return quiet_for_; }

 private:
  double silence_s_;
  uint32_t every_n_steps_ = 1;
  double watch_time_ = 0;           // [s] simulated time of the last sign of life of the stream
  Clock::time_point watch_wall_{};  // and when it was seen
  Clock::time_point last_poll_{};   // the previous Quiet or Start
  std::optional<Clock::time_point> poll_start_;  // this poll's start (PollStarts)
  double quiet_for_ = 0;            // [s]
};

/// The batch numbers of the current subscription as they arrive (the Model numbers each
/// subscription's batches 1, 2, 3, ...; a gap is batches it dropped). Each push goes on its own
/// call, so after pushes that timed out (a plotter stopped, suspended or starved) the batches
/// still unread in its sockets are taken in by several ORB threads at once, and an older batch
/// can come after a newer one. Its samples are older than those shown: taken in, they would read
/// as a reset of the Model and clear the plot's history. Such a batch is late and left out; the
/// Model counted it as dropped, and it stays counted as missing here. A number further below
/// than kLateBatches is no late batch (the Model drops a subscriber that failed for 60 s, far
/// fewer batches) but a sender that numbers anew: the count goes on from it.
class BatchSequence {
 public:
  /// The most batches a late one can lie behind the newest taken.
  static constexpr uint64_t kLateBatches = uint64_t{1} << 20;
  /// A new subscription: its numbers start again at 1 (the counts go on).
  void Restart() { next_ = 1; }
  /// Batch `number` arrived: false when it is late (below one taken before, by at most
  /// kLateBatches).
  bool Take(uint64_t number);
  uint64_t missing() const { return missing_; }  ///< numbers skipped, over all subscriptions
  uint64_t late() const { return late_; }        ///< batches left out as late

 private:
  uint64_t next_ = 1;
  uint64_t missing_ = 0;
  uint64_t late_ = 0;
};

}  // namespace caliper::plotter
