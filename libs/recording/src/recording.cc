#include "caliper/recording/recording.h"

#include <filesystem>
#include <fcntl.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <functional>
#include <fstream>
#include <mutex>
#include <thread>
#include <variant>

#include "caliper/core/numbers.h"

namespace caliper::recording {

std::string WithExtension(const std::string& path) {
  return std::filesystem::path(path).filename().has_extension() ? path : path + kExtension;
}


namespace {

constexpr char kFormat[] = "caliper-recording";
constexpr int kFormatVersion = 1;
// the first bytes of an encoded DynamicState and its layout's versions: 2 adds the delayed
// channels' measurements, and a state without any is written as 1 (as before them)
constexpr char kStateMagic[4] = {'C', 'L', 'D', 'S'};
constexpr uint32_t kStateVersion = 2;
constexpr uint32_t kStateVersionWithoutMeasurements = 1;

// a double's text that reads back as the same double
std::string ExactText(double v) { return core::FormatDouble(v); }

// little-endian bytes, whatever the host's order (the file is read by Python's struct "<d")
void PutU64(std::string* out, uint64_t v) {
  char b[8];
  for (int i = 0; i < 8; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xff);
  out->append(b, 8);
}

void PutDouble(std::string* out, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  PutU64(out, bits);
}

uint64_t GetU64(const unsigned char* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(p[i]) << (8 * i);
  return v;
}

double GetDouble(const unsigned char* p) {
  const uint64_t bits = GetU64(p);
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

std::string PackDoubles(const std::vector<double>& values) {
  std::string out;
  out.reserve(values.size() * 8);
  for (double v : values) PutDouble(&out, v);
  return out;
}

// a little-endian float64 blob; false when its size is not a multiple of 8
bool UnpackDoubles(const void* data, int bytes, std::vector<double>* values) {
  if (bytes < 0 || bytes % 8 != 0) return false;
  values->resize(static_cast<size_t>(bytes) / 8);
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < values->size(); ++i) (*values)[i] = GetDouble(p + 8 * i);
  return true;
}

// Reads an encoded state front to back; every read checks the bytes left first.
class StateReader {
 public:
  explicit StateReader(const std::string& bytes) : bytes_(bytes) {}
  void Need(size_t n, const char* what) const {
    if (bytes_.size() - pos_ < n)
      throw RecordingError("not a dynamic state: its bytes end inside " + std::string(what) + " (" +
                           std::to_string(bytes_.size()) + " bytes)");
  }
  uint64_t U64(const char* what) {
    Need(8, what);
    const uint64_t v = GetU64(reinterpret_cast<const unsigned char*>(bytes_.data()) + pos_);
    pos_ += 8;
    return v;
  }
  double Double(const char* what) {
    const uint64_t bits = U64(what);
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  // a count of items of `item_bytes` each that must fit in what is left (no huge allocations
  // from garbage)
  size_t Count(size_t item_bytes, const char* what) {
    const uint64_t n = U64(what);
    if (item_bytes > 0 && n > (bytes_.size() - pos_) / item_bytes)
      throw RecordingError("not a dynamic state: " + std::string(what) + " counts " +
                           std::to_string(n) + " items, more than its " +
                           std::to_string(bytes_.size()) + " bytes hold");
    return static_cast<size_t>(n);
  }
  std::vector<double> Doubles(const char* what) {
    std::vector<double> v(Count(8, what));
    for (double& x : v) x = Double(what);
    return v;
  }
  void Skip(size_t n) { pos_ += n; }
  size_t left() const { return bytes_.size() - pos_; }

 private:
  const std::string& bytes_;
  size_t pos_ = 0;
};

// --- SQLite helpers -------------------------------------------------------------------------

// SQLite's refusal (its message); the Reader adds the file's name
class SqlError : public RecordingError {
 public:
  using RecordingError::RecordingError;
};

// A prepared statement, finalized on destruction.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK)
      throw SqlError(sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void Reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  void Bind(int i, int64_t v) { sqlite3_bind_int64(stmt_, i, v); }
  void Bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  void Bind(int i, const std::string& v) {
    sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void BindBlob(int i, const std::string& v) {
    sqlite3_bind_blob(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  // true while rows come; throws with SQLite's code in the message on failure
  bool Step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    last_code_ = rc;
    throw SqlError(sqlite3_errmsg(db_));
  }
  void Run() {
    Step();
    Reset();
  }
  int64_t Int(int col) const { return sqlite3_column_int64(stmt_, col); }
  double Real(int col) const { return sqlite3_column_double(stmt_, col); }
  std::string Text(int col) const {
    const auto* t = sqlite3_column_text(stmt_, col);
    return t ? std::string(reinterpret_cast<const char*>(t), sqlite3_column_bytes(stmt_, col))
             : std::string();
  }
  std::string Blob(int col) const {
    const void* b = sqlite3_column_blob(stmt_, col);
    return b ? std::string(static_cast<const char*>(b), sqlite3_column_bytes(stmt_, col))
             : std::string();
  }
  int last_code() const { return last_code_; }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  int last_code_ = SQLITE_OK;
};

void Exec(sqlite3* db, const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message ? message : sqlite3_errmsg(db);
    sqlite3_free(message);
    throw SqlError(text);
  }
}

int64_t QueryInt(sqlite3* db, const char* sql) {
  Statement s(db, sql);
  return s.Step() ? s.Int(0) : 0;
}

constexpr const char* kSchema = R"sql(
CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT);
CREATE TABLE channels(position INTEGER PRIMARY KEY, id TEXT, unit TEXT, rows INTEGER,
                      cols INTEGER);
CREATE TABLE scenes(version INTEGER PRIMARY KEY, step INTEGER, file_name TEXT, data BLOB);
CREATE TABLE keyframes(step INTEGER PRIMARY KEY, time_s REAL, scene_version INTEGER, state BLOB);
CREATE TABLE events(seq INTEGER PRIMARY KEY, step INTEGER, kind TEXT, target TEXT, vals BLOB);
CREATE INDEX events_by_step ON events(step);
CREATE TABLE samples(step INTEGER PRIMARY KEY, time_s REAL, vals BLOB);
CREATE TABLE log(seq INTEGER PRIMARY KEY, time_s REAL, priority TEXT, category TEXT,
                 component TEXT, message TEXT);
)sql";

bool FileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

void RemoveFiles(const std::string& path) {
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) ::unlink((path + suffix).c_str());
}

}  // namespace

