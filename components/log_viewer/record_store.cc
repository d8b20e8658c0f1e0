#include "record_store.h"

#include <utility>

namespace caliper::log_viewer {

uint32_t NameTable::Intern(const std::string& name) {
  auto [it, added] = ids_.try_emplace(name, static_cast<uint32_t>(names_.size()));
  if (added) names_.push_back(name);
  return it->second;
}

void NameTable::Clear() {
  names_.clear();
  ids_.clear();
}

size_t RecordStore::Append(std::vector<logging::Record> records) {
  size_t added = 0;
  for (auto& r : records) {
    const uint32_t source = sources_.Intern(r.source);
    if (source >= last_seq_.size()) last_seq_.resize(source + 1, 0);
    if (r.seq != 0) {
      uint64_t& last = last_seq_[source];
      if (r.seq <= last) continue;  // delivered before (a file and the live service overlap)
      last = r.seq;
    }
    Entry e;
    e.time_us = r.time_us;
    e.seq = r.seq;
    e.pid = r.pid;
    e.message = std::move(r.message);
    e.priority = r.priority;
    e.category = categories_.Intern(r.category);
    e.component = components_.Intern(r.component);
    e.host = hosts_.Intern(r.host);
    e.source = source;
    entries_.push_back(std::move(e));
    ++added;
  }
  return added;
}

logging::Record RecordStore::record(size_t i) const {
  const Entry& e = entries_[i];
  logging::Record r;
  r.time_us = e.time_us;
  r.priority = e.priority;
  r.category = category(e);
  r.component = component(e);
  r.host = host(e);
  r.pid = e.pid;
  r.source = source(e);
  r.seq = e.seq;
  r.message = e.message;
  return r;
}

void RecordStore::Clear() {
  entries_.clear();
  categories_.Clear();
  components_.Clear();
  hosts_.Clear();
  sources_.Clear();
  last_seq_.clear();
}

void RecordStore::DropOldest(size_t n) {
  if (n >= entries_.size()) {
    entries_.clear();
    return;
  }
  entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(n));
}

}  // namespace caliper::log_viewer
