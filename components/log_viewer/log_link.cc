#include "log_link.h"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "caliper/logging.hh"
#include "caliper/rtc/naming.h"
#include "listener_servant.h"

namespace caliper::log_viewer {

namespace L = ::Caliper::Logging;
using Clock = std::chrono::steady_clock;

/// The worker's CORBA state; touched by the worker thread only (after construction).
struct LogLink::Impl {
  CORBA::ORB_var orb;
  PortableServer::POA_var poa;
  PortableServer::ObjectId_var servant_id;
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

CORBA::ORB_ptr ProcessOrb() {
  int argc = 0;
  char* argv[] = {nullptr};
  return CORBA::ORB_init(argc, argv);
}

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

}  // namespace

LogLink::LogLink(Options options)
    : options_(std::move(options)),
      inbox_(std::make_shared<LiveInbox>()),
      impl_(std::make_unique<Impl>()) {
  Impl& i = *impl_;
  i.orb = ProcessOrb();
  CORBA::Object_var obj = i.orb->resolve_initial_references("RootPOA");
  i.poa = PortableServer::POA::_narrow(obj);
  PortableServer::POAManager_var manager = i.poa->the_POAManager();
  manager->activate();
  auto* servant = new ListenerServant(inbox_);
  i.servant_id = i.poa->activate_object(servant);
  servant->_remove_ref();  // the POA owns it
  CORBA::Object_var ref = i.poa->id_to_reference(i.servant_id);
  i.listener = L::LogListener::_narrow(ref);
  status_.message = "looking for " + options_.instance + " ...";
  worker_ = std::thread([this] { Run(); });
}

LogLink::~LogLink() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  worker_.join();
  try {
    impl_->poa->deactivate_object(impl_->servant_id);
  } catch (const CORBA::Exception&) {
    // the ORB is already shutting down: nothing left to deactivate
  }
}

std::vector<logging::Record> LogLink::Take() { return inbox_->Take(); }

LinkStatus LogLink::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

void LogLink::Run() {
  // per-thread call timeouts need an omni_thread
  omni_thread* self = omni_thread::create_dummy();
  Impl& i = *impl_;
  const auto short_ms = static_cast<CORBA::ULong>(options_.call_timeout_ms);
  omniORB::setClientThreadCallTimeout(short_ms);

  // unregisters (best effort) and records why the connection is gone
  auto drop = [&](const std::string& why) {
    inbox_->Stop();
    if (!CORBA::is_nil(i.logger)) {
      try {
        i.logger->remove_listener(i.listener_id);
      } catch (const CORBA::Exception&) {
        // a logger that is gone has forgotten its listeners already
      }
    }
    i.logger = L::LogService::_nil();
    i.bound = CORBA::Object::_nil();
    std::lock_guard<std::mutex> lock(mutex_);
    status_.connected = false;
    status_.message = why;
  };

  auto connect = [&] {
    try {
      omniORB::setClientThreadCallTimeout(short_ms);
      CosNaming::NamingContext_var root =
          rtc::ResolveRoot(i.orb, rtc::NamingAddress(options_.nameservice));
      rtc::ComponentEntry entry = rtc::FindComponent(root, options_.instance);
      L::LogService_var logger = L::LogService::_narrow(entry.object);
      if (CORBA::is_nil(logger))
        throw std::runtime_error(entry.path + " is not a Logging component");
      CORBA::String_var file = logger->session_file();
      // listen first, then ask for the backlog: nothing falls between the two
      inbox_->BeginSync(file.in());
      const uint64_t after = inbox_->last_serial();
      i.listener_id = logger->add_listener(i.listener);
      i.logger = logger;
      i.bound = entry.object;
      i.session_file = file.in();
      i.path = entry.path;
      i.waiting_since = Impl::kNone;
      omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.query_timeout_ms));
      L::StoredRecordSeq_var backlog = logger->query(Everything(after));
      inbox_->Synced(FromIdl(backlog.in()));
      std::lock_guard<std::mutex> lock(mutex_);
      status_.connected = true;
      status_.message = "following " + options_.instance + " (" + i.path + ")";
      status_.session_file = i.session_file;
      ++status_.registrations;
    } catch (const L::InvalidQuery& e) {
      drop("no connection to " + options_.instance + ": " + e.reason.in());
    } catch (const CORBA::Exception& e) {
      drop("no connection to " + options_.instance + ": " + rtc::Describe(e));
    } catch (const std::exception& e) {
      drop("no connection to " + options_.instance + ": " + e.what());
    }
  };

  // true while the registered logger answers and is still the one bound under its name
  auto check = [&]() -> bool {
    try {
      omniORB::setClientThreadCallTimeout(short_ms);
      CORBA::String_var file = i.logger->session_file();
      if (i.session_file != file.in()) {
        drop(options_.instance + " started a new session log; registering again");
        return false;
      }
      // the logger drops a listener it failed to reach once: records that wait a whole period
      // while none arrive mean that happened
      const uint64_t last = inbox_->last_serial();
      L::RecordFilter newest = Everything(last);
      newest.limit = 1;
      L::StoredRecordSeq_var waiting = i.logger->query(newest);
      if (waiting->length() == 0) {
        i.waiting_since = Impl::kNone;
      } else if (i.waiting_since == last) {
        drop(options_.instance + " stopped sending records; registering again");
        return false;
      } else {
        i.waiting_since = last;
      }
    } catch (const CORBA::Exception& e) {
      drop("no connection to " + options_.instance + ": " + rtc::Describe(e) +
           " (the logger may have died); retrying");
      return false;
    }
    try {
      CosNaming::NamingContext_var root =
          rtc::ResolveRoot(i.orb, rtc::NamingAddress(options_.nameservice));
      rtc::ComponentEntry entry = rtc::FindComponent(root, options_.instance);
      if (!entry.object->_is_equivalent(i.bound)) {
        drop(options_.instance + " was started again; registering again");
        return false;
      }
    } catch (const CORBA::Exception&) {
      // the naming service being away does not disturb a logger that answers
    } catch (const std::exception&) {
    }
    return true;
  };

  auto next = Clock::now();
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait_until(lock, next, [&] { return stopping_; });
      if (stopping_) break;
    }
    if (CORBA::is_nil(i.logger) || !check()) connect();
    next = Clock::now() + std::chrono::milliseconds(CORBA::is_nil(i.logger)
                                                        ? options_.retry_period_ms
                                                        : options_.check_period_ms);
  }
  omniORB::setClientThreadCallTimeout(short_ms);
  drop("stopped");
  if (self != nullptr) omni_thread::release_dummy();
}

}  // namespace caliper::log_viewer
