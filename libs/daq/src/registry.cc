#include "caliper/daq/registry.h"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>

namespace caliper::daq {

UnknownId::UnknownId(const std::string& id, const std::string& kind)
    : std::out_of_range("unknown " + kind + " '" + id + "'"), id_(id) {}

InvalidValue::InvalidValue(const std::string& id, const std::string& reason)
    : std::invalid_argument(id + ": " + reason), id_(id), reason_(reason) {}

std::string Shape::ToString() const { return std::to_string(rows) + "x" + std::to_string(cols); }

bool GlobMatch(const std::string& pattern, const std::string& text) {
  // no flags: neither '/' nor a leading '.' is special, so '*' and '?' cross the dots of ids
  return fnmatch(pattern.c_str(), text.c_str(), 0) == 0;
}

Handle Registry::Add(ChannelInfo info, Getter getter, Setter setter) {
  if (info.id.empty()) throw std::invalid_argument("daq channel with an empty id");
  if (info.shape.size() == 0)
    throw std::invalid_argument(info.id + ": empty shape " + info.shape.ToString());
  if (!getter) throw std::invalid_argument(info.id + ": no getter");
  if (index_.count(info.id)) throw std::invalid_argument(info.id + ": already registered");
  info.writable = static_cast<bool>(setter);

  uint32_t slot;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    slot = static_cast<uint32_t>(slots_.size());
    slots_.emplace_back();
  }
  Slot& s = slots_[slot];
  s.info = std::move(info);
  s.getter = std::move(getter);
  s.setter = std::move(setter);
  s.size = s.info.shape.size();
  s.live = true;
  index_.emplace(s.info.id, slot);
  ++version_;
  return {slot, s.generation};
}

Handle Registry::Add(ChannelInfo info, Source source, Setter setter) {
  if (!source.block || !source.values)
    throw std::invalid_argument(info.id + ": source without a block or values");
  SourceBlock* block = source.block.get();
  const double* values = source.values;
  const size_t n = info.shape.size();
  // the same values through a getter, for reads by id or handle; the slot's source keeps the
  // block alive as long as the getter
  Getter getter = [block, values, n](double* out) {
    block->Update();
    std::copy_n(values, n, out);
  };
  const Handle h = Add(std::move(info), std::move(getter), std::move(setter));
  slots_[h.slot].source = std::move(source);
  return h;
}

Access Registry::Resolved(Handle handle) const {
  if (!Valid(handle)) ThrowStale(handle);
  const Slot& s = slots_[handle.slot];
  return {&s.getter, s.source.block.get(), s.source.values, s.info.shape.size()};
}

void Registry::Release(uint32_t slot) {
  Slot& s = slots_[slot];
  s.live = false;
  ++s.generation;
  // drop the functors now: they may hold references into a scene that is going away
  s.getter = nullptr;
  s.setter = nullptr;
  s.source = Source();
  free_.push_back(slot);
}

bool Registry::Remove(const std::string& id) {
  const auto it = index_.find(id);
  if (it == index_.end()) return false;
  Release(it->second);
  index_.erase(it);
  ++version_;
  return true;
}

size_t Registry::RemoveMatching(const std::string& pattern) {
  size_t removed = 0;
  for (auto it = index_.begin(); it != index_.end();) {
    if (GlobMatch(pattern, it->first)) {
      Release(it->second);
      it = index_.erase(it);
      ++removed;
    } else {
      ++it;
    }
  }
  if (removed) ++version_;
  return removed;
}

void Registry::Clear() {
  for (const auto& [id, slot] : index_) Release(slot);
  index_.clear();
  ++version_;
}

std::vector<ChannelInfo> Registry::List(const std::string& pattern) const {
  std::vector<ChannelInfo> out;
  for (const auto& [id, slot] : index_)
    if (GlobMatch(pattern, id)) out.push_back(slots_[slot].info);
  std::sort(out.begin(), out.end(),
            [](const ChannelInfo& a, const ChannelInfo& b) { return a.id < b.id; });
  return out;
}

