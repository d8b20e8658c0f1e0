#include "caliper/logging/batching_appender.h"

#include <dirent.h>
#include <log4cpp/LoggingEvent.hh>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "caliper/core/system.h"
#include "caliper/logging/log.h"

namespace caliper::logging {

using Clock = std::chrono::steady_clock;

BatchingAppender::BatchingAppender(const std::string& name, std::unique_ptr<RecordSink> sink,
                                   AppenderOptions options)
    : log4cpp::AppenderSkeleton(name),
      sink_(std::move(sink)),
      options_(std::move(options)),
      spool_path_(options_.spool_dir + "/" + options_.spool_name + ".spool") {
  core::MakeDirectories(options_.spool_dir);
  if (options_.replay_orphans) ClaimOrphans();
  thread_ = std::thread([this] { Run(); });
}

BatchingAppender::~BatchingAppender() {
  Stop(std::chrono::milliseconds(2000));
  // the spool folder goes once nothing waits in it (rmdir leaves a folder with files alone), so
  // folders of ended sessions do not pile up
  rmdir(options_.spool_dir.c_str());
}

void BatchingAppender::ClaimOrphans() {
  DIR* dir = opendir(options_.spool_dir.c_str());
  if (dir == nullptr) return;
  std::vector<std::string> names;
  while (dirent* entry = readdir(dir)) names.emplace_back(entry->d_name);
  closedir(dir);
  const std::string suffix = ".spool";
  const std::string claimed_mark = ".claimed-";
  std::sort(names.begin(), names.end());
  for (const auto& name : names) {
    // a spool of a dead process, `<stem>-<pid>.spool`, or one claimed by a process that died
    // before it had replayed it, `<stem>-<pid>.claimed-<claimer pid>`
    long owner = 0;
    std::string stem;
    const auto mark = name.find(claimed_mark);
    if (mark != std::string::npos) {
      stem = name.substr(0, mark);
      owner = std::strtol(name.c_str() + mark + claimed_mark.size(), nullptr, 10);
    } else if (name.size() > suffix.size() &&
               name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      stem = name.substr(0, name.size() - suffix.size());
      const auto dash = stem.rfind('-');
      if (dash == std::string::npos) continue;
      owner = std::strtol(stem.c_str() + dash + 1, nullptr, 10);
    } else {
      continue;
    }
    if (stem == options_.spool_name || owner == getpid() || core::ProcessAlive(owner)) continue;
    // rename is atomic: of two processes claiming the same orphan, one wins
    const std::string claimed = options_.spool_dir + "/" + stem + claimed_mark +
                                std::to_string(getpid());
    if (std::rename((options_.spool_dir + "/" + name).c_str(), claimed.c_str()) == 0)
      orphan_files_.push_back(claimed);
  }
}

void BatchingAppender::_append(const log4cpp::LoggingEvent& event) { Append(MakeRecord(event)); }

void BatchingAppender::Append(Record record) {
  std::lock_guard<std::mutex> lock(mutex_);
  record.seq = next_seq_++;
  ++stats_.appended;
  if (identity_.source.empty()) identity_ = record;
  if (stopped_) {  // the sender is gone: straight to the spool
    SpoolLocked({record});
    return;
  }
  queue_.push_back(std::move(record));
  if (queue_.size() >= options_.max_batch) wake_.notify_one();
}

bool BatchingAppender::HasBacklog() const {
  return !orphan_files_.empty() || spool_replayed_ < spool_written_;
}

void BatchingAppender::SpoolLocked(const std::vector<Record>& records) {
  if (records.empty()) return;
  std::string text;
  size_t kept = 0;
  for (const auto& r : records) {
    std::string line = FormatLine(r) + '\n';
    if (spool_written_ + text.size() + line.size() > options_.max_spool_bytes) break;
    text += line;
    ++kept;
  }
  if (kept < records.size()) {
    if (dropped_unreported_ == 0)
      std::fprintf(stderr,
                   "caliper: log spool %s is at its bound of %.3g MiB (log.spool_max): records "
                   "are dropped and counted until the Logging component takes them\n",
                   spool_path_.c_str(), options_.max_spool_bytes / 1048576.0);
    dropped_unreported_ += records.size() - kept;
    stats_.dropped += records.size() - kept;
  }
  if (text.empty()) return;
  core::MakeDirectories(options_.spool_dir);  // another process may have removed it, empty
  std::ofstream out(spool_path_, std::ios::app | std::ios::binary);
  out << text;
  out.flush();
  if (!out) {
    std::fprintf(stderr, "caliper: cannot write log spool %s: %zu records lost\n",
                 spool_path_.c_str(), kept);
    dropped_unreported_ += kept;
    stats_.dropped += kept;
    return;
  }
  spool_written_ += text.size();
  stats_.spooled += kept;
}

bool BatchingAppender::TrySend(const std::vector<Record>& batch) {
  try {
    sink_->Send(batch);
    return true;
  } catch (const SinkUnavailable&) {
    return false;
  }
}

bool BatchingAppender::ReplayFile(const std::string& path, uint64_t* offset) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return true;  // nothing there (removed by hand): nothing to replay
  in.seekg(static_cast<std::streamoff>(*offset));
  std::vector<Record> batch;
  uint64_t position = *offset;
  uint64_t batch_end = position;
  std::string line;
  while (true) {
    const bool got = static_cast<bool>(std::getline(in, line));
    const bool complete = got && !in.eof();
    if (complete) {
      position += line.size() + 1;
      Record r;
      if (ParseLine(line, &r)) batch.push_back(std::move(r));
      batch_end = position;
    }
    if (!complete || batch.size() >= options_.max_batch) {
      if (!batch.empty()) {
        if (!TrySend(batch)) return false;
        std::lock_guard<std::mutex> lock(mutex_);
        stats_.sent += batch.size();
      }
      *offset = batch_end;
      batch.clear();
      if (!complete) return true;  // end of file (a torn last line is dropped)
    }
  }
}

