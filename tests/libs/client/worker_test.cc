#include "caliper/client/worker.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace caliper::client {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// waits until `done` holds, at most `limit`; true when it did
bool WaitFor(const std::function<bool()>& done, milliseconds limit = milliseconds(5000)) {
  const auto end = Clock::now() + limit;
  while (!done()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(milliseconds(2));
  }
  return true;
}

double MsBetween(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

double MsSince(Clock::time_point t) { return MsBetween(t, Clock::now()); }

// what the worker thread records, read by the test thread
struct Log {
  std::mutex mutex;
  std::vector<int> jobs;
  std::vector<Clock::time_point> ticks;
  size_t job_count() {
    std::lock_guard<std::mutex> lock(mutex);
    return jobs.size();
  }
  size_t tick_count() {
    std::lock_guard<std::mutex> lock(mutex);
    return ticks.size();
  }
};

Worker::Hooks TickInto(const std::shared_ptr<Log>& log) {
  Worker::Hooks hooks;
  hooks.tick = [log] {
    std::lock_guard<std::mutex> lock(log->mutex);
    log->ticks.push_back(Clock::now());
  };
  return hooks;
}

TEST(WorkerTest, RunsJobsInTheOrderPosted) {
  auto log = std::make_shared<Log>();
  Worker worker({milliseconds(10000)}, {});
  auto post = [&](int n) {
    EXPECT_TRUE(worker.Post([log, n] {
      std::lock_guard<std::mutex> lock(log->mutex);
      log->jobs.push_back(n);
    }));
  };
  for (int n = 0; n < 50; ++n) post(n);  // queued before the thread runs
  worker.Start();
  // from two threads at once: each thread's jobs keep their order
  std::thread other([&] {
    for (int n = 1000; n < 1200; ++n) post(n);
  });
  for (int n = 50; n < 250; ++n) post(n);
  other.join();
  ASSERT_TRUE(WaitFor([&] { return log->job_count() == 450; })) << log->job_count();
  std::lock_guard<std::mutex> lock(log->mutex);
  std::vector<int> mine, theirs;
  for (int n : log->jobs) (n >= 1000 ? theirs : mine).push_back(n);
  for (size_t k = 0; k < mine.size(); ++k) ASSERT_EQ(mine[k], static_cast<int>(k));
  for (size_t k = 0; k < theirs.size(); ++k) ASSERT_EQ(theirs[k], 1000 + static_cast<int>(k));
}

TEST(WorkerTest, RunsJobsAndHooksOnItsOwnThread) {
  std::atomic<int> on_worker{0};
  std::atomic<bool> started{false}, finished{false};
  Worker* self = nullptr;
  Worker::Hooks hooks;
  hooks.start = [&] { started = true; };
  hooks.finish = [&] { finished = true; };
  Worker worker({milliseconds(10000)}, std::move(hooks));
  self = &worker;
  worker.Start();
  worker.Post([&] { on_worker += self->on_worker_thread() ? 1 : 100; });
  ASSERT_TRUE(WaitFor([&] { return on_worker != 0; }));
  EXPECT_EQ(on_worker, 1);
  EXPECT_TRUE(started);
  EXPECT_FALSE(worker.on_worker_thread());
  EXPECT_FALSE(finished);
  EXPECT_TRUE(worker.Stop());
  EXPECT_TRUE(finished);
}

TEST(WorkerTest, TicksAtOnceAndThenAtItsPeriod) {
  auto log = std::make_shared<Log>();
  Worker worker({milliseconds(100)}, TickInto(log));
  const auto t0 = Clock::now();
  worker.Start();
  ASSERT_TRUE(WaitFor([&] { return log->tick_count() >= 6; }));
  worker.Stop();
  std::lock_guard<std::mutex> lock(log->mutex);
  EXPECT_LT(MsBetween(t0, log->ticks[0]), 80);
  for (size_t k = 1; k < 6; ++k) {
    // a period from the start of the previous tick (its own time stamp comes a little later)
    const double gap = MsBetween(log->ticks[k - 1], log->ticks[k]);
    EXPECT_GE(gap, 95) << "tick " << k;
    EXPECT_LT(gap, 300) << "tick " << k;
  }
}

TEST(WorkerTest, JobsDoNotMoveTheTicks) {
  auto log = std::make_shared<Log>();
  Worker worker({milliseconds(300)}, TickInto(log));
  worker.Start();
  ASSERT_TRUE(WaitFor([&] { return log->tick_count() == 1; }));
  std::atomic<int> ran{0};
  for (int n = 0; n < 5; ++n) {
    worker.Post([&] { ++ran; });
    std::this_thread::sleep_for(milliseconds(20));
  }
  EXPECT_EQ(ran, 5);
  EXPECT_EQ(log->tick_count(), 1u);  // 100 ms into a 300 ms period
}

TEST(WorkerTest, TickInMovesTheNextTickAndSetPeriodTheOnesAfter) {
  auto log = std::make_shared<Log>();
  Worker worker({milliseconds(60000)}, TickInto(log));
  worker.Start();
  ASSERT_TRUE(WaitFor([&] { return log->tick_count() == 1; }));
  worker.set_period(milliseconds(50));  // the tick scheduled stays a minute away
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_EQ(log->tick_count(), 1u);
  const auto asked = Clock::now();
  worker.TickIn(milliseconds(0));
  ASSERT_TRUE(WaitFor([&] { return log->tick_count() == 2; }));
  EXPECT_LT(MsSince(asked), 100);
  // then the new period
  ASSERT_TRUE(WaitFor([&] { return log->tick_count() == 4; }, milliseconds(1000)));
  worker.set_period(milliseconds(60000));
  worker.TickIn(milliseconds(60000));
  const size_t ticks = log->tick_count();
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_EQ(log->tick_count(), ticks);
}

// a job inside a call that does not return: Stop() gives up after its bound, the worker ends
// on its own when the call returns, and what it captured lives until then
TEST(WorkerTest, StopReturnsWithinItsBoundWhileAJobIsStuck) {
  struct Stuck {
    std::atomic<bool> inside{false};
    std::atomic<bool> release{false};
    std::atomic<bool> later_job{false};
    std::atomic<bool> finished{false};
  };
  auto stuck = std::make_shared<Stuck>();
  auto worker =
      std::make_unique<Worker>(Worker::Options{milliseconds(10000), milliseconds(200)},
                               Worker::Hooks{{}, {}, {}, [stuck] { stuck->finished = true; }});
  worker->Start();
  worker->Post([stuck] {
    stuck->inside = true;
    while (!stuck->release) std::this_thread::sleep_for(milliseconds(5));
  });
  worker->Post([stuck] { stuck->later_job = true; });
  ASSERT_TRUE(WaitFor([&] { return stuck->inside.load(); }));
  const auto t0 = Clock::now();
  EXPECT_FALSE(worker->Stop(milliseconds(200)));
  const double waited = MsSince(t0);
  EXPECT_GE(waited, 190);
  EXPECT_LT(waited, 1000);
  EXPECT_TRUE(worker->stopping());
  const WorkerHandle handle = worker->handle();
  worker.reset();  // returns at once: the thread was left to end on its own
  EXPECT_LT(MsSince(t0), 1000);
  EXPECT_FALSE(stuck->finished);
  EXPECT_GE(stuck.use_count(), 2);  // the worker still holds what its hooks captured
  stuck->release = true;
  ASSERT_TRUE(WaitFor([&] { return stuck->finished.load(); }));
  // the job posted after the stuck one was dropped, and the hooks released their captures
  EXPECT_FALSE(stuck->later_job);
  ASSERT_TRUE(WaitFor([&] { return stuck.use_count() == 1; }));
  EXPECT_FALSE(handle.Post([] {}));
  EXPECT_TRUE(handle.stopping());
}

TEST(WorkerTest, StopWaitsForAJobThatEndsWithinTheBound) {
  std::atomic<bool> done{false}, finished{false};
  Worker worker({milliseconds(10000)}, Worker::Hooks{{}, {}, {}, [&] { finished = done.load(); }});
  worker.Start();
  std::atomic<bool> inside{false};
  worker.Post([&] {
    inside = true;
    std::this_thread::sleep_for(milliseconds(100));
    done = true;
  });
  ASSERT_TRUE(WaitFor([&] { return inside.load(); }));
  EXPECT_TRUE(worker.Stop(milliseconds(3000)));
  EXPECT_TRUE(done);
  EXPECT_TRUE(finished);                      // finish came after the job
  EXPECT_TRUE(worker.Stop(milliseconds(0)));  // again: already ended
}

TEST(WorkerTest, PostingAfterStopIsHarmless) {
  auto log = std::make_shared<Log>();
  Worker worker({milliseconds(10000)}, {});
  worker.Start();
  ASSERT_TRUE(worker.Stop());
  auto captured = std::make_shared<int>(7);
  EXPECT_FALSE(worker.Post([log, captured] { log->jobs.push_back(*captured); }));
  EXPECT_EQ(captured.use_count(), 1);  // the job was dropped at once, not kept
  worker.TickIn(milliseconds(0));
  worker.set_period(milliseconds(1));
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_EQ(log->job_count(), 0u);
  EXPECT_TRUE(worker.stopping());
  EXPECT_TRUE(worker.Stop(milliseconds(0)));
}

TEST(WorkerTest, AnEscapedExceptionIsCountedAndTheWorkerCarriesOn) {
  std::atomic<bool> after{false};
  Worker worker({milliseconds(10000)}, {});
  worker.Start();
  worker.Post([] { throw std::runtime_error("boom"); });
  worker.Post([&] { after = true; });
  ASSERT_TRUE(WaitFor([&] { return after.load(); }));
  EXPECT_EQ(worker.failures(), 1u);
  EXPECT_EQ(worker.last_failure(), "boom");
}

TEST(WorkerTest, AfterJobsRunsOnceAfterEachBatch) {
  struct Counts {
    std::atomic<int> jobs{0};
    std::atomic<int> after{0};
    std::atomic<int> jobs_seen_by_after{-1};
  };
  auto c = std::make_shared<Counts>();
  Worker::Hooks hooks;
  hooks.after_jobs = [c] {
    ++c->after;
    c->jobs_seen_by_after = c->jobs.load();
  };
  Worker worker({milliseconds(10000)}, std::move(hooks));
  for (int n = 0; n < 3; ++n) worker.Post([c] { ++c->jobs; });
  worker.Start();
  ASSERT_TRUE(WaitFor([&] { return c->after.load() == 1; }));
  EXPECT_EQ(c->jobs_seen_by_after, 3);  // after all three
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_EQ(c->after, 1);  // not after the tick alone
}

}  // namespace
}  // namespace caliper::client
