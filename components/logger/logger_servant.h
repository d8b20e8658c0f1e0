#pragma once
// CORBA adapter of the Logging component: converts, forwards, and pushes new records to listeners.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "caliper/logging.hh"
#include "caliper/rtc/rtobject_servant.h"
#include "logger_component.h"

namespace caliper::logger {

/// Pushes newly stored records to the registered listeners, one sender thread per listener (at
/// most kMaxListeners), so that a slow or stopped listener delays nobody else: submit only
/// queues. A push waits at most the ORB's call timeout (`corba.call_timeout`). A push that times
/// out costs that listener its backlog; kMaxTimeouts in a row, or any other failure (TRANSIENT,
/// COMM_FAILURE, OBJECT_NOT_EXIST, ...), drop the listener and free its place. What waits for
/// one listener is bounded (kMaxQueueRecords, kMaxQueueBytes, the oldest going first): it sees
/// a gap in the serials and can query it.
class ListenerHub {
 public:
  static constexpr size_t kMaxListeners = 64;
  /// Listeners of one client process (rtc::ClientOf: the endpoint serving the reference).
  static constexpr size_t kMaxListenersPerClient = 8;
  static constexpr size_t kMaxQueueRecords = 100000;
  static constexpr size_t kMaxQueueBytes = 64u << 20;
  /// One push carries at most about this much [bytes] (at least one record).
  static constexpr size_t kMaxPushBytes = 1u << 20;
  static constexpr int kMaxTimeouts = 12;

  ~ListenerHub();
  /// Registers a listener; throws Caliper::Logging::LimitExceeded when kMaxListeners are
  /// registered, or kMaxListenersPerClient of the same client, CORBA::BAD_PARAM for a nil
  /// reference.
  uint64_t Add(Caliper::Logging::LogListener_ptr listener);
  void Remove(uint64_t id);
  void Publish(const std::vector<StoredRecord>& records);
  /// Listeners registered and not dropped.
  size_t size();

 private:
  using Shared = std::shared_ptr<const StoredRecord>;
  struct Listener {
    Caliper::Logging::LogListener_var ref;
    std::string client;  ///< rtc::ClientOf(ref)
    std::deque<Shared> queue;
    size_t queued_bytes = 0;
    int timeouts = 0;  ///< pushes timed out in a row
    bool stop = false;
    bool dead = false;  ///< dropped: its thread has ended, nothing more is queued for it
    std::thread thread;
  };
  void Run(Listener* listener);
  /// Takes the dropped listeners out of the map (the caller joins their threads).
  std::vector<std::unique_ptr<Listener>> TakeDead();

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
