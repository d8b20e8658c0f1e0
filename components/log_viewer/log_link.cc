#include "log_link.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "caliper/client/session.h"
#include "caliper/logging.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "listener_servant.h"

namespace caliper::log_viewer {

namespace L = ::Caliper::Logging;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// The worker's state. The CORBA part is set up by the constructor and then touched by the
// worker thread only (its hooks and jobs); `status` is guarded by `mutex`.
struct LogLink::Impl {
  explicit Impl(LogLink::Options o)
      : options(std::move(o)),
        inbox(std::make_shared<LiveInbox>()),
        short_ms(static_cast<CORBA::ULong>(options.call_timeout_ms)),
        query_ms(static_cast<CORBA::ULong>(options.query_timeout_ms)) {}

  void Tick();
  void FillGaps();
  bool FetchAfter(uint64_t after_serial, std::vector<LiveRecord>* out);
  void Connect();
  bool Check();
  void FillGap();
  void Drop(const std::string& why);
  // every call the worker makes from now on waits at most `ms`: per thread (the naming service's
  // objects; needs -ORBsupportPerThreadTimeOut 1) and on the logger's reference (always works)
  void Limit(CORBA::ULong ms, CORBA::Object_ptr target = CORBA::Object::_nil()) {
    omniORB::setClientThreadCallTimeout(ms);
    if (!CORBA::is_nil(target)) omniORB::setClientCallTimeout(target, ms);
  }
  bool Stopping() const { return worker.stopping(); }

  const LogLink::Options options;
  const std::shared_ptr<LiveInbox> inbox;
  const CORBA::ULong short_ms;
  const CORBA::ULong query_ms;

  client::WorkerHandle worker;  // the thread that runs Tick and FillGaps

  std::mutex mutex;
  LinkStatus status;

  CORBA::ORB_var orb;
  PortableServer::POA_var poa;
  PortableServer::ObjectId_var servant_id;
  PortableServer::ServantBase_var servant;  // one reference: status() reads its counters
  ListenerServant* listener_servant = nullptr;
  L::LogListener_var listener;
  L::LogService_var logger;  // nil while not registered
  CORBA::Object_var bound;   // what the name was bound to when we registered
  CORBA::ULongLong listener_id = 0;
  std::string session_file;
  std::string path;  // the logger's naming path
  // the last serial taken in when the previous check saw newer records waiting; kNone when none
  uint64_t waiting_since = kNone;
  static constexpr uint64_t kNone = ~uint64_t{0};
};

namespace {

L::RecordFilter Everything(uint64_t after_serial) {
  L::RecordFilter q;
  q.max_priority = 0x7fffffff;
  q.category_prefix = "";
  q.instance = "";
  q.regex = "";
  q.from_time_us = 0;
  q.to_time_us = 0;
  q.after_serial = after_serial;
  q.limit = 0;
  return q;
}

// A time range of records, inclusive; the extremes stand for "no bound". Split points avoid 0
// and 1, so that no bound is ever 0 (which a RecordFilter reads as "no bound").
struct TimeWindow {
  int64_t from = std::numeric_limits<int64_t>::min();
  int64_t to = std::numeric_limits<int64_t>::max();
};

// A time that splits the records with `times` into two non-empty parts, about a quarter of them
// before it; false when there is none (they all have the same time, or they are all -1, 0, 1).
bool SplitTime(std::vector<int64_t> times, int64_t* split) {
  std::sort(times.begin(), times.end());
  const int64_t lo = times.front();
  const int64_t hi = times.back();
  if (lo == hi) return false;
  int64_t s = times[times.size() / 4];
  if (s == lo) s = *std::upper_bound(times.begin(), times.end(), lo);
  if (s == 0 || s == 1) {
    if (hi >= 2) {
      s = 2;
    } else if (lo <= -2) {
      s = -1;
    } else {
      return false;
    }
  }
  *split = s;
  return true;
}

}  // namespace

LogLink::LogLink(Options options)
    : options_(std::move(options)), impl_(std::make_shared<Impl>(options_)) {
  Impl& i = *impl_;
  i.status.message = "looking for " + options_.instance + " ...";
  // the worker's hooks share its state: a worker left inside a call outlives the LogLink
  client::Worker::Hooks hooks;
  hooks.start = [impl = impl_] { impl->Limit(impl->short_ms); };
  hooks.tick = [impl = impl_] { impl->Tick(); };
  hooks.finish = [impl = impl_] { impl->Drop("stopped"); };
  worker_ = std::make_unique<client::Worker>(
      client::Worker::Options{milliseconds(options_.retry_period_ms),
                              milliseconds(options_.stop_timeout_ms)},
      std::move(hooks));
  i.worker = worker_->handle();
  // a gap in the pushed serials: the worker queries it
  i.inbox->set_on_gap([worker = i.worker, weak = std::weak_ptr<Impl>(impl_)] {
    worker.Post([weak] {
      if (auto impl = weak.lock()) impl->FillGaps();
    });
  });
  i.orb = rtc::ClientOrb();
  CORBA::Object_var obj = i.orb->resolve_initial_references("RootPOA");
  i.poa = PortableServer::POA::_narrow(obj);
  PortableServer::POAManager_var manager = i.poa->the_POAManager();
  manager->activate();
  i.listener_servant = new ListenerServant(
      [inbox = i.inbox](std::vector<LiveRecord> records) { inbox->Push(std::move(records)); });
  i.servant = i.listener_servant;  // ours; activation adds the POA's reference
  i.servant_id = i.poa->activate_object(i.listener_servant);
  CORBA::Object_var ref = i.poa->id_to_reference(i.servant_id);
  i.listener = L::LogListener::_narrow(ref);
  worker_->Start();
}

LogLink::~LogLink() {
  Impl& i = *impl_;
  // the worker unregisters (Drop) and ends; one inside a call to a logger that stopped answering
  // is left to end when the call times out (the state it needs is shared with it); nothing it
  // takes in reaches anyone now
  worker_->Stop(milliseconds(options_.stop_timeout_ms));
  i.inbox->Stop();
  try {
    i.poa->deactivate_object(i.servant_id);
  } catch (const CORBA::Exception&) {
    // the ORB is already shutting down: nothing left to deactivate
  }
}

std::vector<logging::Record> LogLink::Take() { return impl_->inbox->Take(); }

LinkStatus LogLink::status() const {
  LinkStatus s;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    s = impl_->status;
  }
  s.lost = impl_->inbox->lost();
  s.listener_failures = impl_->listener_servant->failures();
  if (s.listener_failures > 0) s.listener_failure = impl_->listener_servant->last_failure();
  return s;
}