const ChannelInfo& Registry::Info(const std::string& id) const {
  return slots_[Resolve(id).slot].info;
}

const ChannelInfo& Registry::Info(Handle handle) const {
  if (!Valid(handle)) ThrowStale(handle);
  return slots_[handle.slot].info;
}

Handle Registry::Resolve(const std::string& id) const {
  Handle h;
  if (!TryResolve(id, &h)) throw UnknownId(id);
  return h;
}

bool Registry::TryResolve(const std::string& id, Handle* handle) const {
  const auto it = index_.find(id);
  if (it == index_.end()) return false;
  *handle = {it->second, slots_[it->second].generation};
  return true;
}

void Registry::ThrowStale(Handle handle) const {
  // the slot keeps the id of the channel that was removed until the slot is reused
  if (handle.slot < slots_.size() && !slots_[handle.slot].live &&
      slots_[handle.slot].generation == handle.generation + 1)
    throw UnknownId(slots_[handle.slot].info.id);
  throw UnknownId("<stale handle>");
}

std::vector<double> Registry::Get(const std::string& id) const {
  const Handle h = Resolve(id);
  std::vector<double> values(slots_[h.slot].info.shape.size());
  Read(h, values.data());
  return values;
}

std::vector<Reading> Registry::Sample(const std::vector<std::string>& ids) const {
  std::vector<const char*> names(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) names[i] = ids[i].c_str();
  std::vector<Shape> shapes;
  std::vector<double> values;
  SampleInto(names.data(), names.size(), &shapes, &values);
  std::vector<Reading> out(ids.size());
  const double* at = values.data();
  for (size_t i = 0; i < ids.size(); ++i) {
    out[i].id = ids[i];
    out[i].shape = shapes[i];
    out[i].values.assign(at, at + shapes[i].size());
    at += shapes[i].size();
  }
  return out;
}

void Registry::SampleInto(const char* const* ids, size_t count, std::vector<Shape>* shapes,
                          std::vector<double>* values) const {
  // every id resolved before anything is read. The key and the handles of a call of a few ids (a
  // controller's cycle) keep their memory from call to call in each thread; a larger call's
  // handles are its own, freed when it returns
  constexpr size_t kKeptHandles = 1024;
  thread_local std::string key;
  thread_local std::vector<Handle> kept;
  std::vector<Handle> own;
  std::vector<Handle>& handles = count <= kKeptHandles ? kept : own;
  handles.resize(count);
  shapes->resize(count);
  size_t total = 0;
  for (size_t i = 0; i < count; ++i) {
    key.assign(ids[i]);
    if (!TryResolve(key, &handles[i])) throw UnknownId(key);
    (*shapes)[i] = slots_[handles[i].slot].info.shape;
    total += (*shapes)[i].size();
  }
  values->resize(total);
  double* out = values->data();
  for (size_t i = 0; i < count; ++i) {
    Read(handles[i], out);
    out += (*shapes)[i].size();
  }
}

void Registry::Set(const std::string& id, const std::vector<double>& values) {
  Set(Resolve(id), values.data(), values.size());
}

void Registry::Set(Handle handle, const double* values, size_t count) {
  if (!Valid(handle)) ThrowStale(handle);
  const Slot& s = slots_[handle.slot];
  const ChannelInfo& info = s.info;
  if (!s.setter) throw InvalidValue(info.id, "read-only");
  if (count != info.shape.size())
    throw InvalidValue(info.id, "expected " + std::to_string(info.shape.size()) + " value" +
                                    (info.shape.size() == 1 ? "" : "s") + " (shape " +
                                    info.shape.ToString() + "), got " + std::to_string(count));
  for (size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      throw InvalidValue(
          info.id, (count == 1 ? std::string("value") : "value " + std::to_string(i)) + " is " +
                       (std::isnan(values[i]) ? "NaN" : "infinite"));
  try {
    s.setter(values);
  } catch (const InvalidValue&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw InvalidValue(info.id, e.what());
  }
}

}  // namespace caliper::daq
