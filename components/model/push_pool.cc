#include "push_pool.h"

#include <algorithm>

#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/peers.h"
#include "model_convert.h"

namespace caliper::model {

namespace S = ::Caliper::Scene;
namespace D = ::Caliper::Daq;
using rtc::PeerGone;
using simulation::ModelCore;
using simulation::Snapshot;
using Clock = std::chrono::steady_clock;

// how often a subscription without batches is looked at again
constexpr std::chrono::milliseconds kPollInterval{20};

PushPool::PushPool(const PushLimits& limits) : limits_(limits) {
  for (size_t i = 0; i < std::max<size_t>(1, limits_.threads); ++i)
    threads_.emplace_back([this] { Work(); });
}

PushPool::~PushPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& t : threads_) t.join();
  for (auto& [key, entry] : entries_) entry->target->Detach();
}

uint64_t PushPool::Find(Kind kind, CORBA::Object_ptr ref) {
  std::lock_guard<std::mutex> lock(mutex_);
  return FindLocked(kind, ref);
}

uint64_t PushPool::FindLocked(Kind kind, CORBA::Object_ptr ref) {
  for (auto& [key, entry] : entries_)
    if (key.first == kind && entry->ref->_is_equivalent(ref)) {
      entry->retry_at = Clock::time_point{};
      wake_.notify_one();
      return key.second;
    }
  return 0;
}

size_t PushPool::CountLocked(Kind kind, const std::string* client) const {
  size_t n = 0;
  for (const auto& [key, entry] : entries_)
    if (key.first == kind && (client == nullptr || entry->client == *client)) ++n;
  return n;
}

void PushPool::CheckRoom(Kind kind, const std::string& client) {
  std::lock_guard<std::mutex> lock(mutex_);
  CheckRoomLocked(kind, client);
}

void PushPool::CheckRoomLocked(Kind kind, const std::string& client) const {
  const bool observers = kind == Kind::kObserver;
  const char* what = observers ? "observers" : "subscriptions";
  const size_t per_client =
      observers ? limits_.observers_per_client : limits_.subscriptions_per_client;
  const size_t total = observers ? limits_.observers : limits_.subscriptions;
  if (CountLocked(kind, &client) >= per_client)
    throw D::LimitExceeded((std::string("client ") + client + " has " +
                            std::to_string(per_client) + " " + what +
                            ", the most one client may have")
                               .c_str(),
                           per_client);
  if (CountLocked(kind, nullptr) >= total)
    throw D::LimitExceeded((std::string("the Model serves ") + std::to_string(total) + " " + what +
                            ", the most it takes")
                               .c_str(),
                           total);
}

uint64_t PushPool::Add(Kind kind, uint64_t id, const std::string& client, CORBA::Object_ptr ref,
                       std::shared_ptr<PushTarget> target) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (kind == Kind::kObserver) {
    // registered meanwhile by a call of its own
    const uint64_t existing = FindLocked(kind, ref);
    if (existing != 0) return existing;
  }
  CheckRoomLocked(kind, client);
  auto entry = std::make_shared<Entry>();
  entry->target = std::move(target);
  entry->client = client;
  entry->ref = CORBA::Object::_duplicate(ref);
  entries_[{kind, id}] = std::move(entry);
  wake_.notify_one();
  return id;
}

bool PushPool::Remove(Kind kind, uint64_t id) {
  std::shared_ptr<Entry> entry;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find({kind, id});
    if (it == entries_.end()) return false;
    entry = it->second;
    entry->removed = true;
    entries_.erase(it);
  }
  entry->target->Detach();
  return true;
}

void PushPool::Due(Kind kind, uint64_t id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find({kind, id});
    if (it == entries_.end()) return;
    it->second->retry_at = Clock::time_point{};
  }
  wake_.notify_one();
}

void PushPool::Wake() {
  { std::lock_guard<std::mutex> lock(mutex_); }
  wake_.notify_one();
}

std::shared_ptr<PushPool::Entry> PushPool::PickLocked(Clock::time_point now,
                                                      Clock::time_point* wake_at) {
  *wake_at = now + std::chrono::hours(1);
  if (entries_.empty()) return nullptr;
  // in turn, starting after the one served last
  auto it = entries_.upper_bound(cursor_);
  for (size_t n = 0; n < entries_.size(); ++n, ++it) {
    if (it == entries_.end()) it = entries_.begin();
    Entry& e = *it->second;
    if (e.busy || in_flight_.count(e.client) > 0) continue;
    if (e.retry_at > now) {
      *wake_at = std::min(*wake_at, e.retry_at);
      continue;
    }
    if (!e.target->HasWork()) continue;
    cursor_ = it->first;
    return it->second;
  }
  return nullptr;
}