// --- DynamicState bytes ----------------------------------------------------------------------

// magic "CLDS", u64 version, then time, steps, the bodies (13 doubles each: position, quaternion
// w x y z, linear and angular velocity), joint positions, actuators (each a counted vector),
// commands, the engine's numbers and (version 2) the measurements: every vector as a u64 count and
// its doubles, all little-endian
std::string EncodeState(const sgal::DynamicState& state) {
  std::string out(kStateMagic, 4);
  const bool measured = !state.measurements.empty();
  PutU64(&out, measured ? kStateVersion : kStateVersionWithoutMeasurements);
  PutDouble(&out, state.time);
  PutU64(&out, state.steps);
  PutU64(&out, state.bodies.size());
  for (const auto& b : state.bodies) {
    for (int i = 0; i < 3; ++i) PutDouble(&out, b.pose.position[i]);
    PutDouble(&out, b.pose.orientation.w());
    PutDouble(&out, b.pose.orientation.x());
    PutDouble(&out, b.pose.orientation.y());
    PutDouble(&out, b.pose.orientation.z());
    for (int i = 0; i < 3; ++i) PutDouble(&out, b.linear_velocity[i]);
    for (int i = 0; i < 3; ++i) PutDouble(&out, b.angular_velocity[i]);
  }
  auto put_vector = [&out](const std::vector<double>& v) {
    PutU64(&out, v.size());
    for (double x : v) PutDouble(&out, x);
  };
  put_vector(state.joint_positions);
  PutU64(&out, state.actuators.size());
  for (const auto& a : state.actuators) put_vector(a);
  put_vector(state.commands);
  put_vector(state.engine);
  if (measured) put_vector(state.measurements);
  return out;
}

