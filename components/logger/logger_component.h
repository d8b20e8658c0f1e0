#pragma once
// The Logging component: stores records from every component in the session's log file while
// ACTIVE (an INACTIVE logger refuses records; senders keep them in their spools meanwhile).
//
// Configuration (config/logger.conf):
//   logger.directory       where session files go
//   logger.session         session id in the file name (the launcher passes its own)
//   logger.memory_records  how many recent records queries can see

#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "caliper/rtc/runtime.h"
#include "log_store.h"

namespace caliper::logger {

/// The logger cannot store now (inactive, disk full); the sender retries later.
class NotAccepting : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LoggerComponent : public rtc::Component {
 public:
  explicit LoggerComponent(rtc::Runtime& runtime);

  rtc::ReturnCode OnInitialize() override;
  rtc::ReturnCode OnFinalize() override;

  /// Stores a batch (skipping duplicates) and hands the new records to the listener callback.
  /// Records from other processes are refused unless ACTIVE (`own` records always go in).
  std::vector<StoredRecord> Submit(const std::vector<logging::Record>& records, bool own = false);
  std::vector<StoredRecord> Query(const QueryFilter& filter) const;
  std::string session_file() const;

  /// Called with every batch of newly stored records (the servant forwards them to listeners).
  void SetListener(std::function<void(const std::vector<StoredRecord>&)> listener);

  static std::vector<core::ConfigKey> ConfigKeys();

 private:
  rtc::Runtime& runtime_;
  std::unique_ptr<LogStore> store_;
  // whether the session log could not be written (a full disk): reported once, and its end
  std::mutex write_mutex_;
  bool write_failing_ = false;
  int64_t failing_since_us_ = 0;
  uint64_t refused_batches_ = 0;
  mutable std::mutex listener_mutex_;
  std::function<void(const std::vector<StoredRecord>&)> listener_;
};

}  // namespace caliper::logger