void PushPool::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    Clock::time_point wake_at;
    const std::shared_ptr<Entry> entry = PickLocked(Clock::now(), &wake_at);
    if (!entry) {
      wake_.wait_until(lock, wake_at);
      continue;
    }
    const Key key = cursor_;
    entry->busy = true;
    ++in_flight_[entry->client];
    lock.unlock();
    std::string why;
    PushTarget::Outcome outcome;
    try {
      outcome = entry->target->Push(&why);
    } catch (const std::exception& e) {
      outcome = PushTarget::Outcome::kFailed;
      why = e.what();
    } catch (...) {
      outcome = PushTarget::Outcome::kFailed;
      why = "an exception of unknown type";
    }
    lock.lock();
    entry->busy = false;
    if (--in_flight_[entry->client] == 0) in_flight_.erase(entry->client);
    const std::shared_ptr<PushTarget> dropped = AccountLocked(key, *entry, outcome, why);
    if (dropped) {
      lock.unlock();
      dropped->Detach();
      lock.lock();
    }
  }
}

std::shared_ptr<PushTarget> PushPool::AccountLocked(const Key& key, Entry& entry,
                                                    PushTarget::Outcome outcome,
                                                    const std::string& why) {
  using Outcome = PushTarget::Outcome;
  const bool observer = key.first == Kind::kObserver;
  auto& log = logging::Get(observer ? "observers" : "daq");
  const auto id = static_cast<unsigned long long>(key.second);
  const auto now = Clock::now();
  if (outcome == Outcome::kNothing) {
    // subscriptions are polled (their batches come from the recorder, which tells no one)
    if (!observer) entry.retry_at = now + kPollInterval;
    return nullptr;
  }
  if (outcome == Outcome::kSent) {
    if (entry.failures > 0)
      log.info("%s %llu (client %s) answers again after %llu failed pushes",
               observer ? "observer" : "subscription", id, entry.client.c_str(),
               static_cast<unsigned long long>(entry.failures));
    entry.failures = 0;
    entry.failing_since.reset();
    return nullptr;
  }
  const bool gone = outcome == Outcome::kGone;
  if (!gone) {
    if (!entry.failing_since) entry.failing_since = now;
    if (entry.failures++ == 0)
      log.warn("%s %llu (client %s) is slow or unreachable: %s; retrying every %lld ms with the "
               "latest state",
               observer ? "observer" : "subscription", id, entry.client.c_str(), why.c_str(),
               static_cast<long long>(limits_.retry_after.count()));
    entry.retry_at = now + limits_.retry_after;
    if (now - *entry.failing_since < limits_.drop_after) return nullptr;
  }
  if (entry.removed) return nullptr;  // removed by its client meanwhile
  const std::string reason =
      gone ? why
           : "no push succeeded for " +
                 std::to_string(std::chrono::duration_cast<std::chrono::seconds>(
                                    now - *entry.failing_since)
                                    .count()) +
                 " s (last: " + why + ")";
  if (observer)
    log.info("dropping an observer (%llu, client %s): %s", id, entry.client.c_str(),
             reason.c_str());
  else
    log.info("dropping subscription %llu (client %s): %s", id, entry.client.c_str(),
             reason.c_str());
  entry.removed = true;
  std::shared_ptr<PushTarget> target = entry.target;
  entries_.erase(key);
  return target;
}

// ------------------------------------------------------------------------ observers

ObserverTarget::ObserverTarget(ModelCore& core, PushPool& pool, S::SceneObserver_ptr observer)
    : core_(core), pool_(pool), observer_(S::SceneObserver::_duplicate(observer)) {
  omniORB::setClientCallTimeout(observer_.in(),
                                static_cast<CORBA::ULong>(pool.limits().call_timeout.count()));
}

void ObserverTarget::MarkPending() {
  if (!pending_.exchange(true)) pool_.Wake();
}

void ObserverTarget::OnScene(std::shared_ptr<const sgal::Scene> scene, uint64_t generation) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scene_ = std::move(scene);
    scene_generation_ = generation;
    snapshot_.reset();
  }
  MarkPending();
}

void ObserverTarget::OnSnapshot(std::shared_ptr<const Snapshot> snapshot) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_ = std::move(snapshot);
  }
  MarkPending();
}

void ObserverTarget::OnCleared() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cleared_ = true;
    scene_.reset();
    snapshot_.reset();
  }
  MarkPending();
}

