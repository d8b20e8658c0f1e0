#include "logger_servant.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "caliper/logging/log.h"
#include "caliper/logging/message_pattern.h"
#include "caliper/rtc/log_service_sink.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/peers.h"

namespace caliper::logger {

namespace idl = ::Caliper::Logging;

namespace {

const StoredRecord& Ref(const StoredRecord& s) { return s; }
const StoredRecord& Ref(const std::shared_ptr<const StoredRecord>& s) { return *s; }

/// Query answers (records) and pushes (shared records) alike.
template <typename Records>
idl::StoredRecordSeq* ToIdl(const Records& records) {
  auto* out = new idl::StoredRecordSeq;
  out->length(static_cast<CORBA::ULong>(records.size()));
  for (CORBA::ULong i = 0; i < records.size(); ++i) {
    (*out)[i].serial = Ref(records[i]).serial;
    (*out)[i].rec = rtc::ToIdl(Ref(records[i]).record);
  }
  return out;
}

/// What a queued record costs a listener's queue [bytes].
size_t Bytes(const StoredRecord& s) {
  const auto& r = s.record;
  return sizeof(StoredRecord) + r.message.size() + r.category.size() + r.component.size() +
         r.host.size() + r.source.size();
}

}  // namespace

ListenerHub::~ListenerHub() {
  std::map<uint64_t, std::unique_ptr<Listener>> listeners;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, l] : listeners_) l->stop = true;
    listeners.swap(listeners_);
  }
  wake_.notify_all();
  for (auto& [id, l] : listeners) l->thread.join();
}

std::vector<std::unique_ptr<ListenerHub::Listener>> ListenerHub::TakeDead() {
  std::vector<std::unique_ptr<Listener>> dead;
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = listeners_.begin(); it != listeners_.end();) {
    if (it->second->dead) {
      dead.push_back(std::move(it->second));
      it = listeners_.erase(it);
    } else {
      ++it;
    }
  }
  return dead;
}

uint64_t ListenerHub::Add(idl::LogListener_ptr ref) {
  if (CORBA::is_nil(ref)) throw CORBA::BAD_PARAM(0, CORBA::COMPLETED_NO);
  // the places of dropped listeners are free again; their threads have ended
  for (auto& dead : TakeDead()) dead->thread.join();
  const std::string client = rtc::ClientOf(ref);
  std::lock_guard<std::mutex> lock(mutex_);
  if (listeners_.size() >= kMaxListeners)
    throw idl::LimitExceeded(
        ("already " + std::to_string(listeners_.size()) + " log listeners, at most " +
         std::to_string(kMaxListeners) + "; remove_listener frees a place")
            .c_str(),
        kMaxListeners);
  const auto of_client = std::count_if(listeners_.begin(), listeners_.end(),
                                       [&](const auto& l) { return l.second->client == client; });
  if (static_cast<size_t>(of_client) >= kMaxListenersPerClient)
    throw idl::LimitExceeded(("the client at " + client + " has " + std::to_string(of_client) +
                              " log listeners already, at most " +
                              std::to_string(kMaxListenersPerClient) + " per client")
                                 .c_str(),
                             kMaxListenersPerClient);
  const uint64_t id = next_id_++;
  auto listener = std::make_unique<Listener>();
  listener->ref = idl::LogListener::_duplicate(ref);
  listener->client = client;
  Listener* raw = listener.get();
  listener->thread = std::thread([this, raw] { Run(raw); });
  listeners_[id] = std::move(listener);
  return id;
}

void ListenerHub::Remove(uint64_t id) {
  std::unique_ptr<Listener> listener;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = listeners_.find(id);
    if (it == listeners_.end()) return;
    listener = std::move(it->second);
    listeners_.erase(it);
    listener->stop = true;
  }
  wake_.notify_all();
  listener->thread.join();
}

size_t ListenerHub::size() {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t live = 0;
  for (const auto& [id, l] : listeners_) live += l->dead ? 0 : 1;
  return live;
}

void ListenerHub::Publish(const std::vector<StoredRecord>& records) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Shared> shared;
  for (auto& [id, l] : listeners_) {
    if (l->dead) continue;
    // one copy of each record, whatever the number of listeners
    if (shared.empty())
      for (const auto& s : records) shared.push_back(std::make_shared<const StoredRecord>(s));
    for (const auto& s : shared) {
      l->queue.push_back(s);
      l->queued_bytes += Bytes(*s);
    }
    // a listener that falls this far behind loses its oldest records, never the logger's memory
    while (l->queue.size() > kMaxQueueRecords || l->queued_bytes > kMaxQueueBytes) {
      l->queued_bytes -= Bytes(*l->queue.front());
      l->queue.pop_front();
    }
  }
  wake_.notify_all();
}

