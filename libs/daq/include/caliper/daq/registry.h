#pragma once
// The data-acquisition registry: every quantity of a simulation under a string id, with its unit,
// its shape, a getter and (when writable) a setter. Knows neither CORBA nor any engine.
//
// Values are doubles in SI units; a matrix is stored row-major (rows * cols values, row after
// row), a quaternion as w x y z. Ids are dotted paths: `<model>.<actuator>.motor.current`,
// `<model>.<body>.position`, ...
//
// Threading: a Registry is not synchronised. The simulation thread (or whoever holds the model's
// step lock) adds, removes, reads and writes channels; getters therefore always see a consistent
// step.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace caliper::daq {

/// A lookup by an id (or a stale handle) that names nothing registered.
class UnknownId : public std::out_of_range {
 public:
  /// `kind` names what was looked up ("id", "subscription") for the message.
  explicit UnknownId(const std::string& id, const std::string& kind = "id");
  /// The id that was not found.
  const std::string& id() const { return id_; }

 private:
  std::string id_;
};

/// A write that cannot be applied: wrong number of values, NaN or infinite values, a read-only
/// channel, or a value the owner of the channel rejects.
class InvalidValue : public std::invalid_argument {
 public:
  InvalidValue(const std::string& id, const std::string& reason);
  /// The channel written to.
  const std::string& id() const { return id_; }
  /// Why the value was refused, without the id (e.g. "read-only").
  const std::string& reason() const { return reason_; }

 private:
  std::string id_;
  std::string reason_;
};

/// The shape of a value: rows x cols doubles (a scalar is 1 x 1, a vector 3 x 1, a quaternion
/// 4 x 1, a rotation matrix 3 x 3).
struct Shape {
  uint32_t rows = 1;
  uint32_t cols = 1;

  /// rows * cols: how many doubles a value holds.
  size_t size() const { return static_cast<size_t>(rows) * cols; }
  /// "3x1" for messages.
  std::string ToString() const;
  bool operator==(const Shape& o) const { return rows == o.rows && cols == o.cols; }
  bool operator!=(const Shape& o) const { return !(*this == o); }

  static Shape Scalar() { return {1, 1}; }
  static Shape Vector(uint32_t n) { return {n, 1}; }
  static Shape Matrix(uint32_t rows, uint32_t cols) { return {rows, cols}; }
};

/// What a channel is, without its functors: what list() reports.
struct ChannelInfo {
  std::string id;           // e.g. arm.elbow_flexor.motor.current
  std::string unit;         // SI: A, N, m, rad, "" for dimensionless
  Shape shape;              // rows x cols
  bool writable = false;    // has a setter (set by Registry::Add)
  bool is_static = false;   // a model parameter (true) or a state changing every step (false)
  std::string description;  // one line
};

/// Writes shape.size() doubles (row-major) to `out`.
using Getter = std::function<void(double* out)>;
/// Applies shape.size() doubles (row-major, already checked finite). May throw
/// std::invalid_argument with a reason; Registry::Set turns it into InvalidValue.
using Setter = std::function<void(const double* values)>;

/// Values that a group of channels reads in place (e.g. a per-step cache of every body's pose):
/// a reader that copies many channels per step updates each block once and then copies the
/// values, with no call per channel. Lives on the simulation thread, like the registry.
class SourceBlock {
 public:
  virtual ~SourceBlock() = default;
  /// Brings the block's values up to date; called before any of its values are read. Must be
  /// cheap when called again with nothing changed (several channels of a block are read per step).
  virtual void Update() = 0;
};

/// Where a channel added with a source keeps its values: `shape.size()` doubles at `values`,
/// up to date after `block->Update()`, valid (at the same address) as long as `block` lives.
struct Source {
  std::shared_ptr<SourceBlock> block;
  const double* values = nullptr;
};

/// How to read a resolved channel without a lookup, for a reader that copies many channels per
/// step (the recorder). Valid only while Registry::version() stays the same: any Add, Remove or
/// Clear may move or free what it points to, so re-resolve when the version changed.
struct Access {
  const Getter* getter = nullptr;  // always set
  SourceBlock* block = nullptr;    // set for a channel added with a Source: call Update() first,
  const double* values = nullptr;  // then read its `size` doubles at `values`
  size_t size = 0;                 // shape.size()
};

/// A pre-resolved channel: reading through it does no string hashing. A handle goes stale when
/// its channel is removed (also when the same id is registered again); using a stale handle
/// throws UnknownId, Valid() tells beforehand.
struct Handle {
  uint32_t slot = UINT32_MAX;
  uint32_t generation = 0;
};

/// One value returned by Registry::Sample.
struct Reading {
  std::string id;
  Shape shape;
  std::vector<double> values;  // shape.size() doubles, row-major
};

