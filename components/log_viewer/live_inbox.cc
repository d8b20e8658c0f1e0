#include "live_inbox.h"

#include <iterator>
#include <utility>

namespace caliper::log_viewer {

void LiveInbox::BeginSync(const std::string& session_file) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (session_file != session_file_) {
    // another session: its serials start at 1 again (records seen before are still recognised
    // by their source and seq in the RecordStore)
    session_file_ = session_file;
    last_serial_ = 0;
  }
  buffer_.clear();
  state_ = State::kSyncing;
}

void LiveInbox::AcceptLocked(std::vector<LiveRecord>& records) {
  for (auto& r : records) {
    if (r.serial <= last_serial_) continue;  // both pushed and answered by the query
    last_serial_ = r.serial;
    pending_.push_back(std::move(r.record));
  }
}

void LiveInbox::Synced(std::vector<LiveRecord> records) {
  std::lock_guard<std::mutex> lock(mutex_);
  AcceptLocked(records);
  AcceptLocked(buffer_);
  buffer_.clear();
  state_ = State::kLive;
}

void LiveInbox::Push(std::vector<LiveRecord> records) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (state_ == State::kSyncing) {
    buffer_.insert(buffer_.end(), std::make_move_iterator(records.begin()),
                   std::make_move_iterator(records.end()));
  } else if (state_ == State::kLive) {
    AcceptLocked(records);
  }
}

void LiveInbox::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  state_ = State::kStopped;
  buffer_.clear();
}

uint64_t LiveInbox::last_serial() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_serial_;
}

std::vector<logging::Record> LiveInbox::Take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<logging::Record> out;
  out.swap(pending_);
  return out;
}

}  // namespace caliper::log_viewer
