#pragma once
// The Log Viewer's connection to the Logging component: a worker thread finds the logger
// (`logger0`) in the naming service, registers a LogListener with it, asks for what it already
// holds, checks it every second and registers again when it was restarted, its session changed
// or it stopped sending records (a logger drops a listener it once failed to reach).
// Records arrive on ORB threads into an inbox that the GUI empties with Take(), so that the GUI
// never waits on CORBA. No Qt here; CORBA stays in the .cc files.

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "caliper/logging/record.h"
#include "live_inbox.h"

namespace caliper::log_viewer {

/// The connection as the GUI shows it.
struct LinkStatus {
  bool connected = false;      ///< a listener is registered with a logger that answers
  std::string message;         ///< what is going on, e.g. why there is no connection
  std::string session_file;    ///< the logger's session log (when connected once)
  uint64_t registrations = 0;  ///< how many times a listener was registered (reconnections)
};

/// The worker. Every public method returns at once.
class LogLink {
 public:
  struct Options {
    std::string nameservice;           ///< corbaname::HOST:PORT; "" for the default
    std::string instance = "logger0";  ///< the Logging component's instance name
    int call_timeout_ms = 2000;        ///< every short call (lookup, register, ping)
    int query_timeout_ms = 30000;      ///< the first query, which may carry 200,000 records
    int check_period_ms = 1000;        ///< how often a connected logger is checked
    int retry_period_ms = 1000;        ///< how often an unreachable logger is looked for
  };

  /// Uses the process's ORB (initialises one when there is none), activates the listener in its
  /// RootPOA and starts the worker.
  explicit LogLink(Options options);
  /// Unregisters the listener (waiting at most call_timeout_ms) and stops the worker.
  ~LogLink();
  LogLink(const LogLink&) = delete;
  LogLink& operator=(const LogLink&) = delete;

  /// The records that arrived since the last call, oldest first.
  std::vector<logging::Record> Take();
  LinkStatus status() const;
  const Options& options() const { return options_; }

  struct Impl;

 private:
  void Run();

  Options options_;
  std::shared_ptr<LiveInbox> inbox_;
  std::unique_ptr<Impl> impl_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  LinkStatus status_;
  std::thread worker_;
};

}  // namespace caliper::log_viewer
