#include "log_store.h"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "caliper/core/system.h"
#include "caliper/logging/message_pattern.h"

namespace caliper::logger {

std::string TruncationMarker(size_t cut_bytes) {
  return "\xE2\x80\xA6 [truncated " + std::to_string(cut_bytes) + " bytes]";  // "…"
}

std::string Truncate(const std::string& text, size_t max_bytes) {
  if (text.size() <= max_bytes) return text;
  // room for the longest marker this text can need (cutting all of it)
  const size_t room = TruncationMarker(text.size()).size();
  size_t keep = max_bytes > room ? max_bytes - room : 0;
  // never half a UTF-8 character: back off over continuation bytes (10xxxxxx)
  while (keep > 0 && (static_cast<unsigned char>(text[keep]) & 0xC0) == 0x80) --keep;
  return text.substr(0, keep) + TruncationMarker(text.size() - keep);
}

std::string SessionFileName(const std::string& session, int64_t time_us) {
  const time_t seconds = static_cast<time_t>(time_us / 1000000);
  struct tm local;
  localtime_r(&seconds, &local);
  char stamp[32];
  strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  return std::string("caliper-") + stamp + "-" + session + ".log";
}

namespace {

/// An existing file of this session in `directory`, or "".
std::string FindSessionFile(const std::string& directory, const std::string& session) {
  DIR* dir = opendir(directory.c_str());
  if (dir == nullptr) return "";
  const std::string suffix = "-" + session + ".log";
  std::string found;
  while (dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    // caliper-YYYYmmdd-HHMMSS-<session>.log
    if (name.rfind("caliper-", 0) == 0 && name.size() == 8 + 15 + suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      found = directory + "/" + name;
  }
  closedir(dir);
  return found;
}

/// The record with its texts within the store's bounds.
logging::Record Bounded(logging::Record r) {
  r.message = Truncate(r.message, kMaxMessageBytes);
  for (std::string* field : {&r.category, &r.component, &r.host, &r.source})
    *field = Truncate(*field, kMaxFieldBytes);
  return r;
}

}  // namespace

LogStore::LogStore(const std::string& directory, const std::string& session, size_t memory_records,
                   size_t memory_bytes)
    : memory_records_(memory_records), memory_bytes_(memory_bytes) {
  core::MakeDirectories(directory);
  path_ = FindSessionFile(directory, session);
  const bool existing = !path_.empty();
  if (existing) {
    Recover();
  } else {
    path_ = directory + "/" + SessionFileName(session, core::NowMicros());
  }
  file_.open(path_, std::ios::app | std::ios::binary);
  if (!file_) throw std::runtime_error("cannot open session log " + path_);
  if (!existing) {
    file_ << "# caliper session log; session " << session << "; started "
          << core::FormatTime(core::NowMicros())
          << "\n# time(UTC)\tpriority\tcategory\tcomponent\thost\tpid\tsource\tseq\tmessage\n";
    file_.flush();
  }
}

void LogStore::Recover() {
  std::ifstream in(path_, std::ios::binary);
  std::string line;
  uint64_t good_bytes = 0;
  uint64_t position = 0;
  while (std::getline(in, line)) {
    const bool complete = !in.eof();
    position += line.size() + (complete ? 1 : 0);
    if (!complete) break;  // torn last line of a killed logger: cut off below
    good_bytes = position;
    logging::Record r;
    if (!logging::ParseLine(line, &r)) continue;
    // a file written before the bounds may hold longer texts: memory keeps to them anyway
    r = Bounded(std::move(r));
    if (r.seq != 0) seen_.Insert(r.source, r.seq);
    Remember(std::make_shared<const StoredRecord>(StoredRecord{++serial_, std::move(r)}));
  }
  in.close();
  if (good_bytes < position && truncate(path_.c_str(), static_cast<off_t>(good_bytes)) != 0)
    throw std::runtime_error("cannot repair torn session log " + path_);
}

std::vector<StoredRecord> LogStore::Submit(const std::vector<logging::Record>& records) {
  std::vector<logging::Record> bounded;
  bounded.reserve(records.size());
  for (const auto& r : records) bounded.push_back(Bounded(r));
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<StoredRecord> stored;
  std::string text;
  // the batch counts as stored only once it is in the file, so that a retry after a failed
  // write is not taken for a duplicate
  std::set<std::pair<std::string, uint64_t>> in_batch;
  uint64_t serial = serial_;
  for (auto& r : bounded) {
    if (r.seq != 0) {
      // delivered before (a retried batch), or twice in this one
      if (seen_.Contains(r.source, r.seq) || !in_batch.emplace(r.source, r.seq).second) continue;
    }
    text += logging::FormatLine(r);
    text += '\n';
    stored.push_back({++serial, std::move(r)});
  }
  if (!text.empty()) {
    struct stat before;
    const bool sized = stat(path_.c_str(), &before) == 0;
    // one write per batch: a record reaches the file whole or, after a crash, is cut off whole
    errno = 0;
    file_ << text;
    file_.flush();
    if (!file_) {
      // drop what could not be written and cut off any fragment that was, then start afresh
      const int error = errno;
      std::string why = "cannot write session log " + path_;
      if (error != 0) why += ": " + std::string(std::strerror(error));
      file_.close();
      if (!sized || truncate(path_.c_str(), before.st_size) != 0)
        why += " (a partial line may be left in it)";
      file_.clear();
      file_.open(path_, std::ios::app | std::ios::binary);
      throw std::runtime_error(why);
    }
  }
  serial_ = serial;
  for (const auto& s : stored) {
    if (s.record.seq != 0) seen_.Insert(s.record.source, s.record.seq);
    Remember(std::make_shared<const StoredRecord>(s));
  }
  return stored;
}

namespace {
size_t BytesOf(const StoredRecord& s) {
  const auto& r = s.record;
  return sizeof(StoredRecord) + r.message.size() + r.category.size() + r.component.size() +
         r.host.size() + r.source.size();
}
}  // namespace

void LogStore::Remember(std::shared_ptr<const StoredRecord> record) {
  recent_bytes_ += BytesOf(*record);
  recent_.push_back(std::move(record));
  while (!recent_.empty() && (recent_.size() > memory_records_ || recent_bytes_ > memory_bytes_)) {
    recent_bytes_ -= BytesOf(*recent_.front());
    recent_.pop_front();
  }
}

std::vector<StoredRecord> LogStore::Query(const QueryFilter& f) const {
  std::optional<logging::MessagePattern> pattern;
  if (!f.regex.empty()) pattern.emplace(f.regex);
  const size_t limit = f.limit == 0 ? kMaxQueryRecords : std::min(f.limit, kMaxQueryRecords);
  // newest first; under the lock only the cheap tests, and pointers copied
  std::vector<std::shared_ptr<const StoredRecord>> candidates;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
      const StoredRecord& s = **it;
      const auto& r = s.record;
      if (s.serial <= f.after_serial) break;  // serials grow: every older one is too
      if (r.priority > f.max_priority) continue;
      if (!f.category_prefix.empty() && r.category.rfind(f.category_prefix, 0) != 0) continue;
      if (!f.component.empty() && r.component != f.component) continue;
      if (f.from_time_us != 0 && r.time_us < f.from_time_us) continue;
      if (f.to_time_us != 0 && r.time_us > f.to_time_us) continue;
      candidates.push_back(*it);
      if (!pattern && candidates.size() == limit) break;
    }
  }
  if (before_match_) before_match_();
  std::vector<StoredRecord> out;
  for (const auto& c : candidates) {
    if (out.size() == limit) break;
    if (pattern && !pattern->Search(c->record.message)) continue;
    out.push_back(*c);
  }
  std::reverse(out.begin(), out.end());
  return out;
}

uint64_t LogStore::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return serial_;
}

}  // namespace caliper::logger
