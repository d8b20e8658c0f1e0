#pragma once
// The background worker of a client's link to a component (the GUI tools' ModelLink, DaqLink and
// LogLink): one thread known to omniORB that runs jobs posted from any thread, in order, and a
// periodic tick (poll a status, look a lost peer up again), and that stops within a bound even
// while it is stuck in a call to a peer that stopped answering.
//
//   client::Worker::Hooks hooks;
//   hooks.start = [] { omniORB::setClientThreadCallTimeout(1500); };
//   hooks.tick = [link] { link->Poll(); };              // every period
//   client::Worker worker({std::chrono::milliseconds(200)}, std::move(hooks));
//   worker.Start();
//   worker.Post([link] { link->model()->start(); });    // from the GUI thread: never waits
//
// The caller never waits on the worker, but in Stop() (and the destructor). Jobs and hooks run on
// the worker thread only, one at a time, so the state they share needs no lock of its own.
// Whatever a job or hook captures must outlive the thread: with a bounded stop a worker stuck in
// a call is left to end on its own, so capture shared state (std::shared_ptr), not `this`.
// No CORBA and no Qt in this header.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

namespace caliper::client {

namespace internal {
struct WorkerState;
}  // namespace internal

/// A weak, copyable reference to a Worker's queue and flags, for code that runs on the worker
/// thread (its jobs and hooks) and may outlive the Worker object itself. Every method is safe from
/// any thread; once the worker thread has ended and the Worker is destroyed, Post() drops its job
/// and stopping() is true. A default-constructed handle refers to no worker (it behaves the same).
class WorkerHandle {
 public:
  /// A handle to no worker: Post() drops, stopping() is true.
  WorkerHandle() = default;

  /// Queues `job` to run on the worker thread after the jobs posted before it (FIFO). Never
  /// blocks. Returns false, dropping the job (on the calling thread), when the worker is stopping
  /// or gone.
  bool Post(std::function<void()> job) const;
  /// Moves the next tick to `delay` from now [ms] (0: at once), replacing the one scheduled; the
  /// ticks after it follow the period again. Wakes the worker.
  void TickIn(std::chrono::milliseconds delay) const;
  /// Sets the period between the starts of two ticks [ms], from the next tick scheduled on (the
  /// one already scheduled keeps its time; TickIn moves it).
  void set_period(std::chrono::milliseconds period) const;
  /// True once Stop() was called (or the worker is gone): a job or hook in the middle of a long
  /// piece of work checks it between calls and returns early.
  bool stopping() const;

 private:
  friend class Worker;
  explicit WorkerHandle(std::weak_ptr<internal::WorkerState> state) : state_(std::move(state)) {}
  std::weak_ptr<internal::WorkerState> state_;
};

/// Owns the worker thread. The thread runs, in this order: Hooks::start once; then, at every
/// wake-up, the jobs queued (FIFO, each once), Hooks::after_jobs when there were any, and
/// Hooks::tick when a tick is due; after Stop(), Hooks::finish once. The first tick comes at once
/// after start. Each tick is due one period after the start of the previous one, unless TickIn()
/// moved it. Jobs not yet begun when Stop() is called are dropped.
///
/// An exception that escapes a job or hook is caught (C++ and CORBA ones, with their message),
/// counted in failures() and the worker carries on: a job should catch what it can handle itself.
/// The thread is known to omniORB (rtc::OmniThread) for its lifetime, so that per-thread call
/// timeouts (omniORB::setClientThreadCallTimeout) work in jobs and hooks.
class Worker {
 public:
  /// Stop() bound that waits without a limit.
  static constexpr std::chrono::milliseconds kForever = std::chrono::milliseconds::max();

  /// What the worker thread runs besides its jobs; every hook may be empty.
  struct Hooks {
    /// Once, first, on the worker thread (set call timeouts here).
    std::function<void()> start;
    /// At every tick (poll the peer, look it up again while it is lost).
    std::function<void()> tick;
    /// After the jobs of a wake-up have run, before a tick that is due (work that follows a
    /// batch of jobs once, however many there were).
    std::function<void()> after_jobs;
    /// Once, last, after Stop() (unregister, unsubscribe; bound each call by a short timeout).
    std::function<void()> finish;
  };

  /// How the worker keeps time.
  struct Options {
    /// Between the starts of two ticks [ms]; set_period() changes it later.
    std::chrono::milliseconds period{1000};
    /// How long the destructor waits for the worker thread to end [ms] (see Stop()); kForever
    /// waits for it, however long its current call takes.
    std::chrono::milliseconds stop_timeout{kForever};
  };

  /// Makes the worker; no thread runs until Start().
  Worker(Options options, Hooks hooks);
  /// Stop(options.stop_timeout).
  ~Worker();
  /// Not copyable: one owner per thread.
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  /// Starts the worker thread (once; later calls do nothing). Jobs posted before are kept.
  void Start();

  /// Asks the worker to stop and waits for it: for the job or hook under way to return, then
  /// Hooks::finish. Returns true when the thread ended within `bound` [ms] (kForever: no limit)
  /// and was joined; false when it did not (it is left to end on its own: it makes no further
  /// tick or job, runs Hooks::finish when its call returns, and keeps alive what its hooks
  /// captured until then), or when called from the worker thread itself (which cannot wait for
  /// itself). Later calls return at once: true when the thread ended meanwhile. Thread-safe.
  bool Stop(std::chrono::milliseconds bound = kForever);

  /// See WorkerHandle::Post.
  bool Post(std::function<void()> job) { return handle().Post(std::move(job)); }
  /// See WorkerHandle::TickIn.
  void TickIn(std::chrono::milliseconds delay) { handle().TickIn(delay); }
  /// See WorkerHandle::set_period.
  void set_period(std::chrono::milliseconds period) { handle().set_period(period); }
  /// See WorkerHandle::stopping.
  bool stopping() const { return handle().stopping(); }
  /// A handle for the worker's own jobs and hooks (it does not keep the worker alive).
  WorkerHandle handle() const { return WorkerHandle(state_); }

  /// How many exceptions escaped a job or hook (thread-safe).
  std::uint64_t failures() const;
  /// The message of the last of them ("" when none; thread-safe).
  std::string last_failure() const;
  /// True on the worker thread (from a job or hook).
  bool on_worker_thread() const;

 private:
  std::shared_ptr<internal::WorkerState> state_;
  std::chrono::milliseconds stop_timeout_;
  std::thread thread_;
};

}  // namespace caliper::client
