#pragma once
// A DAQ subscription of a client: a DataConsumer servant in this process that the Model pushes
// sample batches to, handed to a callback. Lossless (the Model's stepping waits for this
// consumer in lock-step and as-fast-as-possible runs) or lossy (it drops the oldest batches of a
// slow consumer, counted). caliper-ctl record and the Python package record through it.
//
//   client::DataFeed feed(session, model, {"arm.elbow.position"}, 1, true,
//                         [&](const client::Batch& b) { /* store b.times, b.data */ });
//   ... step the Model ...
//   feed.Close();

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "caliper/client/model.h"
#include "caliper/client/session.h"

namespace caliper::client {

/// One batch of samples as pushed by the Model (views valid during the callback only).
struct Batch {
  uint64_t number = 0;           ///< 1, 2, 3, ... per subscription; a gap is a lost batch
  const double* times = nullptr;  ///< simulated time of each sample [s], `count` of them
  size_t count = 0;               ///< samples in the batch
  const double* data = nullptr;   ///< count * values_per_sample values, sample by sample
  size_t values_per_sample = 0;
  std::vector<std::string> stale_ids;  ///< subscribed ids the Model no longer has (NaN)
};

class DataFeed {
 public:
  /// Called on an ORB thread, one batch at a time, with mutex() held.
  using OnBatch = std::function<void(const Batch&)>;

  /// Activates the consumer in the session's RootPOA and subscribes `ids` every N steps
  /// (subscribe_lossless when `lossless`). The Model's refusals raise the library's errors
  /// (UnknownIdError naming an id, LimitExceededError, ...) through Call.
  DataFeed(Session& session, const ModelRef& model, const std::vector<std::string>& ids,
           uint32_t every_n_steps, bool lossless, OnBatch on_batch);
  /// Close().
  ~DataFeed();
  DataFeed(const DataFeed&) = delete;
  DataFeed& operator=(const DataFeed&) = delete;

  /// The Model's subscription id.
  uint64_t subscription() const { return subscription_; }
  /// The Model's counters for it (dropped samples, time waited). UnknownIdError with the Model's
  /// reason when the Model ended it (a consumer that missed a push deadline); ConnectionError
  /// when the Model is gone.
  ::Caliper::Daq::SubscriptionStatus Status();
  /// No batch reaches the callback after this; unsubscribes (a Model already gone is fine) and
  /// deactivates the consumer. Idempotent.
  void Close();

  /// Held while the callback runs: lock it to read what the callback writes.
  std::mutex& mutex();
  /// Batches received so far (read under mutex()).
  uint64_t batches() const;
  /// Ids the Model reported stale in any batch (read under mutex()).
  const std::set<std::string>& stale() const;

 private:
  class Consumer;
  ModelRef model_;
  PortableServer::POA_var poa_;
  Consumer* consumer_ = nullptr;  // owned by owner_
  PortableServer::ServantBase_var owner_;
  PortableServer::ObjectId_var oid_;
  uint64_t subscription_ = 0;
  bool closed_ = false;
};

}  // namespace caliper::client
