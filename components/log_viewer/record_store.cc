#include "record_store.h"

#include <utility>

namespace caliper::log_viewer {

uint32_t RecordStore::Intern(const std::string& name, std::vector<std::string>* names,
                             std::unordered_map<std::string, uint32_t>* ids) {
  auto [it, added] = ids->try_emplace(name, static_cast<uint32_t>(names->size()));
  if (added) names->push_back(name);
  return it->second;
}

size_t RecordStore::Append(std::vector<logging::Record> records) {
  size_t added = 0;
  for (auto& r : records) {
    if (r.seq != 0) {
      uint64_t& last = last_seq_[r.source];
      if (r.seq <= last) continue;  // delivered before (a file and the live service overlap)
      last = r.seq;
    }
    Entry e;
    e.category = Intern(r.category, &categories_, &category_ids_);
    e.component = Intern(r.component, &components_, &component_ids_);
    e.record = std::move(r);
    entries_.push_back(std::move(e));
    ++added;
  }
  return added;
}

void RecordStore::Clear() {
  entries_.clear();
  categories_.clear();
  category_ids_.clear();
  components_.clear();
  component_ids_.clear();
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
