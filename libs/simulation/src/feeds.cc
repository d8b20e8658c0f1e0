#include "caliper/simulation/feeds.h"

#include <algorithm>

#include "caliper/logging/log.h"

namespace caliper::simulation {

using Clock = std::chrono::steady_clock;

Feeds::Feeds(const daq::Registry& registry, const Limits& limits)
    : registry_(registry), limits_(limits), recorder_(registry) {}

uint64_t Feeds::Subscribe(const std::vector<std::string>& ids, uint32_t every_n_steps,
                          size_t batch_steps, std::chrono::milliseconds lossless_wait) {
  if (every_n_steps == 0) throw InvalidValue("every_n_steps must be at least 1");
  if (ids.empty()) throw InvalidValue("subscribe to at least one id");
  if (ids.size() > limits_.ids_per_call)
    throw LimitExceeded(std::to_string(ids.size()) + " ids in one subscription; at most " +
                        std::to_string(limits_.ids_per_call), limits_.ids_per_call);
  // every subscribed value is read at every sampled step with the lock held: bound them all
  size_t values = 0;
  for (const auto& id : ids) {
    if (!registry_.Contains(id)) throw UnknownId("unknown id '" + id + "'", id);
    values += registry_.Info(id).shape.size();
  }
  if (subscribed_values_ + values > limits_.subscribed_values)
    throw LimitExceeded("subscribing " + std::to_string(values) + " values to the " +
                        std::to_string(subscribed_values_) + " subscribed already: at most " +
                        std::to_string(limits_.subscribed_values) +
                        " values in all subscriptions together",
                        limits_.subscribed_values);
  daq::SubscriptionOptions options;
  options.ids = ids;
  options.every_n_steps = every_n_steps;
  options.batch_steps = std::max<size_t>(1, batch_steps);
  // the batches waiting for slow consumers stay within Limits::queued_bytes in all (each queue
  // gets the share of a subscription holding every value allowed)
  const double batch_bytes =
      8.0 * static_cast<double>(limits_.subscribed_values) * options.batch_steps;
  options.queue_capacity = static_cast<size_t>(
      std::clamp(static_cast<double>(limits_.queued_bytes) / batch_bytes, 2.0, 64.0));
  try {
    const uint64_t id = recorder_.Subscribe(options);
    subscribed_values_ += values;
    Feed& feed = feeds_[id];
    feed.capacity = options.queue_capacity;
    feed.values = values;
    if (lossless_wait.count() > 0) {
      feed.lossless_wait = lossless_wait;
      ++lossless_;
    }
    return id;
  } catch (const daq::UnknownId& e) {
    throw UnknownId(e.what(), e.id());
  } catch (const std::invalid_argument& e) {
    throw InvalidValue(e.what());
  }
}

void Feeds::Unsubscribe(uint64_t subscription, const std::string& reason) {
  const auto feed = feeds_.find(subscription);
  if (feed == feeds_.end()) return;  // already gone
  const std::string kind = feed->second.lossless_wait.count() > 0 ? "lossless " : "";
  try {
    const daq::SubscriptionStats stats = recorder_.Stats(subscription);
    uint64_t unsent = 0;  // queued, and the partial batch
    for (const daq::Batch& b : recorder_.Unsubscribe(subscription)) unsent += b.step_count;
    const uint64_t dropped = stats.dropped_samples + feed->second.undelivered_samples;
    auto& log = logging::Get("daq");
    if (!reason.empty())
      log.warn("%ssubscription %llu ended by the Model after %llu samples (%llu never sent): %s",
               kind.c_str(), static_cast<unsigned long long>(subscription),
               static_cast<unsigned long long>(stats.samples),
               static_cast<unsigned long long>(dropped + unsent), reason.c_str());
    else if (dropped > 0)
      log.notice("%ssubscription %llu ended: %llu samples taken, %llu of them dropped (the "
                 "consumer was slower than the simulation ran)",
                 kind.c_str(), static_cast<unsigned long long>(subscription),
                 static_cast<unsigned long long>(stats.samples),
                 static_cast<unsigned long long>(dropped));
  } catch (const daq::UnknownId&) {
    // already gone
  }
  if (feed->second.lossless_wait.count() > 0) --lossless_;
  subscribed_values_ -= feed->second.values;
  feeds_.erase(feed);
  if (!reason.empty()) {
    ended_[subscription] = reason;
    if (ended_.size() > 64) ended_.erase(ended_.begin());
  }
}

FeedStatus Feeds::Status(uint64_t subscription) const {
  const auto feed = feeds_.find(subscription);
  if (feed == feeds_.end()) {
    const auto ended = ended_.find(subscription);
    const std::string id = std::to_string(subscription);
    throw UnknownId(ended != ended_.end()
                        ? "subscription " + id + " was ended by the Model: " + ended->second
                        : "no subscription " + id,
                    id);
  }
  const daq::SubscriptionStats stats = recorder_.Stats(subscription);
  FeedStatus out;
  out.lossless = feed->second.lossless_wait.count() > 0;
  out.samples = stats.samples;
  out.batches = stats.batches;
  out.dropped_batches = stats.dropped + feed->second.undelivered_batches;
  out.dropped_samples = stats.dropped_samples + feed->second.undelivered_samples;
  out.queued = stats.queued;
  out.waited_s = feed->second.waited_s;
  return out;
}

void Feeds::NoteUndelivered(uint64_t subscription, uint64_t batches, uint64_t samples) {
  const auto feed = feeds_.find(subscription);
  if (feed == feeds_.end()) return;
  feed->second.undelivered_batches += batches;
  feed->second.undelivered_samples += samples;
}

void Feeds::SetConsumerWake(std::function<void(uint64_t)> wake) {
  consumer_wake_ = std::move(wake);
}

void Feeds::OnStep(uint64_t step, double time) { recorder_.OnStep(step, time); }

bool Feeds::Flush(uint64_t subscription) {
  try {
    const uint64_t before = recorder_.Stats(subscription).batches;
    recorder_.Flush(subscription);
    return recorder_.Stats(subscription).batches != before;
  } catch (const daq::UnknownId&) {
    return false;
  }
}

void Feeds::NotifyRoom() {
  {
    std::lock_guard<std::mutex> room(room_mutex_);
    ++room_events_;
  }
  room_.notify_all();
}

uint64_t Feeds::Blocked() const {
  for (const auto& [id, feed] : feeds_) {
    if (feed.lossless_wait.count() == 0) continue;
    // one step queues at most two batches (one on a layout change, one full)
    if (recorder_.Stats(id).queued + 2 > feed.capacity) return id;
  }
  return 0;
}

bool Feeds::AwaitRoom(std::unique_lock<std::mutex>& lock,
                      const std::function<bool()>& interrupted) {
  if (lossless_ == 0) return false;
  bool released = false;
  uint64_t waiting_for = 0;  // the subscription waited for now (0: none yet)
  Clock::time_point since;
  for (;;) {
    // read before looking at the queues: a take after the look changes it
    uint64_t seen;
    {
      std::lock_guard<std::mutex> room(room_mutex_);
      seen = room_events_;
    }
    const uint64_t blocked = Blocked();
    if (blocked == 0) return released;
    Feed& feed = feeds_[blocked];
    const auto now = Clock::now();
    if (blocked != waiting_for) {
      waiting_for = blocked;
      since = now;
      if (consumer_wake_) consumer_wake_(blocked);
    }
    const auto deadline = since + feed.lossless_wait;
    if (now >= deadline) {
      Unsubscribe(blocked, "its consumer took no batch for " +
                               std::to_string(feed.lossless_wait.count()) +
                               " ms while the simulation waited for it (lossless); the Model "
                               "goes on without it");
      waiting_for = 0;
      continue;
    }
    lock.unlock();
    released = true;
    {
      std::unique_lock<std::mutex> room(room_mutex_);
      room_.wait_until(room, deadline, [&] { return room_events_ != seen; });
    }
    lock.lock();
    const auto it = feeds_.find(blocked);
    if (it != feeds_.end())
      it->second.waited_s += std::chrono::duration<double>(Clock::now() - now).count();
    if (interrupted()) return true;
  }
}

std::vector<daq::Batch> Feeds::TakeBatches(uint64_t subscription, bool* gone,
                                           uint64_t* dropped_samples) {
  if (gone != nullptr) *gone = false;
  try {
    std::vector<daq::Batch> batches = recorder_.TakeBatches(subscription);
    if (!batches.empty()) NotifyRoom();
    if (dropped_samples != nullptr)
      *dropped_samples = recorder_.Stats(subscription).dropped_samples;
    return batches;
  } catch (const daq::UnknownId&) {
    if (gone != nullptr) *gone = true;
    return {};
  }
}

bool Feeds::WaitForBatches(uint64_t subscription, std::chrono::milliseconds timeout) {
  try {
    return recorder_.WaitForBatches(subscription, timeout);
  } catch (const daq::UnknownId&) {
    return false;
  }
}

}  // namespace caliper::simulation
