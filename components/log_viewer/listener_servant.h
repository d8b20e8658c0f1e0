#pragma once
// The Log Viewer's LogListener servant: converts each pushed batch and hands it to the inbox.

#include <memory>

#include "caliper/logging.hh"
#include "log_link.h"

namespace caliper::log_viewer {

class ListenerServant : public virtual POA_Caliper::Logging::LogListener {
 public:
  explicit ListenerServant(std::shared_ptr<LiveInbox> inbox) : inbox_(std::move(inbox)) {}

  /// Records the logger stored; never throws (a throwing listener would be dropped).
  void on_records(const Caliper::Logging::StoredRecordSeq& records) override;

 private:
  std::shared_ptr<LiveInbox> inbox_;
};

/// IDL stored records to LiveRecords.
std::vector<LiveRecord> FromIdl(const Caliper::Logging::StoredRecordSeq& records);

}  // namespace caliper::log_viewer
