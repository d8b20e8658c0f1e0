#pragma once
// What ModelCore and the parts it owns (Feeds, EditHistory, Replayer, ExperimentRunner) share: the
// errors they raise, the bounds of what one client may ask, and the counters of a data
// subscription. model_core.h includes it: its users need not.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace caliper::simulation {

/// The operation is not possible now (no scene, faulted, running); the message says why.
class NotAvailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A bad value (NaN, out of range, wrong shape); the message says which and why.
class InvalidValue : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// An id (actuator, channel) that does not exist; `id()` names it.
class UnknownId : public std::out_of_range {
 public:
  UnknownId(const std::string& what, std::string id) : std::out_of_range(what), id_(std::move(id)) {}
  const std::string& id() const { return id_; }

 private:
  std::string id_;
};

/// A request above what one call may ask for or one queue may hold; `limit()` is the bound.
class LimitExceeded : public std::length_error {
 public:
  LimitExceeded(const std::string& what, uint64_t limit) : std::length_error(what), limit_(limit) {}
  uint64_t limit() const { return limit_; }

 private:
  uint64_t limit_;
};

/// Bounds of what one client call may ask the Model to do (each refused above with
/// LimitExceeded naming the bound).
struct Limits {
  size_t ids_per_call = 100000;          // ids in one get/sample or subscribe
  size_t channels_per_list = 200000;     // channels one list/channels reply may hold
  size_t pattern_length = 1024;          // characters of a list/channels glob
  size_t pattern_stars = 8;              // '*' in a list/channels glob
  uint64_t experiment_steps = 100000000;  // steps of one run_experiment (28 h at 1 ms)
  size_t pending_writes = 100000;        // motor commands queued for the next step
  size_t subscribed_values = 100000;     // values of all data subscriptions together
  size_t queued_bytes = size_t{256} << 20;  // batches waiting for slow consumers, in all
  std::chrono::milliseconds pull_lease{2000};  // a pull not renewed for this long ends
  uint64_t recording_bytes = uint64_t{4} << 30;  // the largest recording file (a client's 0 = this)
};

/// The counters of one data subscription.
struct FeedStatus {
  bool lossless = false;         // the stepping waits for its consumer (see Subscribe)
  uint64_t samples = 0;          // taken so far
  uint64_t batches = 0;          // completed so far
  uint64_t dropped_batches = 0;  // never delivered: the queue was full or their push failed
  uint64_t dropped_samples = 0;  // the samples those batches held
  uint64_t queued = 0;           // batches waiting to be taken
  double waited_s = 0;           // wall time the stepping waited for the consumer [s]
};

}  // namespace caliper::simulation