sgal::DynamicState DecodeState(const std::string& bytes) {
  if (bytes.size() < 4 || std::memcmp(bytes.data(), kStateMagic, 4) != 0)
    throw RecordingError("not a dynamic state: it does not start with CLDS (" +
                         std::to_string(bytes.size()) + " bytes)");
  StateReader in(bytes);
  in.Skip(4);
  const uint64_t version = in.U64("the version");
  if (version != kStateVersion && version != kStateVersionWithoutMeasurements)
    throw RecordingError("a dynamic state of layout version " + std::to_string(version) +
                         ", this build reads versions " +
                         std::to_string(kStateVersionWithoutMeasurements) + " and " +
                         std::to_string(kStateVersion));
  sgal::DynamicState state;
  state.time = in.Double("the time");
  state.steps = in.U64("the step count");
  state.bodies.resize(in.Count(13 * 8, "the bodies"));
  for (auto& b : state.bodies) {
    for (int i = 0; i < 3; ++i) b.pose.position[i] = in.Double("a body");
    const double w = in.Double("a body"), x = in.Double("a body"), y = in.Double("a body"),
                 z = in.Double("a body");
    b.pose.orientation = Eigen::Quaterniond(w, x, y, z);
    for (int i = 0; i < 3; ++i) b.linear_velocity[i] = in.Double("a body");
    for (int i = 0; i < 3; ++i) b.angular_velocity[i] = in.Double("a body");
  }
  state.joint_positions = in.Doubles("the joint positions");
  state.actuators.resize(in.Count(8, "the actuators"));
  for (auto& a : state.actuators) a = in.Doubles("an actuator's state");
  state.commands = in.Doubles("the commands");
  state.engine = in.Doubles("the engine's numbers");
  if (version == kStateVersion) {
    state.measurements = in.Doubles("the measurements");
    // one encoding per state: none is written as version 1
    if (state.measurements.empty())
      throw RecordingError("not a dynamic state: version " + std::to_string(kStateVersion) +
                           " with no measurements (written as version " +
                           std::to_string(kStateVersionWithoutMeasurements) + ")");
  }
  if (in.left() != 0)
    throw RecordingError("not a dynamic state: " + std::to_string(in.left()) +
                         " bytes follow its end");
  return state;
}

// --- Writer ------------------------------------------------------------------------------------

using Record = std::variant<Keyframe, Event, SceneVersion, Sample, LogRecord>;

struct Writer::Impl {
  std::string path;
  std::chrono::milliseconds commit_every;
  uint64_t max_bytes = 0;
  sqlite3* db = nullptr;
  std::unique_ptr<Statement> insert_keyframe, insert_event, insert_scene, insert_sample, insert_log;

  // the simulation thread's side: the queue and the requests to the writer thread
  std::mutex mutex;
  std::condition_variable wake, flushed;
  std::vector<Record> queue;
  uint64_t flush_requested = 0, flush_done = 0;
  bool stop = false;
  std::atomic<bool> stopped{false};  // a write failed: later Add* do nothing
  std::string error;                 // guarded by mutex
  std::atomic<uint64_t> bytes{0};
  std::thread thread;

  // the writer thread's own
  std::vector<Record> batch;
  uint64_t last_step = 0;

  // records waiting for a disk that does not keep up: beyond this the recording stops rather
  // than fill the Model's memory (at 1 kHz with a sample and events a step, about 30 s of them)
  static constexpr size_t kMaxQueued = 100000;

  void Push(Record&& record) {
    if (stopped.load(std::memory_order_relaxed)) return;
    std::lock_guard<std::mutex> lock(mutex);
    if (queue.size() >= kMaxQueued) {
      error = "recording to " + path + " stopped: the disk did not keep up (" +
              std::to_string(kMaxQueued) + " records waited to be written); the file holds what " +
              "came before";
      stopped = true;
      queue.clear();
      return;
    }
    queue.push_back(std::move(record));
  }

  void Prepare() {
    insert_keyframe = std::make_unique<Statement>(
        db,
        // a later keyframe at the same step (an edit while paused) replaces the earlier one; the
        // events' keyframe marks tell a replay which events came after the last one
        "INSERT OR REPLACE INTO keyframes(step, time_s, scene_version, state) VALUES(?,?,?,?)");
    insert_event = std::make_unique<Statement>(
        db, "INSERT INTO events(step, kind, target, vals) VALUES(?,?,?,?)");
    insert_scene = std::make_unique<Statement>(
        db, "INSERT INTO scenes(version, step, file_name, data) VALUES(?,?,?,?)");
    insert_sample =
        std::make_unique<Statement>(db, "INSERT INTO samples(step, time_s, vals) VALUES(?,?,?)");
    insert_log = std::make_unique<Statement>(
        db, "INSERT INTO log(time_s, priority, category, component, message) VALUES(?,?,?,?,?)");
  }

