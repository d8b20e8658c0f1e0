#pragma once
// CORBA adapter of the Logging component: converts, forwards, and pushes new records to listeners.

#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "caliper/logging.hh"
#include "caliper/rtc/rtobject_servant.h"
#include "logger_component.h"

namespace caliper::logger {

/// One sender thread per listener, so that a slow listener delays nobody else; a listener that is
/// gone (TRANSIENT, COMM_FAILURE, OBJECT_NOT_EXIST) is dropped.
class ListenerHub {
 public:
  ~ListenerHub();
  uint64_t Add(Caliper::Logging::LogListener_ptr listener);
  void Remove(uint64_t id);
  void Publish(const std::vector<StoredRecord>& records);

 private:
  struct Listener {
    Caliper::Logging::LogListener_var ref;
    std::deque<StoredRecord> queue;
    bool stop = false;
    bool dead = false;  ///< its peer is gone; nothing more is queued for it
    std::thread thread;
  };
  void Run(Listener* listener);

  std::mutex mutex_;
  std::condition_variable wake_;
  std::map<uint64_t, std::unique_ptr<Listener>> listeners_;
  uint64_t next_id_ = 1;
};

class LoggerServant : public virtual POA_Caliper::Logging::Logger, public rtc::RTObjectServant {
 public:
  LoggerServant(rtc::Runtime& runtime, LoggerComponent& component);
  ~LoggerServant() override;

  CORBA::ULong submit(const Caliper::Logging::RecordSeq& records) override;
  Caliper::Logging::StoredRecordSeq* query(const Caliper::Logging::RecordFilter& q) override;
  char* session_file() override;
  CORBA::ULongLong add_listener(Caliper::Logging::LogListener_ptr listener) override;
  void remove_listener(CORBA::ULongLong id) override;

 private:
  LoggerComponent& component_;
  ListenerHub hub_;
};

}  // namespace caliper::logger