void ListenerHub::Run(Listener* l) {
  auto& log = logging::Get("listeners");
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return l->stop || !l->queue.empty(); });
    if (l->stop) return;
    std::vector<Shared> batch;
    size_t bytes = 0;
    while (!l->queue.empty() &&
           (batch.empty() || bytes + Bytes(*l->queue.front()) <= kMaxPushBytes)) {
      const size_t b = Bytes(*l->queue.front());
      bytes += b;
      l->queued_bytes -= b;
      batch.push_back(std::move(l->queue.front()));
      l->queue.pop_front();
    }
    lock.unlock();
    bool timed_out = false;
    std::string failure;
    try {
      std::unique_ptr<idl::StoredRecordSeq> seq(ToIdl(batch));
      l->ref->on_records(*seq);
    } catch (const CORBA::TIMEOUT& e) {
      timed_out = true;
      failure = rtc::Describe(e);
    } catch (const CORBA::Exception& e) {
      failure = rtc::Describe(e);
    }
    lock.lock();
    if (failure.empty()) {
      l->timeouts = 0;
      continue;
    }
    if (timed_out && ++l->timeouts < kMaxTimeouts) {
      // slow, not gone: what waited for it is dropped, the listener stays
      const size_t dropped = l->queue.size();
      l->queue.clear();
      l->queued_bytes = 0;
      lock.unlock();
      log.warn("a log listener did not answer in time (%s): %zu waiting records dropped",
               failure.c_str(), dropped + batch.size());
      lock.lock();
      continue;
    }
    // gone (or stopped for kMaxTimeouts pushes): its place is freed by the next Add or Remove
    l->queue.clear();
    l->queued_bytes = 0;
    l->dead = true;
    lock.unlock();
    log.info("dropping a log listener: %s", failure.c_str());
    return;
  }
}

LoggerServant::LoggerServant(rtc::Runtime& runtime, LoggerComponent& component)
    : rtc::RTObjectServant(runtime), component_(component) {
  component_.SetListener(
      [this](const std::vector<StoredRecord>& records) { hub_.Publish(records); });
}

LoggerServant::~LoggerServant() { component_.SetListener(nullptr); }

CORBA::ULong LoggerServant::submit(const idl::RecordSeq& records) {
  std::vector<logging::Record> batch;
  batch.reserve(records.length());
  for (CORBA::ULong i = 0; i < records.length(); ++i) batch.push_back(rtc::FromIdl(records[i]));
  try {
    return static_cast<CORBA::ULong>(component_.Submit(batch).size());
  } catch (const std::exception& e) {
    throw idl::NotAvailable(e.what());
  }
}

idl::StoredRecordSeq* LoggerServant::query(const idl::RecordFilter& q) {
  QueryFilter f;
  f.max_priority = q.max_priority;
  f.category_prefix = q.category_prefix.in();
  f.component = q.instance.in();
  f.regex = q.regex.in();
  f.from_time_us = q.from_time_us;
  f.to_time_us = q.to_time_us;
  f.after_serial = q.after_serial;
  f.limit = q.limit;
  try {
    return ToIdl(component_.Query(f));
  } catch (const logging::PatternError& e) {
    throw idl::InvalidQuery(e.what());
  } catch (const std::exception& e) {
    logging::Get("query").error("query failed: %s", e.what());
    throw CORBA::INTERNAL(0, CORBA::COMPLETED_NO);
  }
}

char* LoggerServant::session_file() { return CORBA::string_dup(component_.session_file().c_str()); }

CORBA::ULongLong LoggerServant::add_listener(idl::LogListener_ptr listener) {
  if (CORBA::is_nil(listener)) throw idl::NotAvailable("the listener is nil");
  // a reference to nothing would hold a place until its pushes had failed for long: refuse it
  // now (the check leaves the reference with the pushes' own timeout, corba.call_timeout)
  const auto timeout = std::chrono::milliseconds(
      static_cast<long>(runtime_.config().GetDouble("corba.call_timeout") * 1000));
  const std::string why =
      rtc::Unreachable(listener, "LogListener", idl::LogListener::_PD_repoId, timeout);
  if (!why.empty()) throw idl::NotAvailable(why.c_str());
  const uint64_t id = hub_.Add(listener);
  logging::Get("listeners").info("log listener %llu added (client %s)",
                                 static_cast<unsigned long long>(id),
                                 rtc::ClientOf(listener).c_str());
  return id;
}

void LoggerServant::remove_listener(CORBA::ULongLong id) { hub_.Remove(id); }

}  // namespace caliper::logger
