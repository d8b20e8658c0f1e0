#pragma once
// The data-acquisition recorder: subscriptions to sets of registry ids, sampled every n steps by
// the simulation thread and handed out in numbered batches through a bounded queue per
// subscription. Owns no threads: a subscriber's sender takes batches (or runs the consumer) on its
// own thread, and a full queue drops its oldest batch instead of blocking the simulation.
//
// Threading:
// - Subscribe, Unsubscribe, OnStep and Flush read the Registry: call them where the registry is
//   used, i.e. on the simulation thread (or under the model's step lock).
// - TakeBatches, WaitForBatches, Deliver, DeliverAll, Stats and subscriptions may be called from
//   any thread at any time; they never make OnStep wait longer than a map lookup.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/daq/registry.h"

namespace caliper::daq {

/// Numbers subscriptions, from 1.
using SubscriptionId = uint64_t;

/// One id of a subscription as its batches lay it out.
struct Column {
  std::string id;
  std::string unit;    // SI
  Shape shape;         // rows x cols
  size_t offset = 0;   // of its first value within a sample
  bool stale = false;  // the id no longer exists (e.g. the scene was reloaded): its values are NaN
};

/// Samples of one subscription: `step_count` samples taken at steps first_step,
/// first_step + every_n_steps, ...; every sample holds the values of all columns in column order
/// (matrices row-major).
struct Batch {
  SubscriptionId subscription = 0;
  uint64_t sequence = 0;       // 1, 2, 3, ... per subscription; a gap means batches were dropped
  uint64_t first_step = 0;     // step of the first sample
  uint64_t every_n_steps = 1;  // steps between samples
  size_t step_count = 0;       // samples in this batch
  std::vector<double> times;   // simulated time of each sample [s] (step_count)
  std::shared_ptr<const std::vector<Column>> columns;  // shared by batches of the same layout
  size_t values_per_sample = 0;                        // sum of the columns' shape sizes
  std::vector<double> data;  // step_count * values_per_sample, sample after sample
  uint64_t layout = 1;       // the subscription's layout: grows whenever its columns change

  /// The values of one column over the batch: step_count * shape.size() doubles, sample after
  /// sample.
  std::vector<double> Values(size_t column) const;
  /// The same by id; throws UnknownId when the batch has no such column.
  std::vector<double> Values(const std::string& id) const;
  /// Ids of the stale columns.
  std::vector<std::string> StaleIds() const;
};

/// Receives batches on the thread that calls Recorder::Deliver.
using Consumer = std::function<void(const Batch& batch)>;

/// What to record and how to hand it out.
struct SubscriptionOptions {
  std::vector<std::string> ids;  // registry ids, in the order of the columns
  uint64_t every_n_steps = 1;    // sample every n-th step (>= 1)
  size_t batch_steps = 100;      // samples per batch (>= 1)
  size_t queue_capacity = 64;    // batches queued before the oldest is dropped (>= 1)
  Consumer consumer;             // optional: what Deliver() hands batches to
};

/// Counters of one subscription.
struct SubscriptionStats {
  uint64_t samples = 0;            // samples taken
  uint64_t batches = 0;            // batches completed (the last sequence number)
  uint64_t dropped = 0;            // batches dropped because the queue was full
  uint64_t dropped_samples = 0;    // the samples those batches held
  size_t queued = 0;               // batches waiting to be taken
  std::vector<std::string> stale;  // ids that no longer exist
  std::string last_error;          // the last getter failure, "" when none
};

/// Subscriptions sampled by OnStep; batches queued per subscription.
class Recorder {
 public:
  /// `registry` must outlive the recorder.
  explicit Recorder(const Registry& registry);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Starts recording `options.ids` from the next OnStep on. Throws UnknownId for an id that is
  /// not registered and std::invalid_argument for no ids or a zero every_n_steps, batch_steps or
  /// queue_capacity.
  SubscriptionId Subscribe(SubscriptionOptions options);
  /// Ends a subscription; returns what it had not handed out yet (queued batches and the partial
  /// one, in sequence order). Threads waiting in WaitForBatches wake up. Throws UnknownId.
  std::vector<Batch> Unsubscribe(SubscriptionId id);

  /// Samples the subscriptions due at `step` (the step just completed, simulated time `sim_time`
  /// [s]). Re-resolves every id first when the registry changed: vanished ids turn stale (NaN),
  /// ids registered again come back. A batch that reaches batch_steps samples is queued; a step
  /// that goes backwards (reset) or skips a due sample starts a new batch.
  void OnStep(uint64_t step, double sim_time);
  /// Queues the partial batch of every subscription (or of one; UnknownId when unknown).
  void Flush();
  void Flush(SubscriptionId id);

  /// Takes up to `max` queued batches, oldest first. Throws UnknownId.
  std::vector<Batch> TakeBatches(SubscriptionId id, size_t max = SIZE_MAX);
  /// Blocks until the subscription has a queued batch (true), the timeout passes or it is
  /// unsubscribed (false). Throws UnknownId.
  bool WaitForBatches(SubscriptionId id, std::chrono::milliseconds timeout);
  /// Hands up to `max` queued batches to the subscription's consumer, on the calling thread;
  /// returns how many. An exception from the consumer propagates (that batch is gone, the rest
  /// stay queued). Throws UnknownId, std::logic_error when it has no consumer.
  size_t Deliver(SubscriptionId id, size_t max = SIZE_MAX);
  /// Deliver() for every subscription with a consumer; returns the number of batches.
  size_t DeliverAll();

  /// Throws UnknownId.
  SubscriptionStats Stats(SubscriptionId id) const;
  /// The ids of the current subscriptions, ascending.
  std::vector<SubscriptionId> subscriptions() const;

 private:
  struct Queue;
  struct Subscription;

  std::shared_ptr<Queue> FindQueue(SubscriptionId id) const;
  /// Hands up to `max` of the queue's batches to its consumer, one at a time.
  static size_t DeliverFrom(Queue& queue, size_t max);
  Subscription& Find(SubscriptionId id);
  void Resolve(Subscription& s, bool initial);
  void Plan(Subscription& s);
  void Sample(Subscription& s, uint64_t step, double sim_time);
  void Emit(Subscription& s);

  const Registry& registry_;
  uint64_t registry_version_;
  mutable std::mutex mutex_;  // guards subscriptions_ (the map and the subscriptions' state)
  std::map<SubscriptionId, std::unique_ptr<Subscription>> subscriptions_;
  SubscriptionId next_id_ = 1;
};

}  // namespace caliper::daq