  void Write(const Record& record) {
    if (const auto* k = std::get_if<Keyframe>(&record)) {
      last_step = k->step;
      Statement& s = *insert_keyframe;
      s.Bind(1, static_cast<int64_t>(k->step));
      s.Bind(2, k->time);
      s.Bind(3, static_cast<int64_t>(k->scene_version));
      s.BindBlob(4, EncodeState(k->state));
      s.Run();
    } else if (const auto* e = std::get_if<Event>(&record)) {
      last_step = e->step;
      Statement& s = *insert_event;
      s.Bind(1, static_cast<int64_t>(e->step));
      s.Bind(2, e->kind);
      s.Bind(3, e->target);
      s.BindBlob(4, PackDoubles(e->values));
      s.Run();
    } else if (const auto* v = std::get_if<SceneVersion>(&record)) {
      last_step = v->step;
      Statement& s = *insert_scene;
      s.Bind(1, static_cast<int64_t>(v->version));
      s.Bind(2, static_cast<int64_t>(v->step));
      s.Bind(3, v->file_name);
      s.BindBlob(4, v->bytes);
      s.Run();
    } else if (const auto* p = std::get_if<Sample>(&record)) {
      last_step = p->step;
      Statement& s = *insert_sample;
      s.Bind(1, static_cast<int64_t>(p->step));
      s.Bind(2, p->time);
      s.BindBlob(3, PackDoubles(p->values));
      s.Run();
    } else if (const auto* l = std::get_if<LogRecord>(&record)) {
      Statement& s = *insert_log;
      s.Bind(1, l->time);
      s.Bind(2, l->priority);
      s.Bind(3, l->category);
      s.Bind(4, l->component);
      s.Bind(5, l->message);
      s.Run();
    }
  }

  void UpdateBytes() {
    bytes = static_cast<uint64_t>(QueryInt(db, "PRAGMA page_count")) *
            static_cast<uint64_t>(QueryInt(db, "PRAGMA page_size"));
  }

  uint64_t StepOf(const Record& record) const {
    if (const auto* k = std::get_if<Keyframe>(&record)) return k->step;
    if (const auto* e = std::get_if<Event>(&record)) return e->step;
    if (const auto* v = std::get_if<SceneVersion>(&record)) return v->step;
    if (const auto* p = std::get_if<Sample>(&record)) return p->step;
    return last_step;  // a log record carries no step
  }

  // one transaction with everything in `batch`; on failure the recording stops
  void Commit() {
    if (batch.empty()) return;
    const uint64_t first_step = StepOf(batch.front());
    try {
      Exec(db, "BEGIN");
      for (const auto& r : batch) Write(r);
      Exec(db, "COMMIT");
      UpdateBytes();
    } catch (const std::exception& e) {
      const int code = sqlite3_extended_errcode(db) & 0xff;
      for (auto* s : {insert_keyframe.get(), insert_event.get(), insert_scene.get(),
                      insert_sample.get(), insert_log.get()})
        s->Reset();
      if (!sqlite3_get_autocommit(db)) sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
      std::string why;
      // the file at its limit (within a batch of it), or the disk full before that
      const uint64_t batch_bytes = uint64_t{8} << 20;
      if (code == SQLITE_FULL && max_bytes > 0 && bytes + batch_bytes >= max_bytes)
        why = "the file reached its limit of " + std::to_string(max_bytes) +
              " bytes or the disk is full";
      else if (code == SQLITE_FULL)
        why = "disk full";
      else if (code == SQLITE_IOERR)
        why = "write error";
      else
        why = "cannot write";
      std::lock_guard<std::mutex> lock(mutex);
      error = "recording to " + path + " stopped at step " + std::to_string(first_step) + ": " +
              why + " (" + e.what() + "); the file holds what came before";
      stopped = true;
      queue.clear();
    }
    batch.clear();
  }

  void Run() {
    auto next_commit = std::chrono::steady_clock::now() + commit_every;
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      wake.wait_until(lock, next_commit, [this] { return stop || flush_requested > flush_done; });
      const uint64_t flush_target = flush_requested;
      const bool stopping = stop;
      // the simulation thread gets back a cleared vector that keeps its capacity
      batch.swap(queue);
      lock.unlock();
      if (!stopped) Commit();
      batch.clear();
      next_commit = std::chrono::steady_clock::now() + commit_every;
      lock.lock();
      flush_done = flush_target;
      flushed.notify_all();
      if (stopping) return;
    }
  }
};

