#include "caliper/daq/recorder.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace caliper::daq {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

std::vector<double> Batch::Values(size_t column) const {
  const Column& c = columns->at(column);
  const size_t n = c.shape.size();
  std::vector<double> out(step_count * n);
  for (size_t k = 0; k < step_count; ++k)
    std::copy_n(data.begin() + k * values_per_sample + c.offset, n, out.begin() + k * n);
  return out;
}

std::vector<double> Batch::Values(const std::string& id) const {
  for (size_t i = 0; i < columns->size(); ++i)
    if ((*columns)[i].id == id) return Values(i);
  throw UnknownId(id);
}

std::vector<std::string> Batch::StaleIds() const {
  std::vector<std::string> out;
  for (const auto& c : *columns)
    if (c.stale) out.push_back(c.id);
  return out;
}

/// The bounded hand-over between the simulation thread and a subscriber's sender.
struct Recorder::Queue {
  Queue(size_t capacity_, Consumer consumer_)
      : capacity(capacity_), consumer(std::move(consumer_)) {}

  /// Appends, dropping the oldest batch when full; never waits for a consumer.
  void Push(Batch&& batch) {
    Batch old;  // freed after the lock is released
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (batches.size() >= capacity) {
        dropped_samples += batches.front().step_count;
        old = std::move(batches.front());
        batches.pop_front();
        ++dropped;
        KeepLocked(old);
      }
      batches.push_back(std::move(batch));
    }
    ready.notify_one();
  }
  /// Keeps a batch that was handed out or dropped as the spare whose memory the next batch
  /// reuses, when there is none yet.
  void Recycle(Batch&& batch) {
    std::lock_guard<std::mutex> lock(mutex);
    KeepLocked(batch);
  }
  /// Moves the spare's buffers (emptied, capacity kept) into `batch`; false when there is none.
  /// Called once per batch, not per sample.
  bool TakeSpare(Batch* batch) {
    std::lock_guard<std::mutex> lock(mutex);
    if (spare.data.capacity() == 0) return false;
    batch->data = std::move(spare.data);
    batch->times = std::move(spare.times);
    spare = Batch();
    batch->data.clear();
    batch->times.clear();
    return true;
  }
  std::vector<Batch> Take(size_t max) {
    std::vector<Batch> out;
    std::lock_guard<std::mutex> lock(mutex);
    while (!batches.empty() && out.size() < max) {
      out.push_back(std::move(batches.front()));
      batches.pop_front();
    }
    return out;
  }
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      closed = true;
    }
    ready.notify_all();
  }

  const size_t capacity;
  const Consumer consumer;
  std::mutex mutex;  // guards the fields below
  std::condition_variable ready;
  std::deque<Batch> batches;
  uint64_t dropped = 0;
  uint64_t dropped_samples = 0;
  bool closed = false;
  // a batch's memory, reused: a fresh multi-megabyte batch costs a page fault per 4 KiB as the
  // samples fill it, several times the copying itself
  Batch spare;

 private:
  void KeepLocked(Batch& batch) {
    if (spare.data.capacity() != 0 || batch.data.capacity() == 0) return;
    spare.data = std::move(batch.data);
    spare.times = std::move(batch.times);
  }
};

namespace {

/// One part of filling a sample, in column order. Resolved whenever the registry changes, so
/// that a sample does no lookup, and no call per channel for channels read in place: neighbouring
/// columns whose values lie next to each other in one block are copied in one go.
struct Op {
  enum Kind : uint8_t { kCopy, kGet, kNaN };
  Kind kind = kNaN;
  uint32_t column = 0;             // the (first) column it fills, for error messages
  uint32_t block = 0;              // kCopy: index into Subscription::blocks
  size_t count = 0;                // doubles it appends
  const double* values = nullptr;  // kCopy: where they are
  const Getter* getter = nullptr;  // kGet
};

}  // namespace

/// The simulation-thread state of one subscription.
struct Recorder::Subscription {
  SubscriptionId id = 0;
  std::vector<std::string> ids;
  uint64_t every_n_steps = 1;
  size_t batch_steps = 1;
  std::vector<Handle> handles;  // per column; meaningless for stale columns
  // how to fill a sample: valid only while the registry's version is the one they were
  // resolved at (OnStep re-resolves first when it changed)
  std::vector<Op> ops;
  std::vector<SourceBlock*> blocks;       // distinct blocks of the kCopy ops, updated per sample
  std::vector<std::string> block_errors;  // per block: why its update failed this sample, or ""
  std::shared_ptr<const std::vector<Column>> columns;
  size_t values_per_sample = 0;
  bool started = false;    // has taken a sample
  uint64_t last_step = 0;  // of the last sample
  uint64_t sequence = 0;   // of the last batch
  uint64_t layout = 1;     // grows whenever the columns change shape, unit or staleness
  uint64_t samples = 0;
  std::string last_error;
  Batch pending;  // the batch being filled (step_count 0 when none)
  std::shared_ptr<Queue> queue;
};

Recorder::Recorder(const Registry& registry)
    : registry_(registry), registry_version_(registry.version()) {}