/// Channels by id: lookup through a hash map, reads through handles.
class Registry {
 public:
  Registry() = default;
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  /// Registers a channel and returns its handle; `info.writable` is set from whether `setter` is
  /// given. Throws std::invalid_argument for an empty or duplicate id, an empty shape or a
  /// missing getter.
  Handle Add(ChannelInfo info, Getter getter, Setter setter = nullptr);
  /// Registers a channel whose values are read in place from `source` (see Access); reading it
  /// by handle or id works as for a getter. Throws std::invalid_argument as Add above, and for a
  /// source without a block or values.
  Handle Add(ChannelInfo info, Source source, Setter setter = nullptr);
  /// Removes a channel; false when there was none. Its handles go stale.
  bool Remove(const std::string& id);
  /// Removes every channel whose id matches the glob `pattern`; returns how many.
  size_t RemoveMatching(const std::string& pattern);
  /// Removes every channel (a scene is being reloaded). All handles go stale.
  void Clear();

  /// Number of channels.
  size_t size() const { return index_.size(); }
  bool Contains(const std::string& id) const { return index_.count(id) != 0; }
  /// Counts every Add, Remove and Clear: a user holding handles re-resolves when it changed.
  uint64_t version() const { return version_; }

  /// The channels whose ids match the glob `pattern` (GlobMatch), sorted by id.
  std::vector<ChannelInfo> List(const std::string& pattern = "*") const;
  /// Throws UnknownId.
  const ChannelInfo& Info(const std::string& id) const;
  /// Throws UnknownId for a stale handle.
  const ChannelInfo& Info(Handle handle) const;

  /// Throws UnknownId naming the id.
  Handle Resolve(const std::string& id) const;
  /// Whether `id` is registered; `*handle` receives its handle when it is.
  bool TryResolve(const std::string& id, Handle* handle) const;
  /// Whether the handle still names a registered channel.
  bool Valid(Handle handle) const {
    return handle.slot < slots_.size() && slots_[handle.slot].live &&
           slots_[handle.slot].generation == handle.generation;
  }

  /// Writes the channel's shape.size() values to `out`: the hot path, no hashing. Throws
  /// UnknownId for a stale handle.
  void Read(Handle handle, double* out) const {
    if (!Valid(handle)) ThrowStale(handle);
    const Slot& s = slots_[handle.slot];
    if (s.source.block) {
      // in place: no call through the getter
      s.source.block->Update();
      std::copy_n(s.source.values, s.size, out);
    } else {
      s.getter(out);
    }
  }
  /// The channel's getter, or its values in place when it was added with a Source; valid until
  /// version() changes. Throws UnknownId for a stale handle.
  Access Resolved(Handle handle) const;
  /// The current value of one channel. Throws UnknownId.
  std::vector<double> Get(const std::string& id) const;
  /// The current values of `ids`, in order. Throws UnknownId for the first unknown id before
  /// reading anything.
  std::vector<Reading> Sample(const std::vector<std::string>& ids) const;
  /// The same without a copy of each id or a vector per value, for a caller that reads ids every
  /// cycle (a controller's `get`): the shapes of the `count` ids at `ids` (each NUL-terminated)
  /// and their values one after the other (row-major each) into the two buffers, which are
  /// overwritten. Throws UnknownId for the first unknown id before reading anything.
  void SampleInto(const char* const* ids, size_t count, std::vector<Shape>* shapes,
                  std::vector<double>* values) const;

  /// Writes a channel. Throws UnknownId for an unknown id, InvalidValue for a read-only channel,
  /// a count that does not fit the shape, a NaN or infinite value, or a value the setter refuses.
  void Set(const std::string& id, const std::vector<double>& values);
  /// The same through a handle (UnknownId when stale).
  void Set(Handle handle, const double* values, size_t count);

 private:
  struct Slot {
    // what Read touches first, on as few cache lines as may be
    uint32_t generation = 0;
    bool live = false;
    size_t size = 0;  // info.shape.size()
    Source source;    // block and values when added with a Source
    Getter getter;
    Setter setter;
    ChannelInfo info;
  };
  [[noreturn]] void ThrowStale(Handle handle) const;
  void Release(uint32_t slot);

  std::vector<Slot> slots_;                          // indexed by Handle::slot
  std::vector<uint32_t> free_;                       // released slots, reused by Add
  std::unordered_map<std::string, uint32_t> index_;  // id -> slot
  uint64_t version_ = 0;
};

/// Whether `text` matches the glob `pattern`, as fnmatch(3) without flags: `*` any run of
/// characters, dots included; `?` one character; `[abc]`, `[a-z]`, `[!a]` one of a set; `\x`
/// the character x itself.
bool GlobMatch(const std::string& pattern, const std::string& text);

}  // namespace caliper::daq
