#include "caliper/client/worker.h"

#include <omniORB4/CORBA.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <utility>

#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"

namespace caliper::client {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

namespace internal {

// Shared by the Worker, its handles and its thread: the thread keeps it alive when the Worker
// left it to end on its own.
struct WorkerState {
  explicit WorkerState(Worker::Hooks h, milliseconds p) : hooks(std::move(h)), period(p) {}

  Worker::Hooks hooks;  // called by the worker thread only; released when it ends
  std::atomic<bool> stop{false};

  mutable std::mutex mutex;      // guards everything below
  std::condition_variable wake;  // the worker: a job, a moved tick, stop; Stop(): finished
  std::deque<std::function<void()>> jobs;
  milliseconds period;
  Clock::time_point next_tick{};
  bool started = false;
  bool finished = false;  // the worker thread ran its finish hook and ends
  std::thread::id thread_id;
  std::uint64_t failures = 0;
  std::string last_failure;
};

}  // namespace internal

namespace {

using internal::WorkerState;

// a deadline `delay` from now; a huge one means "never" without overflowing the clock
Clock::time_point After(milliseconds delay) {
  constexpr milliseconds kYear{365LL * 24 * 3600 * 1000};
  return Clock::now() + std::min(std::max(delay, milliseconds(0)), kYear);
}

// runs one job or hook; an exception it lets escape is counted, the worker carries on
void Call(WorkerState& s, const std::function<void()>& f) {
  if (!f) return;
  std::string failure;
  try {
    f();
    return;
  } catch (const CORBA::Exception& e) {
    failure = rtc::Describe(e);
  } catch (const std::exception& e) {
    failure = e.what();
  } catch (...) {
    failure = "an unknown exception";
  }
  std::lock_guard<std::mutex> lock(s.mutex);
  ++s.failures;
  s.last_failure = std::move(failure);
}

// Waits for a wake-up and takes the jobs queued; false when the worker is to stop.
bool WaitForWork(WorkerState& s, std::deque<std::function<void()>>* jobs) {
  std::unique_lock<std::mutex> lock(s.mutex);
  while (!s.stop && s.jobs.empty() && Clock::now() < s.next_tick) {
    s.wake.wait_until(lock, s.next_tick);
  }
  if (s.stop) return false;
  jobs->swap(s.jobs);
  return true;
}

// True when a tick is due now; schedules the next one a period on.
bool TickDue(WorkerState& s) {
  std::lock_guard<std::mutex> lock(s.mutex);
  if (s.stop || Clock::now() < s.next_tick) return false;
  s.next_tick = After(s.period);
  return true;
}

void Run(const std::shared_ptr<WorkerState>& state) {
  WorkerState& s = *state;
  const rtc::OmniThread omni;  // per-thread call timeouts need an omni_thread
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.thread_id = std::this_thread::get_id();
  }
  Call(s, s.hooks.start);
  std::deque<std::function<void()>> jobs;
  while (WaitForWork(s, &jobs)) {
    const bool any = !jobs.empty();
    for (; !jobs.empty() && !s.stop; jobs.pop_front()) Call(s, jobs.front());
    jobs.clear();  // those dropped by a stop
    if (s.stop) break;
    if (any) Call(s, s.hooks.after_jobs);
    if (TickDue(s)) Call(s, s.hooks.tick);
  }
  Call(s, s.hooks.finish);
  Worker::Hooks released;
  std::deque<std::function<void()>> dropped;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    std::swap(released, s.hooks);
    dropped.swap(s.jobs);
  }
  // what the hooks and jobs captured goes now, before Stop() hears that the worker ended
  released = Worker::Hooks();
  dropped.clear();
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.finished = true;
  }
  s.wake.notify_all();
}

}  // namespace

bool WorkerHandle::Post(std::function<void()> job) const {
  const std::shared_ptr<WorkerState> s = state_.lock();
  if (!s || s->stop) return false;
  {
    std::lock_guard<std::mutex> lock(s->mutex);
    if (s->stop) return false;
    s->jobs.push_back(std::move(job));
  }
  s->wake.notify_all();
  return true;
}

void WorkerHandle::TickIn(milliseconds delay) const {
  const std::shared_ptr<WorkerState> s = state_.lock();
  if (!s) return;
  {
    std::lock_guard<std::mutex> lock(s->mutex);
    s->next_tick = After(delay);
  }
  s->wake.notify_all();
}

void WorkerHandle::set_period(milliseconds period) const {
  const std::shared_ptr<WorkerState> s = state_.lock();
  if (!s) return;
  std::lock_guard<std::mutex> lock(s->mutex);
  s->period = period;
}

bool WorkerHandle::stopping() const {
  const std::shared_ptr<WorkerState> s = state_.lock();
  return !s || s->stop;
}

Worker::Worker(Options options, Hooks hooks)
    : state_(std::make_shared<WorkerState>(std::move(hooks), options.period)),
      stop_timeout_(options.stop_timeout) {}

Worker::~Worker() {
  Stop(stop_timeout_);
  // destroyed by its own thread: that thread ends on its own
  if (thread_.joinable()) thread_.detach();
}

void Worker::Start() {
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    if (state_->started || state_->stop) return;
    state_->started = true;
    state_->next_tick = Clock::now();  // the first tick at once
  }
  thread_ = std::thread([state = state_] { Run(state); });
}

bool Worker::Stop(milliseconds bound) {
  WorkerState& s = *state_;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.stop = true;
  }
  s.wake.notify_all();
  if (on_worker_thread()) return false;  // it cannot wait for itself
  if (!thread_.joinable()) {
    std::lock_guard<std::mutex> lock(s.mutex);
    return s.finished || !s.started;
  }
  bool ended = false;
  {
    std::unique_lock<std::mutex> lock(s.mutex);
    if (bound == kForever) {
      s.wake.wait(lock, [&] { return s.finished; });
      ended = true;
    } else {
      ended = s.wake.wait_until(lock, After(bound), [&] { return s.finished; });
    }
  }
  if (ended) {
    thread_.join();
  } else {
    thread_.detach();
  }
  return ended;
}

std::uint64_t Worker::failures() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->failures;
}

std::string Worker::last_failure() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->last_failure;
}

bool Worker::on_worker_thread() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->started && std::this_thread::get_id() == state_->thread_id;
}

}  // namespace caliper::client
