#include "logger_servant.h"

#include <regex>

#include "caliper/logging/log.h"
#include "caliper/rtc/log_service_sink.h"
#include "caliper/rtc/naming.h"

namespace caliper::logger {

namespace idl = ::Caliper::Logging;

namespace {

idl::StoredRecordSeq* ToIdl(const std::vector<StoredRecord>& records) {
  auto* out = new idl::StoredRecordSeq;
  out->length(static_cast<CORBA::ULong>(records.size()));
  for (CORBA::ULong i = 0; i < records.size(); ++i) {
    (*out)[i].serial = records[i].serial;
    (*out)[i].rec = rtc::ToIdl(records[i].record);
  }
  return out;
}

constexpr size_t kMaxListenerQueue = 100000;

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

uint64_t ListenerHub::Add(idl::LogListener_ptr ref) {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint64_t id = next_id_++;
  auto listener = std::make_unique<Listener>();
  listener->ref = idl::LogListener::_duplicate(ref);
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

void ListenerHub::Publish(const std::vector<StoredRecord>& records) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, l] : listeners_) {
    if (l->dead) continue;
    l->queue.insert(l->queue.end(), records.begin(), records.end());
    // a listener that falls this far behind loses its oldest records, never the logger's memory
    while (l->queue.size() > kMaxListenerQueue) l->queue.pop_front();
  }
  wake_.notify_all();
}

void ListenerHub::Run(Listener* l) {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return l->stop || !l->queue.empty(); });
    if (l->stop) return;
    std::vector<StoredRecord> batch(l->queue.begin(), l->queue.end());
    l->queue.clear();
    lock.unlock();
    bool gone = false;
    try {
      std::unique_ptr<idl::StoredRecordSeq> seq(ToIdl(batch));
      l->ref->on_records(*seq);
    } catch (const CORBA::Exception& e) {
      gone = true;
      logging::Get("listeners").info("dropping a log listener: %s", rtc::Describe(e).c_str());
    }
    lock.lock();
    if (gone) {
      // leave the thread parked until Remove or the destructor joins it
      l->queue.clear();
      l->dead = true;
      wake_.wait(lock, [&] { return l->stop; });
      return;
    }
  }
}

LoggerServant::LoggerServant(rtc::Runtime& runtime, LoggerComponent& component)
    : rtc::RTObjectServant(runtime), component_(component) {
  component_.SetListener([this](const std::vector<StoredRecord>& records) {
    hub_.Publish(records);
  });
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
  } catch (const std::regex_error& e) {
    throw idl::InvalidQuery(("bad regular expression '" + f.regex + "': " + e.what()).c_str());
  }
}

char* LoggerServant::session_file() {
  return CORBA::string_dup(component_.session_file().c_str());
}

CORBA::ULongLong LoggerServant::add_listener(idl::LogListener_ptr listener) {
  return hub_.Add(listener);
}

void LoggerServant::remove_listener(CORBA::ULongLong id) { hub_.Remove(id); }

}  // namespace caliper::logger