Recorder::~Recorder() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, s] : subscriptions_) s->queue->Close();
}

SubscriptionId Recorder::Subscribe(SubscriptionOptions options) {
  if (options.ids.empty()) throw std::invalid_argument("subscription without ids");
  if (options.every_n_steps == 0) throw std::invalid_argument("every_n_steps must be at least 1");
  if (options.batch_steps == 0) throw std::invalid_argument("batch_steps must be at least 1");
  if (options.queue_capacity == 0) throw std::invalid_argument("queue_capacity must be at least 1");
  for (const auto& id : options.ids)
    if (!registry_.Contains(id)) throw UnknownId(id);

  auto s = std::make_unique<Subscription>();
  s->ids = std::move(options.ids);
  s->every_n_steps = options.every_n_steps;
  s->batch_steps = options.batch_steps;
  s->queue = std::make_shared<Queue>(options.queue_capacity, std::move(options.consumer));
  std::lock_guard<std::mutex> lock(mutex_);
  s->id = next_id_++;
  Resolve(*s, true);
  const SubscriptionId id = s->id;
  subscriptions_.emplace(id, std::move(s));
  return id;
}

std::vector<Batch> Recorder::Unsubscribe(SubscriptionId id) {
  std::unique_ptr<Subscription> s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = subscriptions_.find(id);
    if (it == subscriptions_.end()) throw UnknownId(std::to_string(id), "subscription");
    s = std::move(it->second);
    subscriptions_.erase(it);
  }
  Emit(*s);
  auto rest = s->queue->Take(SIZE_MAX);
  s->queue->Close();
  return rest;
}

void Recorder::Resolve(Subscription& s, bool initial) {
  auto columns = std::make_shared<std::vector<Column>>(s.ids.size());
  s.handles.resize(s.ids.size());
  size_t offset = 0;
  for (size_t i = 0; i < s.ids.size(); ++i) {
    Column& c = (*columns)[i];
    c.id = s.ids[i];
    if (registry_.TryResolve(c.id, &s.handles[i])) {
      const ChannelInfo& info = registry_.Info(s.handles[i]);
      c.unit = info.unit;
      c.shape = info.shape;
    } else {
      // keep the last known layout so that the columns stay where they were
      c.stale = true;
      if (!initial) {
        c.unit = (*s.columns)[i].unit;
        c.shape = (*s.columns)[i].shape;
      }
    }
    c.offset = offset;
    offset += c.shape.size();
  }
  bool same = !initial;
  for (size_t i = 0; i < columns->size() && same; ++i) {
    const Column &a = (*columns)[i], &b = (*s.columns)[i];
    same = a.unit == b.unit && a.shape == b.shape && a.stale == b.stale;
  }
  if (!same) {
    // a batch has one layout: hand out what was sampled with the old one
    if (!initial) {
      Emit(s);
      ++s.layout;
    }
    s.columns = std::move(columns);
    s.values_per_sample = offset;
  }
  Plan(s);
}

void Recorder::Plan(Subscription& s) {
  s.ops.clear();
  s.blocks.clear();
  const std::vector<Column>& columns = *s.columns;
  for (size_t i = 0; i < columns.size(); ++i) {
    Op op;
    op.column = static_cast<uint32_t>(i);
    op.count = columns[i].shape.size();
    if (!columns[i].stale) {
      const Access a = registry_.Resolved(s.handles[i]);
      if (a.block) {
        op.kind = Op::kCopy;
        op.values = a.values;
        const auto it = std::find(s.blocks.begin(), s.blocks.end(), a.block);
        op.block = static_cast<uint32_t>(it - s.blocks.begin());
        if (it == s.blocks.end()) s.blocks.push_back(a.block);
      } else {
        op.kind = Op::kGet;
        op.getter = a.getter;
      }
    }
    if (!s.ops.empty()) {
      Op& last = s.ops.back();
      const bool adjacent_copy = op.kind == Op::kCopy && last.kind == Op::kCopy &&
                                 last.block == op.block && last.values + last.count == op.values;
      if (adjacent_copy || (op.kind == Op::kNaN && last.kind == Op::kNaN)) {
        last.count += op.count;
        continue;
      }
    }
    s.ops.push_back(op);
  }
  s.block_errors.assign(s.blocks.size(), std::string());
}