bool BatchingAppender::ReplayBacklog() {
  while (!orphan_files_.empty()) {
    if (!ReplayFile(orphan_files_.front(), &orphan_offset_)) return false;
    std::remove(orphan_files_.front().c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    orphan_files_.pop_front();
    orphan_offset_ = 0;
  }
  uint64_t offset = spool_replayed_;
  const bool done = ReplayFile(spool_path_, &offset);
  std::lock_guard<std::mutex> lock(mutex_);
  spool_replayed_ = offset;
  if (done && spool_replayed_ >= spool_written_) {
    std::remove(spool_path_.c_str());
    spool_written_ = spool_replayed_ = 0;
  }
  return done;
}

void BatchingAppender::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait_for(lock, options_.flush_interval, [&] {
      return stop_ || queue_.size() >= options_.max_batch;
    });
    const bool stopping = stop_;
    const bool past_deadline = stopping && Clock::now() >= stop_deadline_;
    if (HasBacklog()) {
      // keep the order: whatever is queued goes behind the backlog
      SpoolLocked(std::vector<Record>(queue_.begin(), queue_.end()));
      queue_.clear();
      if (past_deadline) break;
      if (!stopping && Clock::now() < next_retry_) continue;
      lock.unlock();
      const bool ok = ReplayBacklog();
      lock.lock();
      stats_.reachable = ok;
      if (ok && !HasBacklog() && dropped_unreported_ > 0) {
        // the sink has everything that was kept: say what was not
        Record warning = identity_;
        warning.time_us = core::NowMicros();
        warning.priority = kWarn;
        warning.category = "caliper.logging.spool";
        warning.seq = next_seq_++;
        warning.message = std::to_string(dropped_unreported_) +
                          " log records of this process were dropped while the Logging "
                          "component was unreachable: its spool was at its bound (log.spool_max) "
                          "or could not be written";
        dropped_unreported_ = 0;
        queue_.push_back(std::move(warning));
      }
      if (!ok) {
        if (stopping) break;
        next_retry_ = Clock::now() + options_.retry_interval;
      }
      idle_.notify_all();
      continue;
    }
    if (queue_.empty()) {
      idle_.notify_all();
      if (stopping) break;
      continue;
    }
    const size_t n = std::min(queue_.size(), options_.max_batch);
    std::vector<Record> batch(std::make_move_iterator(queue_.begin()),
                              std::make_move_iterator(queue_.begin() + n));
    queue_.erase(queue_.begin(), queue_.begin() + n);
    in_flight_ = n;
    lock.unlock();
    const bool ok = TrySend(batch);
    lock.lock();
    in_flight_ = 0;
    stats_.reachable = ok;
    if (ok) {
      stats_.sent += n;
    } else {
      SpoolLocked(batch);
      SpoolLocked(std::vector<Record>(queue_.begin(), queue_.end()));
      queue_.clear();
      next_retry_ = Clock::now() + options_.retry_interval;
      if (stopping) break;
    }
    idle_.notify_all();
  }
  // whatever could not be delivered stays on disk for a later process to replay
  SpoolLocked(std::vector<Record>(queue_.begin(), queue_.end()));
  queue_.clear();
  stopped_ = true;
  idle_.notify_all();
}

bool BatchingAppender::Flush(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.notify_one();
  return idle_.wait_for(lock, timeout, [&] {
    return queue_.empty() && in_flight_ == 0 && !HasBacklog();
  });
}

BatchingAppender::Stats BatchingAppender::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void BatchingAppender::Stop(std::chrono::milliseconds linger) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    stop_ = true;
    stop_deadline_ = Clock::now() + linger;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void BatchingAppender::close() { Stop(std::chrono::milliseconds(2000)); }

}  // namespace caliper::logging
