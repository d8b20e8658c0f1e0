#pragma once
// The manager's children as processes, without CORBA: starts them (fork/exec), reaps them, caps
// how many run and remembers how the last ones ended.

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace caliper::manager {

/// As many children run as may (the message says how many and how to allow more).
class CapacityReached : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A child could not be started, or ended or hung before it was ready.
class StartFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// No child of that name, or a type the manager does not start.
class UnknownComponent : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One child as clients see it.
struct ChildStatus {
  std::string instance;     ///< bound name, e.g. model3 ("" until it registered)
  std::string type;         ///< model
  pid_t pid = 0;
  std::string naming_path;  ///< host.host_cxt/model3.rtc ("" until it registered)
  std::string output_file;  ///< its stdout and stderr
  bool running = true;
  std::string state;        ///< starting | running | exited with code N | killed by signal N
  double uptime = 0;        ///< [s] from start until now, or until it ended
};

struct SupervisorOptions {
  size_t max_running = 1;                  ///< children that may run at once
  std::string capacity_key;                ///< the setting that raises max_running, for messages
  std::string output_dir;                  ///< `<type>-<pid>.out` files go here (must exist)
  std::chrono::milliseconds grace{5000};   ///< from TERM to KILL when stopping a child
  size_t keep_ended = 50;                  ///< ended children remembered for List()
};

/// Starts, reaps and stops child processes. One thread of its own forks every child (the
/// parent-death signal follows the forking thread, so no short-lived thread may fork) and polls
/// for ended children every 100 ms; no SIGCHLD handler is involved. A child runs in its own
/// process group with signals unblocked, its output in `<output_dir>/<type>-<pid>.out`, and gets
/// SIGTERM when this process dies. An unexpected end is logged as an error (category manager).
/// Thread-safe.
class Supervisor {
 public:
  explicit Supervisor(SupervisorOptions options);
  /// Stops every running child (StopAll).
  ~Supervisor();
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Starts `argv` (argv[0] a path) as a child of `type`, in state "starting". Throws
  /// CapacityReached when max_running children run, StartFailed when it cannot be executed or
  /// the supervisor stops.
  pid_t Start(const std::string& type, const std::vector<std::string>& argv);
  /// A started child is ready as `instance` at `naming_path` (state "running").
  void SetRegistered(pid_t pid, const std::string& instance, const std::string& naming_path);
  /// Stops a running child (TERM, KILL after the grace period), waits until it is reaped and
  /// forgets it; an ended child is just forgotten. Throws UnknownComponent for a pid it does not
  /// know.
  void Stop(pid_t pid);
  /// Stops every running child the same way and refuses new ones.
  void StopAll();

  /// The pid of the child named `instance`; UnknownComponent naming the children it has.
  pid_t PidOf(const std::string& instance) const;
  std::optional<ChildStatus> Status(pid_t pid) const;
  /// Running children, then ended ones, each in start order.
  std::vector<ChildStatus> List() const;
  size_t running() const;
  size_t capacity() const { return options_.max_running; }

 private:
  using Clock = std::chrono::steady_clock;
  struct Child {
    ChildStatus status;
    Clock::time_point started;
    Clock::time_point ended;
    int wait_status = 0;
    bool stopping = false;  // we stop it: its end is no error
  };
  struct StartRequest {
    std::string type;
    std::vector<std::string> argv;
    std::promise<pid_t> result;
  };

  void Run();
  pid_t Spawn(const std::string& type, const std::vector<std::string>& argv);
  /// Reaps what ended; returns the error messages to log (outside the lock).
  std::vector<std::string> ReapLocked();
  /// TERM, then KILL after the grace period, to the running ones of `pids`; waits for their end.
  void Terminate(const std::vector<pid_t>& pids, std::unique_lock<std::mutex>& lock);
  ChildStatus StatusLocked(const Child& child) const;
  size_t RunningLocked() const;
  std::string NamesLocked() const;

  const SupervisorOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;     // the supervisor thread: a request or stop
  std::condition_variable changed_;  // waiters: a child ended
  std::map<pid_t, Child> children_;
  std::deque<StartRequest> requests_;
  bool closed_ = false;
  bool stop_thread_ = false;
  std::thread thread_;
};

/// The last `lines` lines of a text file ("" when it cannot be read).
std::string TailOfFile(const std::string& path, size_t lines);

}  // namespace caliper::manager