void Recorder::Sample(Subscription& s, uint64_t step, double sim_time) {
  Batch& b = s.pending;
  if (b.step_count == 0) {
    s.queue->TakeSpare(&b);
    b.subscription = s.id;
    b.first_step = step;
    b.every_n_steps = s.every_n_steps;
    b.columns = s.columns;
    b.layout = s.layout;
    b.values_per_sample = s.values_per_sample;
    b.times.reserve(s.batch_steps);
    b.data.reserve(s.batch_steps * s.values_per_sample);
  }
  b.times.push_back(sim_time);
  bool block_failed = false;
  for (size_t k = 0; k < s.blocks.size(); ++k) {
    try {
      s.blocks[k]->Update();
      if (!s.block_errors[k].empty()) s.block_errors[k].clear();
    } catch (const std::exception& e) {
      s.block_errors[k] = e.what();
      block_failed = true;
    }
  }
  // appended op by op (the capacity was reserved for the batch): no zero-fill before the copy
  std::vector<double>& data = b.data;
  const std::vector<Column>& columns = *s.columns;
  for (const Op& op : s.ops) {
    switch (op.kind) {
      case Op::kCopy:
        if (block_failed && !s.block_errors[op.block].empty()) {
          data.insert(data.end(), op.count, kNaN);
          s.last_error = columns[op.column].id + ": " + s.block_errors[op.block];
        } else {
          data.insert(data.end(), op.values, op.values + op.count);
        }
        break;
      case Op::kGet: {
        const size_t at = data.size();
        data.resize(at + op.count);
        try {
          (*op.getter)(data.data() + at);
        } catch (const std::exception& e) {
          std::fill_n(data.data() + at, op.count, kNaN);
          s.last_error = columns[op.column].id + ": " + e.what();
        }
        break;
      }
      case Op::kNaN:
        data.insert(data.end(), op.count, kNaN);
        break;
    }
  }
  ++b.step_count;
  ++s.samples;
  s.started = true;
  s.last_step = step;
  if (b.step_count >= s.batch_steps) Emit(s);
}

void Recorder::Emit(Subscription& s) {
  if (s.pending.step_count == 0) return;
  s.pending.sequence = ++s.sequence;
  s.queue->Push(std::move(s.pending));
  s.pending = Batch();
}

void Recorder::OnStep(uint64_t step, double sim_time) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (registry_.version() != registry_version_) {
    registry_version_ = registry_.version();
    for (auto& [id, s] : subscriptions_) Resolve(*s, false);
  }
  for (auto& [id, sp] : subscriptions_) {
    Subscription& s = *sp;
    if (s.started) {
      const uint64_t due = s.last_step + s.every_n_steps;
      if (step < due && step > s.last_step) continue;  // not yet
      // the clock went back (reset) or a due sample was missed: start a new batch
      if (step != due) Emit(s);
    }
    Sample(s, step, sim_time);
  }
}

void Recorder::Flush() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, s] : subscriptions_) Emit(*s);
}

void Recorder::Flush(SubscriptionId id) {
  std::lock_guard<std::mutex> lock(mutex_);
  Emit(Find(id));
}

Recorder::Subscription& Recorder::Find(SubscriptionId id) {
  const auto it = subscriptions_.find(id);
  if (it == subscriptions_.end()) throw UnknownId(std::to_string(id), "subscription");
  return *it->second;
}

std::shared_ptr<Recorder::Queue> Recorder::FindQueue(SubscriptionId id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = subscriptions_.find(id);
  if (it == subscriptions_.end()) throw UnknownId(std::to_string(id), "subscription");
  return it->second->queue;
}

std::vector<Batch> Recorder::TakeBatches(SubscriptionId id, size_t max) {
  return FindQueue(id)->Take(max);
}

bool Recorder::WaitForBatches(SubscriptionId id, std::chrono::milliseconds timeout) {
  const auto queue = FindQueue(id);
  std::unique_lock<std::mutex> lock(queue->mutex);
  queue->ready.wait_for(lock, timeout, [&] { return !queue->batches.empty() || queue->closed; });
  return !queue->batches.empty() && !queue->closed;
}

size_t Recorder::Deliver(SubscriptionId id, size_t max) {
  const auto queue = FindQueue(id);
  if (!queue->consumer)
    throw std::logic_error("subscription " + std::to_string(id) + " has no consumer");
  return DeliverFrom(*queue, max);
}

size_t Recorder::DeliverFrom(Queue& queue, size_t max) {
  size_t delivered = 0;
  while (delivered < max) {
    auto one = queue.Take(1);
    if (one.empty()) break;
    queue.consumer(one.front());
    queue.Recycle(std::move(one.front()));
    ++delivered;
  }
  return delivered;
}

size_t Recorder::DeliverAll() {
  std::vector<std::shared_ptr<Queue>> queues;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, s] : subscriptions_)
      if (s->queue->consumer) queues.push_back(s->queue);
  }
  size_t delivered = 0;
  for (const auto& queue : queues) delivered += DeliverFrom(*queue, SIZE_MAX);
  return delivered;
}

SubscriptionStats Recorder::Stats(SubscriptionId id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = subscriptions_.find(id);
  if (it == subscriptions_.end()) throw UnknownId(std::to_string(id), "subscription");
  const Subscription& s = *it->second;
  SubscriptionStats out;
  out.samples = s.samples;
  out.batches = s.sequence;
  for (const auto& c : *s.columns)
    if (c.stale) out.stale.push_back(c.id);
  out.last_error = s.last_error;
  std::lock_guard<std::mutex> queue_lock(s.queue->mutex);
  out.dropped = s.queue->dropped;
  out.dropped_samples = s.queue->dropped_samples;
  out.queued = s.queue->batches.size();
  return out;
}

std::vector<SubscriptionId> Recorder::subscriptions() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SubscriptionId> out;
  for (const auto& [id, s] : subscriptions_) out.push_back(id);
  return out;
}

}  // namespace caliper::daq
