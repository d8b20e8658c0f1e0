#pragma once
// The Model's senders: a small fixed pool of threads that push to observers (scene, transforms)
// and data subscribers (DAQ batches), so that the simulation never waits on the network and no
// client can make the Model start threads or hold unbounded data for it.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "caliper/model.hh"
#include "caliper/sgal/physics_scene.h"
#include "caliper/simulation/model_core.h"

namespace caliper::model {

/// Bounds on what the Model does for the clients it pushes to (observers and subscriptions).
///
/// A client is the endpoint (host:port of the first IIOP profile) of the object reference it
/// registers: every object of one client process shares its ORB's endpoint, and it is where the
/// Model's pushes go, so a slow or stopped process costs its own share only. The endpoint is
/// read from the reference, not from the calling connection (a client may call over several
/// connections, all from 127.0.0.1); a client that forges endpoints is still held by the totals.
struct PushLimits {
  size_t threads = 4;                  ///< sender threads shared by all observers and subscriptions
  size_t observers_per_client = 16;    ///< observers one client may have registered
  size_t subscriptions_per_client = 32;  ///< subscriptions one client may hold
  size_t observers = 256;              ///< observers over all clients
  size_t subscriptions = 256;          ///< subscriptions over all clients
  /// The deadline of one push (and of the reachability check when registering).
  std::chrono::milliseconds call_timeout{1000};
  /// After a failed push (timeout, refused call) a target waits this long; its next push carries
  /// the latest state in full (all bodies; the DAQ batches of the failed push are dropped).
  std::chrono::milliseconds retry_after{250};
  /// A target whose every push failed for this long is dropped; one whose process is gone
  /// (OBJECT_NOT_EXIST, connection refused) is dropped at once.
  std::chrono::milliseconds drop_after{60000};
};

/// What a sender thread pushes to: one observer or one subscription.
class PushTarget {
 public:
  enum class Outcome { kNothing, kSent, kFailed, kGone };
  virtual ~PushTarget() = default;
  /// Sends what is pending; never called by two threads at once. `why` gets the reason of a
  /// failure.
  virtual Outcome Push(std::string* why) = 0;
  /// True when something may wait to be sent; cheap (no lock that a step holds, no wait), called
  /// under the pool's lock.
  virtual bool HasWork() = 0;
  /// Stops the core from feeding it (called once, when it leaves the pool).
  virtual void Detach() = 0;
};

/// The sender threads and the targets they serve, with the per-client and total caps. A client
/// has at most one push in flight (a stopped process holds one thread, for one deadline at a
/// time); targets are served in turn.
class PushPool {
 public:
  enum class Kind { kObserver, kSubscription };
  explicit PushPool(const PushLimits& limits);
  /// Stops and joins the threads, then detaches every target.
  ~PushPool();
  PushPool(const PushPool&) = delete;
  PushPool& operator=(const PushPool&) = delete;

  const PushLimits& limits() const { return limits_; }
  /// The id of a registered target of `kind` with an equivalent reference (0 when none); a found
  /// one is due for a push at once (a client registering again wants the current state).
  uint64_t Find(Kind kind, CORBA::Object_ptr ref);
  /// Throws Daq::LimitExceeded when `client` or the Model is at its cap for `kind`.
  void CheckRoom(Kind kind, const std::string& client);
  /// Adds a target under `id` and returns `id`; or returns the id of an equivalent one of kind
  /// kObserver registered meanwhile (the new one is then not added). Throws Daq::LimitExceeded.
  uint64_t Add(Kind kind, uint64_t id, const std::string& client, CORBA::Object_ptr ref,
               std::shared_ptr<PushTarget> target);
  /// Removes and detaches a target; false when there is none under `id`.
  bool Remove(Kind kind, uint64_t id);
  /// A target has something to send.
  void Wake();
  /// The target under `id` has something to send now (sooner than its next poll).
  void Due(Kind kind, uint64_t id);