Writer::Writer(const std::string& path, const Header& header, const SceneVersion& scene,
               std::chrono::milliseconds commit_every, uint64_t max_bytes)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->commit_every = commit_every;
  impl_->max_bytes = max_bytes;
  // O_EXCL: an existing file (another recording) is never overwritten, even in a race
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int err = errno;
    if (err == EEXIST)
      throw RecordingError("cannot record to " + path + ": the file exists (choose a new name)");
    throw RecordingError("cannot record to " + path + ": " + std::strerror(err));
  }
  ::close(fd);
  try {
    if (sqlite3_open_v2(path.c_str(), &impl_->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX,
                        nullptr) != SQLITE_OK)
      throw std::runtime_error(impl_->db ? sqlite3_errmsg(impl_->db) : "out of memory");
    sqlite3* db = impl_->db;
    Exec(db, "PRAGMA journal_mode=WAL");
    Exec(db, "PRAGMA synchronous=NORMAL");
    if (max_bytes > 0) {
      const int64_t page = QueryInt(db, "PRAGMA page_size");
      const int64_t pages = std::max<int64_t>(1, static_cast<int64_t>(max_bytes) / page);
      Exec(db, ("PRAGMA max_page_count=" + std::to_string(pages)).c_str());
    }
    Exec(db, "BEGIN");
    Exec(db, kSchema);
    {
      Statement meta(db, "INSERT INTO meta(key, value) VALUES(?,?)");
      auto put = [&meta](const std::string& key, const std::string& value) {
        meta.Bind(1, key);
        meta.Bind(2, value);
        meta.Run();
      };
      put("format", kFormat);
      put("format_version", std::to_string(kFormatVersion));
      put("model_name", header.model_name);
      put("scene_file_name", header.scene_file_name);
      put("time_step_s", ExactText(header.time_step));
      put("keyframe_every", std::to_string(header.keyframe_every));
      put("channels_every", std::to_string(header.channels_every));
      put("first_step", std::to_string(header.first_step));
      put("engine", header.engine);
      Statement channel(db,
                        "INSERT INTO channels(position, id, unit, rows, cols) VALUES(?,?,?,?,?)");
      for (size_t i = 0; i < header.channels.size(); ++i) {
        const Channel& c = header.channels[i];
        channel.Bind(1, static_cast<int64_t>(i));
        channel.Bind(2, c.id);
        channel.Bind(3, c.unit);
        channel.Bind(4, static_cast<int64_t>(c.rows));
        channel.Bind(5, static_cast<int64_t>(c.cols));
        channel.Run();
      }
    }
    impl_->Prepare();
    impl_->Write(scene);
    Exec(db, "COMMIT");
    impl_->UpdateBytes();
  } catch (const std::exception& e) {
    impl_->insert_keyframe.reset();
    impl_->insert_event.reset();
    impl_->insert_scene.reset();
    impl_->insert_sample.reset();
    impl_->insert_log.reset();
    sqlite3_close(impl_->db);
    RemoveFiles(path);
    throw RecordingError("cannot record to " + path + ": " + e.what());
  }
  // room for a commit interval of records at 1 kHz: the two vectors are swapped back and forth
  // and keep their capacity, so a step's push allocates nothing beyond the record itself
  impl_->queue.reserve(1024);
  impl_->batch.reserve(1024);
  impl_->thread = std::thread([this] { impl_->Run(); });
}

Writer::~Writer() {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->stop = true;
  }
  impl_->wake.notify_all();
  impl_->thread.join();
  impl_->insert_keyframe.reset();
  impl_->insert_event.reset();
  impl_->insert_scene.reset();
  impl_->insert_sample.reset();
  impl_->insert_log.reset();
  // the last connection's close checkpoints the write-ahead log into the file and removes it
  sqlite3_close(impl_->db);
}

void Writer::AddKeyframe(const Keyframe& keyframe) { impl_->Push(Record(keyframe)); }
void Writer::AddEvent(const Event& event) { impl_->Push(Record(event)); }
void Writer::AddScene(const SceneVersion& scene) { impl_->Push(Record(scene)); }
void Writer::AddSample(Sample sample) {
  impl_->Push(Record(std::in_place_type<Sample>, std::move(sample)));
}
void Writer::AddLog(const LogRecord& record) { impl_->Push(Record(record)); }

