#pragma once
// The Log Viewer's connection to the Logging component: a worker thread finds the logger
// (`logger0`) in the naming service, registers a LogListener with it, asks for what it already
// holds (in pages), checks it every second and registers again when it was restarted, its session
// changed or it stopped sending records (a logger drops a listener it once failed to reach). A
// jump in the pushed serials (the logger drops the oldest records of a listener 100,000 behind)
// is queried at once. Records arrive on ORB threads into an inbox that the GUI empties with Take(),
// so that the GUI never waits on CORBA; the destructor waits a bounded time for the worker. No
// Qt here; CORBA stays in the .cc files.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "caliper/client/worker.h"
#include "caliper/logging/record.h"
#include "live_inbox.h"

namespace caliper::log_viewer {

/// The connection as the GUI shows it.
struct LinkStatus {
  bool connected = false;          ///< a listener is registered with a logger that answers
  std::string message;             ///< what is going on, e.g. why there is no connection
  std::string session_file;        ///< the logger's session log (when connected once)
  uint64_t registrations = 0;      ///< how many times a listener was registered (reconnections)
  uint64_t lost = 0;               ///< records of the session the logger no longer held for us
  uint64_t listener_failures = 0;  ///< pushed batches that could not be taken in
  std::string listener_failure;    ///< why the last of them could not
};

/// The worker. Every public method returns at once; the destructor within
/// Options::stop_timeout_ms.
class LogLink {
 public:
  struct Options {
    std::string nameservice;           ///< corbaname::HOST:PORT; "" for the default
    std::string instance = "logger0";  ///< the Logging component's instance name
    int call_timeout_ms = 2000;        ///< every short call (lookup, register, ping, unregister)
    /// Each query for a page of records (a few tens of ms for a local logger).
    int query_timeout_ms = 3000;
    /// Records asked for per query: the backlog and gaps come in pages, since a reply must stay
    /// under omniORB's 2 MB message limit. Halved when a reply does not fit or come in time.
    int page_records = 5000;
    int check_period_ms = 1000;  ///< how often a connected logger is checked
    int retry_period_ms = 1000;  ///< how often an unreachable logger is looked for
    /// How long the destructor waits for the worker to unregister and end; a worker still
    /// inside a call then (a logger that stopped answering mid-query) is left to end on its own.
    int stop_timeout_ms = 3000;
  };

  /// Uses the process's ORB (initialises one when there is none), activates the listener in its
  /// RootPOA and starts the worker.
  explicit LogLink(Options options);
  /// Stops the worker, which unregisters the listener (each call waiting at most
  /// call_timeout_ms); returns after stop_timeout_ms at most.
  ~LogLink();
  LogLink(const LogLink&) = delete;
  LogLink& operator=(const LogLink&) = delete;

  /// The records that arrived since the last call, oldest first.
  std::vector<logging::Record> Take();
  LinkStatus status() const;
  const Options& options() const { return options_; }

  /// The worker's state, shared with it: a worker left inside a call outlives the LogLink.
  struct Impl;

 private:
  Options options_;
  std::shared_ptr<Impl> impl_;
  std::unique_ptr<client::Worker> worker_;  // its hooks share impl_
};

}  // namespace caliper::log_viewer
