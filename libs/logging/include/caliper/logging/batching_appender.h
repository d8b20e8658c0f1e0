#pragma once
// A log4cpp appender that numbers records, batches them to a RecordSink from its own thread, and
// spools them to a local file while the sink is unreachable, replaying them in order when it is back.
// The sink drops records it already stored by (source, seq), so a batch retried after a lost
// acknowledgement is stored once: nothing lost, nothing duplicated.

#include <log4cpp/AppenderSkeleton.hh>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "caliper/logging/record.h"

namespace caliper::logging {

/// The sink could not take a batch now (peer gone, timed out); the batch is to be retried.
class SinkUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where batches go: the Logging component over CORBA, or a session store in-process.
class RecordSink {
 public:
  virtual ~RecordSink() = default;
  /// Stores the batch in order or throws SinkUnavailable.
  virtual void Send(const std::vector<Record>& batch) = 0;
};

struct AppenderOptions {
  std::string spool_dir;               ///< where spool files live; created when needed
  std::string spool_name;              ///< file stem, `<instance>-<pid>`; the pid marks orphans
  size_t max_batch = 500;              ///< records per Send
  std::chrono::milliseconds flush_interval{20};   ///< longest a record waits to be batched
  std::chrono::milliseconds retry_interval{300};  ///< wait between attempts on an unreachable sink
  bool replay_orphans = true;          ///< also replay spools left by processes that died
  /// the own spool file's bound [bytes]: records that do not fit are dropped and counted, and a
  /// warning record saying how many goes to the sink once the spool is delivered
  uint64_t max_spool_bytes = uint64_t{64} << 20;
};

class BatchingAppender : public log4cpp::AppenderSkeleton {
 public:
  struct Stats {
    uint64_t appended = 0;  ///< records handed to the appender
    uint64_t sent = 0;      ///< records the sink accepted (including replayed ones)
    uint64_t spooled = 0;   ///< records written to the spool file
    uint64_t dropped = 0;   ///< records dropped: the spool was at its bound or not writable
    bool reachable = true;  ///< whether the last Send succeeded
  };

  BatchingAppender(const std::string& name, std::unique_ptr<RecordSink> sink,
                   AppenderOptions options);
  ~BatchingAppender() override;

  /// Queues one record (numbers it with the next seq); what log4cpp events turn into.
  void Append(Record record);

  /// Waits until everything appended so far reached the sink; false on timeout.
  bool Flush(std::chrono::milliseconds timeout);

  Stats stats() const;
  std::string spool_path() const { return spool_path_; }

  /// Tries to deliver what is queued for up to `linger`, spools the rest, stops the thread.
  void Stop(std::chrono::milliseconds linger);

  void close() override;
  bool reopen() override { return true; }
  bool requiresLayout() const override { return false; }
  void setLayout(log4cpp::Layout*) override {}

 protected:
  void _append(const log4cpp::LoggingEvent& event) override;

 private:
  void Run();
  bool HasBacklog() const;
  void SpoolLocked(const std::vector<Record>& records);
  bool ReplayBacklog();
  bool ReplayFile(const std::string& path, uint64_t* offset);
  bool TrySend(const std::vector<Record>& batch);
  void ClaimOrphans();

  std::unique_ptr<RecordSink> sink_;
  const AppenderOptions options_;
  const std::string spool_path_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Record> queue_;
  uint64_t next_seq_ = 1;
  size_t in_flight_ = 0;
  bool stop_ = false;
  bool stopped_ = false;  ///< the sender thread has ended
  std::chrono::steady_clock::time_point stop_deadline_;
  std::chrono::steady_clock::time_point next_retry_;
  Stats stats_;

  // spool state, touched only by the sender thread (and read under mutex_ by HasBacklog)
  std::deque<std::string> orphan_files_;
  uint64_t spool_written_ = 0;  ///< bytes in the own spool file
  uint64_t spool_replayed_ = 0; ///< bytes of it already delivered
  uint64_t orphan_offset_ = 0;
  uint64_t dropped_unreported_ = 0;  ///< dropped since the last warning record (under mutex_)
  Record identity_;                  ///< the last record's source fields, for that warning

  std::thread thread_;
};

}  // namespace caliper::logging
