#include "log_store.h"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <ctime>
#include <regex>
#include <stdexcept>

#include "caliper/core/system.h"

namespace caliper::logger {

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

}  // namespace

LogStore::LogStore(const std::string& directory, const std::string& session,
                   size_t memory_records)
    : memory_records_(memory_records) {
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
    uint64_t& last = last_seq_[r.source];
    if (r.seq > last) last = r.seq;
    recent_.push_back({++serial_, std::move(r)});
    if (recent_.size() > memory_records_) recent_.pop_front();
  }
  in.close();
  if (good_bytes < position && truncate(path_.c_str(), static_cast<off_t>(good_bytes)) != 0)
    throw std::runtime_error("cannot repair torn session log " + path_);
}

std::vector<StoredRecord> LogStore::Submit(const std::vector<logging::Record>& records) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<StoredRecord> stored;
  std::string text;
  // the batch counts as stored only once it is in the file, so that a retry after a failed
  // write is not taken for a duplicate
  std::map<std::string, uint64_t> last_seq;
  uint64_t serial = serial_;
  for (const auto& r : records) {
    if (r.seq != 0) {
      auto last = last_seq.find(r.source);
      if (last == last_seq.end()) {
        auto known = last_seq_.find(r.source);
        last = last_seq.emplace(r.source, known == last_seq_.end() ? 0 : known->second).first;
      }
      if (r.seq <= last->second) continue;  // delivered before: a retried batch
      last->second = r.seq;
    }
    text += logging::FormatLine(r);
    text += '\n';
    stored.push_back({++serial, r});
  }
  if (!text.empty()) {
    struct stat before;
    const bool sized = stat(path_.c_str(), &before) == 0;
    // one write per batch: a record reaches the file whole or, after a crash, is cut off whole
    file_ << text;
    file_.flush();
    if (!file_) {
      // drop what could not be written and cut off any fragment that was, then start afresh
      std::string why = "cannot write session log " + path_;
      file_.close();
      if (!sized || truncate(path_.c_str(), before.st_size) != 0)
        why += " (a partial line may be left in it)";
      file_.clear();
      file_.open(path_, std::ios::app | std::ios::binary);
      throw std::runtime_error(why);
    }
  }
  serial_ = serial;
  for (const auto& [source, seq] : last_seq) last_seq_[source] = seq;
  for (const auto& s : stored) {
    recent_.push_back(s);
    if (recent_.size() > memory_records_) recent_.pop_front();
  }
  return stored;
}

std::vector<StoredRecord> LogStore::Query(const QueryFilter& f) const {
  std::regex re;
  const bool use_regex = !f.regex.empty();
  if (use_regex) re = std::regex(f.regex, std::regex::ECMAScript);
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<StoredRecord> out;
  for (const auto& s : recent_) {
    const auto& r = s.record;
    if (s.serial <= f.after_serial || r.priority > f.max_priority) continue;
    if (!f.category_prefix.empty() && r.category.rfind(f.category_prefix, 0) != 0) continue;
    if (!f.component.empty() && r.component != f.component) continue;
    if (f.from_time_us != 0 && r.time_us < f.from_time_us) continue;
    if (f.to_time_us != 0 && r.time_us > f.to_time_us) continue;
    if (use_regex && !std::regex_search(r.message, re)) continue;
    out.push_back(s);
  }
  if (f.limit != 0 && out.size() > f.limit) out.erase(out.begin(), out.end() - f.limit);
  return out;
}

uint64_t LogStore::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return serial_;
}

}  // namespace caliper::logger
