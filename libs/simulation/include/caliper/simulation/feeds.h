#pragma once
// The Model's data feeds: subscriptions to registry ids sampled after every step (a daq::Recorder
// with its bounded queues), the bound on the values subscribed in all, the counters the recorder
// does not keep (failed pushes, wall time waited), why the Model ended a subscription, and the
// lossless waiting: before a step the stepping waits, with the owner's lock released, until every
// lossless subscription's queue has room for one more step's batches.
//
// Threading: not thread-safe. ModelCore owns one and calls it with its lock (ModelCore::mutex_)
// held, except TakeBatches, WaitForBatches and NotifyRoom, which any thread may call without that
// lock (they touch only the recorder's queues, which lock themselves, and the room condition,
// which has a mutex of its own).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/daq/recorder.h"
#include "caliper/daq/registry.h"
#include "caliper/simulation/core_types.h"

namespace caliper::simulation {

/// The data subscriptions of one Model; see the file's comment for the threading.
class Feeds {
 public:
  /// Resolves and reads the subscribed ids in `registry`, which must outlive it; `limits` bounds
  /// a subscription's ids (ids_per_call), all subscriptions' values (subscribed_values) and the
  /// queues' bytes (queued_bytes).
  Feeds(const daq::Registry& registry, const Limits& limits);
  Feeds(const Feeds&) = delete;
  Feeds& operator=(const Feeds&) = delete;

  /// A subscription to `ids` sampled every `every_n_steps` steps, in batches of `batch_steps`
  /// samples (0 counts as 1); `lossless_wait` > 0 makes it lossless (see AwaitRoom). Throws
  /// InvalidValue (no ids, every_n_steps 0), LimitExceeded (too many ids or values) or UnknownId.
  uint64_t Subscribe(const std::vector<std::string>& ids, uint32_t every_n_steps,
                     size_t batch_steps, std::chrono::milliseconds lossless_wait);
  /// Ends a subscription (nothing when there is none) and logs its losses; a non-empty `reason`
  /// says why the Model ended it, and Status gives it afterwards (for the last 64 such).
  /// Does not call NotifyRoom: the caller does once it let go of its lock.
  void Unsubscribe(uint64_t subscription, const std::string& reason);
  /// The counters of a subscription. Throws UnknownId, saying why the Model ended it when it did.
  FeedStatus Status(uint64_t subscription) const;
  /// Batches a sender took but could not deliver: counted as dropped (nothing when unknown).
  void NoteUndelivered(uint64_t subscription, uint64_t batches, uint64_t samples);
  /// Called by AwaitRoom when it begins to wait for a subscription's consumer.
  void SetConsumerWake(std::function<void(uint64_t subscription)> wake);
  /// Samples the subscriptions due after step `step` at simulated time `time` [s].
  void OnStep(uint64_t step, double time);
  /// Queues the subscription's partial batch; false when it had none (or is unknown).
  bool Flush(uint64_t subscription);

  /// Waits, with `lock` (the owner's, held) released, until every lossless subscription's queue
  /// has room for the batches of one step; ends (Unsubscribe with the reason) one whose consumer
  /// takes none for its lossless_wait. After each wait, with the lock held again, `interrupted`
  /// says whether to give up (a stop, pause, load or shutdown meanwhile). Returns whether the
  /// lock was let go meanwhile; false at once when no subscription is lossless.
  bool AwaitRoom(std::unique_lock<std::mutex>& lock, const std::function<bool()>& interrupted);
  /// Wakes AwaitRoom: batches were taken, a subscription ended, or the run is to end.
  /// Thread-safe.
  void NotifyRoom();

  /// Takes the queued batches of a subscription; `gone` tells whether it no longer exists,
  /// `dropped_samples` gets how many samples its full queue dropped so far. Thread-safe.
  std::vector<daq::Batch> TakeBatches(uint64_t subscription, bool* gone = nullptr,
                                      uint64_t* dropped_samples = nullptr);
  /// Blocks until the subscription has a batch (true), the timeout passes or it is gone (false).
  /// Thread-safe.
  bool WaitForBatches(uint64_t subscription, std::chrono::milliseconds timeout);

  /// Values of all subscriptions together (the sum of their ids' shape sizes).
  size_t subscribed_values() const { return subscribed_values_; }
  /// Subscriptions with a lossless_wait.
  size_t lossless() const { return lossless_; }

 private:
  // what the Model keeps of a subscription beside the recorder's counters
  struct Feed {
    std::chrono::milliseconds lossless_wait{0};  // 0: lossy
    size_t capacity = 0;                         // of its queue [batches]
    size_t values = 0;                           // sampled at each sampled step
    double waited_s = 0;                         // [s]
    uint64_t undelivered_batches = 0, undelivered_samples = 0;  // failed pushes
  };
  /// The first lossless subscription whose queue has no room for one step (0: none).
  uint64_t Blocked() const;

  const daq::Registry& registry_;
  const Limits limits_;
  daq::Recorder recorder_;
  std::map<uint64_t, Feed> feeds_;
  size_t subscribed_values_ = 0;             // of all subscriptions
  size_t lossless_ = 0;                      // feeds with a lossless_wait
  std::map<uint64_t, std::string> ended_;    // why the Model ended subscriptions (the last 64)
  std::function<void(uint64_t)> consumer_wake_;
  // AwaitRoom sleeps on room_ until room_events_ changes
  std::mutex room_mutex_;
  std::condition_variable room_;
  uint64_t room_events_ = 0;
};

}  // namespace caliper::simulation