 private:
  struct Entry {
    std::shared_ptr<PushTarget> target;
    std::string client;
    CORBA::Object_var ref;
    bool busy = false;
    bool removed = false;
    std::chrono::steady_clock::time_point retry_at{};
    std::optional<std::chrono::steady_clock::time_point> failing_since;
    uint64_t failures = 0;  // failed pushes in a row
  };
  using Key = std::pair<Kind, uint64_t>;

  uint64_t FindLocked(Kind kind, CORBA::Object_ptr ref);
  void CheckRoomLocked(Kind kind, const std::string& client) const;
  void Work();
  /// The next target to push to, or nullptr; `wake_at` gets when to look again.
  std::shared_ptr<Entry> PickLocked(std::chrono::steady_clock::time_point now,
                                    std::chrono::steady_clock::time_point* wake_at);
  /// Takes the outcome of a push into account; may drop the target (returned to detach).
  std::shared_ptr<PushTarget> AccountLocked(const Key& key, Entry& entry,
                                            PushTarget::Outcome outcome, const std::string& why);
  size_t CountLocked(Kind kind, const std::string* client) const;

  const PushLimits limits_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::map<Key, std::shared_ptr<Entry>> entries_;
  std::map<std::string, int> in_flight_;  // pushes in flight per client
  Key cursor_{Kind::kObserver, 0};        // the last target served: the next one is after it
  std::vector<std::thread> threads_;
};

/// Sends scene, cleared and transform updates to one SceneObserver. Only the latest snapshot is
/// kept: a slow observer receives coalesced updates; after a failed push the next one carries
/// every body again (the observer may have missed the last changes).
class ObserverTarget : public PushTarget, public simulation::CoreListener {
 public:
  ObserverTarget(simulation::ModelCore& core, PushPool& pool, Caliper::Scene::SceneObserver_ptr observer);
  void OnScene(std::shared_ptr<const sgal::Scene> scene, uint64_t generation) override;
  void OnSnapshot(std::shared_ptr<const simulation::Snapshot> snapshot) override;
  void OnCleared() override;
  Outcome Push(std::string* why) override;
  bool HasWork() override { return pending_; }
  void Detach() override { core_.RemoveListener(this); }

 private:
  void MarkPending();

  simulation::ModelCore& core_;
  PushPool& pool_;
  Caliper::Scene::SceneObserver_var observer_;
  std::mutex mutex_;  // guards what waits to be sent
  bool cleared_ = false;
  std::shared_ptr<const sgal::Scene> scene_;
  uint64_t scene_generation_ = 0;
  std::shared_ptr<const simulation::Snapshot> snapshot_;
  std::atomic<bool> pending_{false};
  // the sending side, touched by one push at a time
  sgal::ChangeFilter filter_;
  uint64_t generation_ = 0;
  uint64_t update_ = 0;
};

/// Delivers one subscription's batches to its DataConsumer. The batches wait in the recorder's
/// bounded queue (oldest dropped first, counted there, logged here at most every 10 s); those of
/// a failed push are dropped and counted here: the consumer sees the gap in the batch numbers. A
/// lossless subscription (the stepping waits for its queue) ends at its first failed push: a
/// consumer that is gone or misses the deadline must not hold the simulation again.
class SubscriptionTarget : public PushTarget {
 public:
  SubscriptionTarget(simulation::ModelCore& core, uint64_t subscription,
                     Caliper::Daq::DataConsumer_ptr consumer, bool lossless = false);
  Outcome Push(std::string* why) override;
  /// Always: the pool looks for batches every 20 ms (taking them is the check); a lossless one is
  /// also made due when the stepping waits for it.
  bool HasWork() override { return true; }
  void Detach() override { core_.Unsubscribe(subscription_, last_failure_); }

 private:
  simulation::ModelCore& core_;
  const uint64_t subscription_;
  Caliper::Daq::DataConsumer_var consumer_;
  const bool lossless_;
  uint64_t dropped_ = 0;         // batches of failed pushes
  uint64_t queue_dropped_ = 0;   // samples the full queue dropped, as last logged
  std::chrono::steady_clock::time_point queue_logged_{};
  std::string last_failure_;     // why the last push failed ("" after one succeeded)
};

}  // namespace caliper::model