void Writer::Flush() {
  std::unique_lock<std::mutex> lock(impl_->mutex);
  const uint64_t target = ++impl_->flush_requested;
  impl_->wake.notify_all();
  impl_->flushed.wait(lock, [this, target] { return impl_->flush_done >= target; });
}

std::string Writer::error() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->error;
}

bool Writer::stopped() const { return impl_->stopped.load(std::memory_order_relaxed); }

const std::string& Writer::path() const { return impl_->path; }

uint64_t Writer::bytes_written() const { return impl_->bytes; }

// --- Reader ------------------------------------------------------------------------------------

struct Reader::Impl {
  std::string path;
  sqlite3* db = nullptr;
  Header header;
  uint64_t last_step = 0;

  RecordingError Error(const std::string& why) const {
    return RecordingError("cannot read the recording " + path + ": " + why);
  }

  // reads the meta table, turning SQLite's refusals into messages that say what the file is
  void ReadHeader() {
    std::vector<std::pair<std::string, std::string>> meta;
    try {
      Statement s(db, "SELECT key, value FROM meta");
      while (s.Step()) meta.emplace_back(s.Text(0), s.Text(1));
    } catch (const std::exception& e) {
      const int code = sqlite3_errcode(db);
      const std::string what = e.what();
      if (code == SQLITE_NOTADB)
        throw Error("not an SQLite file, so not a Caliper recording (" + what + ")");
      if (what.find("no such table") != std::string::npos)
        throw Error("an SQLite file but not a Caliper recording (it has no meta table)");
      throw;
    }
    auto get = [&](const std::string& key) -> std::string {
      for (const auto& kv : meta)
        if (kv.first == key) return kv.second;
      throw Error("its meta table has no " + key);
    };
    std::string format;
    for (const auto& kv : meta)
      if (kv.first == "format") format = kv.second;
    if (format != kFormat)
      throw Error("an SQLite file but not a Caliper recording (format is '" + format +
                  "', expected '" + kFormat + "')");
    const std::string version = get("format_version");
    if (version != std::to_string(kFormatVersion))
      throw Error("format version " + version + ", this build reads version " +
                  std::to_string(kFormatVersion));
    try {
      header.model_name = get("model_name");
      header.scene_file_name = get("scene_file_name");
      header.time_step = std::stod(get("time_step_s"));
      header.keyframe_every = static_cast<uint32_t>(std::stoul(get("keyframe_every")));
      header.channels_every = static_cast<uint32_t>(std::stoul(get("channels_every")));
      header.first_step = std::stoull(get("first_step"));
      for (const auto& kv : meta)
        if (kv.first == "engine") header.engine = kv.second;
    } catch (const std::logic_error& e) {  // stod/stoul: not a number
      throw Error(std::string("a meta value is not a number (") + e.what() + ")");
    }
    // what a replay divides by and steps toward: refused here rather than met there
    if (!(header.time_step > 0 && header.time_step <= 0.1))
      throw Error("its time step " + std::to_string(header.time_step) + " s is not in (0, 0.1] s");
    if (header.keyframe_every < 1)
      throw Error("its keyframe_every is 0: keyframes at least every step");
    Statement c(db, "SELECT id, unit, rows, cols FROM channels ORDER BY position");
    while (c.Step()) {
      Channel ch;
      ch.id = c.Text(0);
      ch.unit = c.Text(1);
      ch.rows = static_cast<uint32_t>(c.Int(2));
      ch.cols = static_cast<uint32_t>(c.Int(3));
      header.channels.push_back(ch);
    }
    last_step = header.first_step;
    for (const char* sql : {"SELECT max(step) FROM keyframes", "SELECT max(step) FROM events",
                            "SELECT max(step) FROM samples", "SELECT max(step) FROM scenes"})
      last_step = std::max<uint64_t>(last_step, static_cast<uint64_t>(QueryInt(db, sql)));
  }

  size_t Width() const {
    size_t width = 0;
    for (const auto& c : header.channels) width += static_cast<size_t>(c.rows) * c.cols;
    return width;
  }
};

