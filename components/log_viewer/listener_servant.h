#pragma once
// The Log Viewer's LogListener servant: converts each pushed batch and hands it to the inbox.

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/logging.hh"
#include "live_inbox.h"

namespace caliper::log_viewer {

class ListenerServant : public virtual POA_Caliper::Logging::LogListener {
 public:
  /// Where each converted batch goes (the LiveInbox).
  using Sink = std::function<void(std::vector<LiveRecord>)>;

  explicit ListenerServant(Sink sink) : sink_(std::move(sink)) {}

  /// Records the logger stored, handed to the sink. Never throws (the logger drops a listener
  /// whose call fails): a batch that cannot be taken in is counted, logged and left out (the
  /// inbox then sees a gap in the serials and queries it).
  void on_records(const Caliper::Logging::StoredRecordSeq& records) override;

  /// How many batches could not be taken in.
  uint64_t failures() const { return failures_; }
  /// Why the last of them could not ("" when none failed).
  std::string last_failure() const;

 private:
  void Failed(CORBA::ULong records, const char* why) noexcept;

  Sink sink_;
  std::atomic<uint64_t> failures_{0};
  mutable std::mutex mutex_;
  std::string last_failure_;
};

/// IDL stored records to LiveRecords.
std::vector<LiveRecord> FromIdl(const Caliper::Logging::StoredRecordSeq& records);

}  // namespace caliper::log_viewer