PushTarget::Outcome ObserverTarget::Push(std::string* why) {
  pending_ = false;  // what arrives from now on marks it again
  bool cleared;
  std::shared_ptr<const sgal::Scene> scene;
  uint64_t scene_generation;
  std::shared_ptr<const Snapshot> snapshot;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cleared = cleared_;
    cleared_ = false;
    scene = std::move(scene_);
    scene_.reset();
    scene_generation = scene_generation_;
    snapshot = std::move(snapshot_);
    snapshot_.reset();
  }
  if (!cleared && !scene && !snapshot) return Outcome::kNothing;
  enum { kClearing, kDescribing, kMoving } stage = kClearing;
  try {
    if (cleared) observer_->on_scene_cleared();
    stage = kDescribing;
    if (scene) {
      std::unique_ptr<S::Description> description(ToIdl(*scene));
      observer_->on_scene(*description);
      generation_ = scene_generation;
      filter_ = sgal::ChangeFilter();
    }
    stage = kMoving;
    if (snapshot && snapshot->generation == generation_) {
      const std::vector<int> changed = filter_.Changed(snapshot->bodies);
      S::BodyTransformSeq transforms;
      transforms.length(static_cast<CORBA::ULong>(changed.size()));
      for (CORBA::ULong i = 0; i < changed.size(); ++i) {
        transforms[i].body_index = static_cast<CORBA::ULong>(changed[i]);
        transforms[i].pose = ToFrame(snapshot->bodies[changed[i]].pose);
      }
      observer_->on_transforms(++update_, snapshot->time, transforms, ToIdl(snapshot->tendons));
    }
    return Outcome::kSent;
  } catch (const CORBA::Exception& e) {
    *why = rtc::Describe(e);
    if (PeerGone(e, observer_.in())) return Outcome::kGone;
    // the backlog goes, the observer stays: what did not arrive is sent again unless something
    // newer replaced it, and the next transforms carry every body
    filter_ = sgal::ChangeFilter();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const bool newer = cleared_ || scene_;
      if (stage == kClearing) cleared_ = true;
      if (!newer && stage <= kDescribing && scene) {
        scene_ = std::move(scene);
        scene_generation_ = scene_generation;
      }
      if (!newer && !snapshot_) snapshot_ = std::move(snapshot);
    }
    pending_ = true;
    return Outcome::kFailed;
  }
}

// ------------------------------------------------------------------------ subscriptions

SubscriptionTarget::SubscriptionTarget(ModelCore& core, uint64_t subscription,
                                       D::DataConsumer_ptr consumer, bool lossless)
    : core_(core),
      subscription_(subscription),
      consumer_(D::DataConsumer::_duplicate(consumer)),
      lossless_(lossless) {}

PushTarget::Outcome SubscriptionTarget::Push(std::string* why) {
  bool gone = false;
  uint64_t queue_dropped = 0;
  const auto batches = core_.TakeBatches(subscription_, &gone, &queue_dropped);
  if (gone) {
    *why = "the Model ended the subscription (the reason is logged above)";
    return Outcome::kGone;
  }
  // a real-time run does not wait for a slow consumer: say what it lost, every 10 s at most
  const auto now = std::chrono::steady_clock::now();
  if (queue_dropped > queue_dropped_ && now - queue_logged_ >= std::chrono::seconds(10)) {
    logging::Get("daq").warn(
        "%ssubscription %llu: %llu samples dropped so far (its queue was full: the consumer is "
        "slower than the simulation runs%s)",
        lossless_ ? "lossless " : "", static_cast<unsigned long long>(subscription_),
        static_cast<unsigned long long>(queue_dropped),
        lossless_ ? "; the Model waits for it only in lock-step or as fast as possible" : "");
    queue_dropped_ = queue_dropped;
    queue_logged_ = now;
  }
  if (batches.empty()) return Outcome::kNothing;
  for (size_t k = 0; k < batches.size(); ++k) {
    const daq::Batch& b = batches[k];
    D::SampleBatch out;
    out.subscription = subscription_;
    out.batch = b.sequence;
    out.first_step = b.first_step;
    out.layout = b.layout;
    out.times.length(static_cast<CORBA::ULong>(b.times.size()));
    for (CORBA::ULong i = 0; i < b.times.size(); ++i) out.times[i] = b.times[i];
    out.values_per_sample = static_cast<CORBA::ULong>(b.values_per_sample);
    out.data.length(static_cast<CORBA::ULong>(b.data.size()));
    for (CORBA::ULong i = 0; i < b.data.size(); ++i) out.data[i] = b.data[i];
    const std::vector<std::string> stale = b.StaleIds();
    out.stale_ids.length(static_cast<CORBA::ULong>(stale.size()));
    for (CORBA::ULong i = 0; i < stale.size(); ++i) out.stale_ids[i] = stale[i].c_str();
    try {
      consumer_->on_samples(out);
    } catch (const CORBA::Exception& e) {
      // this batch and the rest of the backlog go; the consumer sees the gap in `batch`
      uint64_t samples = 0;
      for (size_t j = k; j < batches.size(); ++j) samples += batches[j].step_count;
      dropped_ += batches.size() - k;
      core_.NoteUndelivered(subscription_, batches.size() - k, samples);
      *why = rtc::Describe(e) + " (" + std::to_string(dropped_) + " batches dropped so far)";
      if (lossless_)
        *why = "a push failed: " + *why + "; a lossless subscription ends at its first failed push";
      last_failure_ = *why;
      return PeerGone(e, consumer_.in()) || lossless_ ? Outcome::kGone : Outcome::kFailed;
    }
  }
  last_failure_.clear();
  return Outcome::kSent;
}

// ------------------------------------------------------------------------ servant


}  // namespace caliper::model