Reader::Reader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  if (!FileExists(path)) throw impl_->Error("the file does not exist");
  try {
    // Read-only; a killed writer's write-ahead log is still read (SQLite recovers the index in
    // the -shm file, which it may create or write even for a read-only connection).
    if (sqlite3_open_v2(path.c_str(), &impl_->db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK)
      throw std::runtime_error(impl_->db ? sqlite3_errmsg(impl_->db) : "out of memory");
    try {
      impl_->ReadHeader();
    } catch (const std::runtime_error& e) {
      const int code = sqlite3_extended_errcode(impl_->db);
      if ((code & 0xff) != SQLITE_READONLY && (code & 0xff) != SQLITE_CANTOPEN) throw;
      // the write-ahead log's index cannot be rebuilt read-only (no -shm and none can be made
      // by a read-only connection): open read-write, and never write (query_only)
      sqlite3_close(impl_->db);
      impl_->db = nullptr;
      if (sqlite3_open_v2(path.c_str(), &impl_->db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK)
        throw std::runtime_error(
            std::string("its write-ahead log (") + path +
            "-wal) needs recovery, which a read-only open cannot do (" + e.what() +
            "), and the file cannot be opened for writing either: copy it with its -wal file "
            "to a writable place");
      Exec(impl_->db, "PRAGMA query_only=1");
      impl_->ReadHeader();
    }
  } catch (const SqlError& e) {
    sqlite3_close(impl_->db);
    throw impl_->Error(e.what());
  } catch (const RecordingError&) {
    sqlite3_close(impl_->db);
    throw;
  } catch (const std::exception& e) {
    sqlite3_close(impl_->db);
    throw impl_->Error(e.what());
  }
}

Reader::~Reader() { sqlite3_close(impl_->db); }

const Header& Reader::header() const { return impl_->header; }

uint64_t Reader::last_step() const { return impl_->last_step; }

double Reader::duration() const {
  return static_cast<double>(impl_->last_step - impl_->header.first_step) * impl_->header.time_step;
}

std::vector<SceneVersion> Reader::scenes() const try {
  std::vector<SceneVersion> out;
  Statement s(impl_->db, "SELECT version, step, file_name, data FROM scenes ORDER BY version");
  while (s.Step()) {
    SceneVersion v;
    v.version = static_cast<uint32_t>(s.Int(0));
    v.step = static_cast<uint64_t>(s.Int(1));
    v.file_name = s.Text(2);
    v.bytes = s.Blob(3);
    out.push_back(std::move(v));
  }
  return out;
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

std::vector<uint64_t> Reader::keyframe_steps() const try {
  std::vector<uint64_t> out;
  Statement s(impl_->db, "SELECT step FROM keyframes ORDER BY step");
  while (s.Step()) out.push_back(static_cast<uint64_t>(s.Int(0)));
  return out;
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

Keyframe Reader::KeyframeAtOrBefore(uint64_t step) const try {
  Statement s(impl_->db,
              "SELECT step, time_s, scene_version, state FROM keyframes WHERE step <= ? "
              "ORDER BY step DESC LIMIT 1");
  s.Bind(1, static_cast<int64_t>(step));
  if (!s.Step()) throw impl_->Error("no keyframe at or before step " + std::to_string(step));
  Keyframe k;
  k.step = static_cast<uint64_t>(s.Int(0));
  k.time = s.Real(1);
  k.scene_version = static_cast<uint32_t>(s.Int(2));
  try {
    k.state = DecodeState(s.Blob(3));
  } catch (const RecordingError& e) {
    throw impl_->Error("the keyframe at step " + std::to_string(k.step) + " is " + e.what());
  }
  return k;
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

namespace {

// the rows of `table` with first <= step < last, in `order`: step, then `columns` (the last a
// `vals` blob of packed doubles), each handed to `row` with its values unpacked; `what` names a
// row in the message about a malformed blob
template <class Row>
void ReadRange(sqlite3* db, const std::string& table, const std::string& columns,
               const std::string& order, uint64_t first, uint64_t last, const char* what,
               int vals_column, const std::function<RecordingError(const std::string&)>& error,
               Row&& row) {
  Statement s(db, "SELECT step, " + columns + " FROM " + table +
                      " WHERE step >= ? AND step < ? ORDER BY " + order);
  s.Bind(1, static_cast<int64_t>(first));
  s.Bind(2, static_cast<int64_t>(last));
  std::vector<double> values;
  while (s.Step()) {
    const uint64_t step = static_cast<uint64_t>(s.Int(0));
    const std::string vals = s.Blob(vals_column);
    if (!UnpackDoubles(vals.data(), static_cast<int>(vals.size()), &values))
      throw error(std::string("the ") + what + " at step " + std::to_string(step) + " has " +
                  std::to_string(vals.size()) + " bytes of values, not a multiple of 8");
    row(s, step, std::move(values));
  }
}

}  // namespace

std::vector<Event> Reader::Events(uint64_t first, uint64_t last) const try {
  std::vector<Event> out;
  ReadRange(impl_->db, "events", "kind, target, vals", "seq", first, last, "event", 3,
            [&](const std::string& m) { return impl_->Error(m); },
            [&](Statement& s, uint64_t step, std::vector<double> values) {
              out.push_back({step, s.Text(1), s.Text(2), std::move(values)});
            });
  return out;
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

std::vector<Sample> Reader::Samples(uint64_t first, uint64_t last) const try {
  std::vector<Sample> out;
  ReadRange(impl_->db, "samples", "time_s, vals", "step", first, last, "sample", 2,
            [&](const std::string& m) { return impl_->Error(m); },
            [&](Statement& s, uint64_t step, std::vector<double> values) {
              out.push_back({step, s.Real(1), std::move(values)});
            });
  return out;
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

std::vector<LogRecord> Reader::Log() const try {
  std::vector<LogRecord> out;
  Statement s(impl_->db,
              "SELECT time_s, priority, category, component, message FROM log ORDER BY seq");
  while (s.Step()) {
    LogRecord r;
    r.time = s.Real(0);
    r.priority = s.Text(1);
    r.category = s.Text(2);
    r.component = s.Text(3);
    r.message = s.Text(4);
    out.push_back(std::move(r));
  }
  return out;
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

void Reader::ExportCsv(const std::string& csv_path) const try {
  const Header& h = impl_->header;
  const size_t width = impl_->Width();
  if (width == 0) throw impl_->Error("it holds no channels to export to " + csv_path);
  // the same column names as caliper-ctl record: `id [unit]`, `id[i] [unit]`, `id[r][c] [unit]`
  std::string text = "time [s]";
  for (const auto& c : h.channels) {
    const std::string unit = " [" + (c.unit.empty() ? std::string("-") : c.unit) + "]";
    if (c.rows == 1 && c.cols == 1) {
      text += "," + c.id + unit;
    } else if (c.rows == 1 || c.cols == 1) {
      for (uint32_t i = 0; i < c.rows * c.cols; ++i)
        text += "," + c.id + "[" + std::to_string(i) + "]" + unit;
    } else {
      for (uint32_t r = 0; r < c.rows; ++r)
        for (uint32_t k = 0; k < c.cols; ++k)
          text += "," + c.id + "[" + std::to_string(r) + "][" + std::to_string(k) + "]" + unit;
    }
  }
  text += "\n";
  // a file written whole to a temporary and renamed: a failed export leaves no truncated CSV
  const std::string part = csv_path + ".part";
  std::ofstream out(part, std::ios::binary | std::ios::trunc);
  if (!out) throw impl_->Error("cannot write " + part + ": " + std::strerror(errno));
  Statement s(impl_->db, "SELECT step, time_s, vals FROM samples ORDER BY step");
  std::vector<double> values;
  while (s.Step()) {
    const std::string vals = s.Blob(2);
    if (!UnpackDoubles(vals.data(), static_cast<int>(vals.size()), &values) ||
        values.size() != width) {
      out.close();
      std::remove(part.c_str());
      throw impl_->Error("the sample at step " + std::to_string(s.Int(0)) + " has " +
                         std::to_string(vals.size()) + " bytes of values, " +
                         std::to_string(width * 8) + " expected");
    }
    text += ExactText(s.Real(1));
    for (double v : values) text += "," + ExactText(v);
    text += "\n";
    if (text.size() > (1 << 20)) {
      out << text;
      text.clear();
    }
  }
  out << text;
  out.close();
  if (!out) {
    std::remove(part.c_str());
    throw impl_->Error("cannot write " + part + " (disk full?)");
  }
  if (std::rename(part.c_str(), csv_path.c_str()) != 0) {
    const int err = errno;
    std::remove(part.c_str());
    throw impl_->Error("cannot rename " + part + " to " + csv_path + ": " + std::strerror(err));
  }
} catch (const SqlError& e) {  // SQLite's refusal: name the file
  throw impl_->Error(e.what());
}

}  // namespace caliper::recording