void LogLink::Impl::Drop(const std::string& why) {
  inbox->Stop();
  // unregistering never waits a query's timeout
  Limit(short_ms, logger);
  if (!CORBA::is_nil(logger)) {
    try {
      logger->remove_listener(listener_id);
    } catch (const CORBA::Exception&) {
      // a logger that is gone has forgotten its listeners already
    }
  }
  logger = L::LogService::_nil();
  bound = CORBA::Object::_nil();
  std::lock_guard<std::mutex> lock(mutex);
  status.connected = false;
  status.message = why;
}

bool LogLink::Impl::FetchAfter(uint64_t after_serial, std::vector<LiveRecord>* out) {
  // a reply of 200,000 records exceeds omniORB's 2 MB message limit, and the logger's `limit`
  // keeps the newest matches (it cannot page by serial): time windows instead, each split until
  // its records fit in a page; the stop flag is checked between pages
  constexpr CORBA::ULong kMinPage = 100;
  CORBA::ULong page = static_cast<CORBA::ULong>(std::max(options.page_records, 1));
  std::vector<TimeWindow> windows(1);
  while (!windows.empty()) {
    if (Stopping()) return false;
    const TimeWindow w = windows.back();
    L::RecordFilter q = Everything(after_serial);
    q.from_time_us = w.from == std::numeric_limits<int64_t>::min() ? 0 : w.from;
    q.to_time_us = w.to == std::numeric_limits<int64_t>::max() ? 0 : w.to;
    q.limit = page + 1;
    L::StoredRecordSeq_var answer;
    try {
      answer = logger->query(q);
    } catch (const CORBA::SystemException& e) {
      // too large a reply breaks the connection, too slow a one times out: smaller pages (a
      // logger that is gone or stopped fails those too)
      const bool retry = CORBA::COMM_FAILURE::_downcast(&e) != nullptr ||
                         CORBA::MARSHAL::_downcast(&e) != nullptr ||
                         CORBA::TIMEOUT::_downcast(&e) != nullptr;
      if (!retry || page <= kMinPage) throw;
      page /= 2;
      continue;
    }
    windows.pop_back();
    std::vector<LiveRecord> records = FromIdl(answer.in());
    std::vector<int64_t> times;
    int64_t split = 0;
    if (records.size() > page) {
      for (const auto& r : records) times.push_back(r.record.time_us);
    }
    if (records.size() <= page || !SplitTime(std::move(times), &split)) {
      // the whole window; or more than a page with one time stamp: its newest (the inbox counts
      // the older ones as lost)
      out->insert(out->end(), std::make_move_iterator(records.begin()),
                  std::make_move_iterator(records.end()));
      continue;
    }
    windows.push_back({w.from, split - 1});
    windows.push_back({split, w.to});
  }
  return true;
}

