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
    lost_ = 0;
  }
  buffer_.clear();
  held_.clear();
  state_ = State::kSyncing;
}

void LiveInbox::HoldLocked(std::vector<LiveRecord>& records) {
  for (auto& r : records) {
    // both pushed and answered by a query: the first one counts
    if (r.serial > last_serial_) held_.emplace(r.serial, std::move(r.record));
  }
}

void LiveInbox::FlushLocked() {
  // everything that follows the last serial without a gap goes to the GUI
  auto it = held_.begin();
  for (; it != held_.end() && it->first == last_serial_ + 1; ++it) {
    last_serial_ = it->first;
    pending_.push_back(std::move(it->second));
  }
  held_.erase(held_.begin(), it);
}

void LiveInbox::SkipMissingLocked() {
  // after a query's answer is merged, serials still missing before the first record held were
  // not in the answer: the logger no longer holds them
  if (held_.empty() || held_.begin()->first == last_serial_ + 1) return;
  if (last_serial_ > 0) lost_ += held_.begin()->first - last_serial_ - 1;
  last_serial_ = held_.begin()->first - 1;
  FlushLocked();
}

void LiveInbox::Synced(std::vector<LiveRecord> records) {
  bool gap = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state_ != State::kSyncing) return;
    HoldLocked(records);
    FlushLocked();
    SkipMissingLocked();
    HoldLocked(buffer_);
    buffer_.clear();
    FlushLocked();
    state_ = State::kLive;
    gap = !held_.empty();
  }
  if (gap && on_gap_) on_gap_();
}

void LiveInbox::Push(std::vector<LiveRecord> records) {
  bool opened = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state_ == State::kSyncing) {
      buffer_.insert(buffer_.end(), std::make_move_iterator(records.begin()),
                     std::make_move_iterator(records.end()));
    } else if (state_ == State::kLive) {
      const bool had_gap = !held_.empty();
      HoldLocked(records);
      FlushLocked();
      opened = !had_gap && !held_.empty();
    }
  }
  if (opened && on_gap_) on_gap_();
}

bool LiveInbox::gap_pending() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_ == State::kLive && !held_.empty();
}

void LiveInbox::GapAnswered(uint64_t after_serial, std::vector<LiveRecord> records) {
  bool gap = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state_ != State::kLive || after_serial != last_serial_) return;
    HoldLocked(records);
    FlushLocked();
    SkipMissingLocked();
    gap = !held_.empty();  // another gap after the answer's records: another query
  }
  if (gap && on_gap_) on_gap_();
}

void LiveInbox::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  state_ = State::kStopped;
  buffer_.clear();
  held_.clear();
}

uint64_t LiveInbox::last_serial() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_serial_;
}

uint64_t LiveInbox::lost() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return lost_;
}

std::vector<logging::Record> LiveInbox::Take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<logging::Record> out;
  out.swap(pending_);
  return out;
}

}  // namespace caliper::log_viewer