void LogLink::Impl::Connect() {
  const std::string& name = options.instance;
  try {
    Limit(short_ms);
    CosNaming::NamingContext_var root =
        rtc::ResolveRoot(orb, client::ResolveNamingAddress(options.nameservice));
    rtc::ComponentEntry entry = rtc::FindComponent(root, name);
    Limit(short_ms, entry.object);
    L::LogService_var found = L::LogService::_narrow(entry.object);
    if (CORBA::is_nil(found)) throw std::runtime_error(entry.path + " is not a Logging component");
    Limit(short_ms, found);
    CORBA::String_var file = found->session_file();
    if (Stopping()) return;
    // listen first, then ask for the backlog: nothing falls between the two
    inbox->BeginSync(file.in());
    const uint64_t after = inbox->last_serial();
    listener_id = found->add_listener(listener);
    logger = found;
    bound = entry.object;
    session_file = file.in();
    path = entry.path;
    waiting_since = kNone;
    if (Stopping()) return;  // the worker ends and unregisters
    {
      std::lock_guard<std::mutex> lock(mutex);
      status.message = "reading the records " + name + " holds ...";
      status.session_file = session_file;
    }
    Limit(query_ms, logger);
    std::vector<LiveRecord> backlog;
    if (!FetchAfter(after, &backlog)) return;
    Limit(short_ms, logger);
    inbox->Synced(std::move(backlog));
    std::lock_guard<std::mutex> lock(mutex);
    status.connected = true;
    status.message = "following " + name + " (" + path + ")";
    status.session_file = session_file;
    ++status.registrations;
  } catch (const L::InvalidQuery& e) {
    Drop("no connection to " + name + ": " + e.reason.in());
  } catch (const CORBA::Exception& e) {
    Drop("no connection to " + name + ": " + rtc::Describe(e));
  } catch (const std::exception& e) {
    Drop("no connection to " + name + ": " + e.what());
  }
}

bool LogLink::Impl::Check() {
  const std::string& name = options.instance;
  try {
    Limit(short_ms, logger);
    CORBA::String_var file = logger->session_file();
    if (session_file != file.in()) {
      Drop(name + " started a new session log; registering again");
      return false;
    }
    if (Stopping()) return true;
    // the logger drops a listener it failed to reach once: records that wait a whole period
    // while none arrive mean that happened
    const uint64_t last = inbox->last_serial();
    L::RecordFilter newest = Everything(last);
    newest.limit = 1;
    L::StoredRecordSeq_var waiting = logger->query(newest);
    if (waiting->length() == 0) {
      waiting_since = kNone;
    } else if (waiting_since == last) {
      Drop(name + " stopped sending records; registering again");
      return false;
    } else {
      waiting_since = last;
    }
  } catch (const CORBA::Exception& e) {
    Drop("no connection to " + name + ": " + rtc::Describe(e) +
         " (the logger may have died); retrying");
    return false;
  }
  if (Stopping()) return true;
  try {
    CosNaming::NamingContext_var root =
        rtc::ResolveRoot(orb, client::ResolveNamingAddress(options.nameservice));
    rtc::ComponentEntry entry = rtc::FindComponent(root, name);
    if (!entry.object->_is_equivalent(bound)) {
      Drop(name + " was started again; registering again");
      return false;
    }
  } catch (const CORBA::Exception&) {
    // the naming service being away does not disturb a logger that answers
  } catch (const std::exception&) {
  }
  return true;
}

void LogLink::Impl::FillGap() {
  // pushed serials jumped: everything after the last one taken in, the duplicates dropped
  const std::string& name = options.instance;
  const uint64_t after = inbox->last_serial();
  try {
    Limit(query_ms, logger);
    std::vector<LiveRecord> records;
    if (!FetchAfter(after, &records)) return;
    Limit(short_ms, logger);
    inbox->GapAnswered(after, std::move(records));
  } catch (const L::InvalidQuery& e) {
    Drop("no connection to " + name + ": " + e.reason.in());
  } catch (const CORBA::Exception& e) {
    Drop("no connection to " + name + ": " + rtc::Describe(e) +
         " (the logger may have died); retrying");
  } catch (const std::exception& e) {
    Drop("no connection to " + name + ": " + e.what() + "; retrying");
  }
}

void LogLink::Impl::FillGaps() {
  // records wait behind a gap: it comes before anything else
  while (!Stopping() && !CORBA::is_nil(logger) && inbox->gap_pending()) FillGap();
}

void LogLink::Impl::Tick() {
  FillGaps();
  if (Stopping()) return;
  if (CORBA::is_nil(logger) || !Check()) {
    if (Stopping()) return;
    Connect();
  }
  worker.TickIn(
      milliseconds(CORBA::is_nil(logger) ? options.retry_period_ms : options.check_period_ms));
}

}  // namespace caliper::log_viewer
