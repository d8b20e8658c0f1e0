// Lossless data subscriptions in ModelCore, without CORBA: a step request, lock-step ticks and a
// run as fast as possible wait for a slow taker and lose no sample; one whose taker stops is
// ended after its wait, with the reason, and the steps go on; a real-time run never waits and
// counts its drops; a stop or pause ends a wait at once. No wall-clock speed is asserted (the
// unit tests also run under sanitizers on a busy machine): the Model's own counters say whether
// it waited, and bounds in time only catch waits that never end.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "caliper/simulation/model_core.h"

namespace caliper::simulation {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const char* const kPosition = "pendulum_tendon.pendulum.position";  // 3 values
// a slow taker: 31 batches of 10 samples (what the queue holds before the stepping waits) take
// at most 5 ms of stepping here, and under 50 ms with sanitizers, so the stepping always waits
constexpr std::chrono::milliseconds kTakerPause{50};

std::string Model(const std::string& file) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/models/" + file;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// Takes a subscription's batches on its own thread, `pause` after each take, and checks that
/// they follow one another: numbers 1, 2, 3, ... and each batch's first step right after the
/// last sample of the one before.
class SlowTaker {
 public:
  SlowTaker(ModelCore& core, uint64_t id, std::chrono::milliseconds pause)
      : core_(core), id_(id), pause_(pause), thread_([this] { Run(); }) {}
  ~SlowTaker() { Stop(); }
  void Stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  uint64_t samples() const { return samples_; }
  /// "" when every batch followed the one before, else the first break.
  std::string breaks() {
    Stop();
    return breaks_;
  }

 private:
  void Run() {
    while (!stop_) {
      for (const daq::Batch& b : core_.TakeBatches(id_)) {
        if (breaks_.empty() && b.sequence != next_batch_)
          breaks_ =
              "batch " + std::to_string(b.sequence) + " after " + std::to_string(next_batch_ - 1);
        if (breaks_.empty() && next_step_ != 0 && b.first_step != next_step_)
          breaks_ = "batch " + std::to_string(b.sequence) + " starts at step " +
                    std::to_string(b.first_step) + ", " + std::to_string(next_step_) + " expected";
        next_batch_ = b.sequence + 1;
        next_step_ = b.first_step + b.step_count * b.every_n_steps;
        samples_ += b.step_count;
      }
      std::this_thread::sleep_for(pause_);
    }
  }

  ModelCore& core_;
  const uint64_t id_;
  const std::chrono::milliseconds pause_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> samples_{0};
  uint64_t next_batch_ = 1;
  uint64_t next_step_ = 0;
  std::string breaks_;
  std::thread thread_;
};

/// Waits (at most 10 s) until `taker` has `n` samples; false when it never had.
bool WaitForSamples(const SlowTaker& taker, uint64_t n) {
  for (int i = 0; i < 1000 && taker.samples() < n; ++i) std::this_thread::sleep_for(10ms);
  return taker.samples() == n;
}

/// `taker` gets `n` samples of subscription `id` (within 10 s), each after the one before, and
/// none dropped: the Model waited for it.
void ExpectEverySampleAfterAWait(ModelCore& core, uint64_t id, SlowTaker& taker, uint64_t n) {
  ASSERT_TRUE(WaitForSamples(taker, n)) << taker.samples() << " samples of " << n;
  EXPECT_EQ(taker.breaks(), "");
  EXPECT_EQ(core.SubscriptionStatus(id).dropped_samples, 0u);
  EXPECT_GT(core.SubscriptionStatus(id).waited_s, 0.0);
}

TEST(LosslessFeed, AStepRequestWaitsForASlowTakerAndLosesNoSample) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  // batches of 10 samples in a queue of 33 (256 MiB over 100,000 values of 10 samples)
  const uint64_t id = core.Subscribe({kPosition}, 1, 10, 2000ms);
  SlowTaker taker(core, id, kTakerPause);
  EXPECT_EQ(core.StepNow(5000), 5000u);
  ASSERT_TRUE(WaitForSamples(taker, 5000)) << taker.samples() << " samples";
  EXPECT_EQ(taker.breaks(), "");
  const FeedStatus status = core.SubscriptionStatus(id);
  EXPECT_TRUE(status.lossless);
  EXPECT_EQ(status.samples, 5000u);
  EXPECT_EQ(status.batches, 500u);
  EXPECT_EQ(status.dropped_batches, 0u);
  EXPECT_EQ(status.dropped_samples, 0u);
  EXPECT_GT(status.waited_s, 0.0);  // the taker was slower than the steps: the Model waited
}

TEST(LosslessFeed, EveryStepOfARequestReachesATakerOnceTheModelRests) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  const uint64_t id = core.Subscribe({kPosition}, 1, 10, 2000ms);
  SlowTaker taker(core, id, 0ms);
  EXPECT_EQ(core.StepNow(1234), 1234u);  // 123 whole batches and 4 samples
  ASSERT_TRUE(WaitForSamples(taker, 1234)) << taker.samples() << " samples: the last 4 stayed";
  EXPECT_EQ(core.StepNow(6), 6u);  // a step request that fills no batch
  ASSERT_TRUE(WaitForSamples(taker, 1240)) << taker.samples() << " samples";
  EXPECT_EQ(taker.breaks(), "");
  EXPECT_EQ(core.SubscriptionStatus(id).batches, 125u);
}

TEST(LosslessFeed, LockStepRequestsOfOneStepKeepWholeBatchesAndLoseNothing) {
  // a lock-step client (step(1) after step(1)) while a lossy subscriber looks every 20 ms: the
  // samples wait in whole batches, and only a Model at rest hands out its partial one
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  const uint64_t id = core.Subscribe({kPosition}, 1, 50);
  // 250 requests: 5 whole batches, within the queue's 6 (256 MiB / 8 B / 100,000 values / 50)
  for (int i = 0; i < 250; ++i) EXPECT_EQ(core.StepNow(1), 1u);
  FeedStatus status = core.SubscriptionStatus(id);
  EXPECT_EQ(status.batches, 5u) << "one batch per 50 steps, not one per request";
  EXPECT_EQ(status.dropped_samples, 0u);
  uint64_t taken = 0;
  for (const daq::Batch& b : core.TakeBatches(id)) taken += b.step_count;
  EXPECT_EQ(taken, 250u);
  EXPECT_EQ(core.StepNow(7), 7u);
  // at rest: the partial batch of 7 goes out to the taker that finds nothing else
  const auto rest = core.TakeBatches(id);
  ASSERT_EQ(rest.size(), 1u);
  EXPECT_EQ(rest[0].step_count, 7u);
  EXPECT_TRUE(core.TakeBatches(id).empty());
  status = core.SubscriptionStatus(id);
  EXPECT_EQ(status.dropped_samples, 0u);
}

TEST(LosslessFeed, WithoutLosslessTheSameRunDropsAndCountsTheSamples) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  const uint64_t id = core.Subscribe({kPosition}, 1, 10);
  EXPECT_EQ(core.StepNow(5000), 5000u);  // nobody takes: the queue keeps its newest 33
  const FeedStatus status = core.SubscriptionStatus(id);
  EXPECT_FALSE(status.lossless);
  EXPECT_EQ(status.batches, 500u);
  EXPECT_EQ(status.queued, 33u);
  EXPECT_EQ(status.dropped_batches, 500u - 33u);
  EXPECT_EQ(status.dropped_samples, 10 * (500u - 33u));
  EXPECT_EQ(status.waited_s, 0.0);
}

TEST(LosslessFeed, ATakerThatStopsIsEndedAfterItsWaitAndTheStepsGoOn) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  // the Model calls this each time the stepping begins to wait for a subscription
  std::atomic<int> waits{0};
  core.SetConsumerWake([&](uint64_t) { ++waits; });
  const uint64_t id = core.Subscribe({kPosition}, 1, 10, 300ms);
  const auto begin = Clock::now();
  EXPECT_EQ(core.StepNow(5000), 5000u);  // nobody takes
  const double took = Seconds(Clock::now() - begin);
  EXPECT_EQ(waits.load(), 1) << "one wait, then the subscription is ended and the steps go on";
  EXPECT_GE(took, 0.3) << "the wait is the subscription's 300 ms";
  // a hang detector, not a speed check: a wait that never ended (or one per step, 5000 x 0.3 s)
  // would take far longer
  EXPECT_LT(took, 30.0);
  try {
    core.SubscriptionStatus(id);
    ADD_FAILURE() << "the subscription of a stopped taker was kept";
  } catch (const UnknownId& e) {
    EXPECT_TRUE(Contains(e.what(), "was ended by the Model: its consumer took no batch for 300 ms"))
        << e.what();
  }
  bool gone = false;
  EXPECT_TRUE(core.TakeBatches(id, &gone).empty());
  EXPECT_TRUE(gone);
  // its values are free again, and a second request does not wait at all
  EXPECT_EQ(core.StepNow(5000), 5000u);
  EXPECT_EQ(waits.load(), 1) << "the second request waited for the ended subscription";
}

TEST(LosslessFeed, AsFastAsPossibleWaitsForASlowTaker) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  core.SetRealTimeFactor(0);
  const uint64_t id = core.Subscribe({kPosition}, 1, 10, 2000ms);
  SlowTaker taker(core, id, kTakerPause);
  core.Start();
  for (int i = 0; i < 100 && core.status().steps < 3000; ++i) core.Advance(20ms);
  core.Pause();
  const uint64_t steps = core.status().steps;
  EXPECT_GE(steps, 3000u);
  // the partial batch is not queued yet
  ExpectEverySampleAfterAWait(core, id, taker, steps - steps % 10);
}

TEST(LosslessFeed, LockStepTicksWaitForASlowTaker) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  const uint64_t id = core.Subscribe({kPosition}, 1, 10, 2000ms);
  SlowTaker taker(core, id, kTakerPause);
  core.Start();
  for (int i = 0; i < 3000; ++i) core.Tick();  // an external execution context
  core.Pause();
  EXPECT_EQ(core.status().steps, 3000u);
  ExpectEverySampleAfterAWait(core, id, taker, 3000);
}

TEST(LosslessFeed, ARealTimeRunNeverWaitsAndCountsWhatItDrops) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  core.SetRealTimeFactor(1);
  std::atomic<int> waits{0};
  core.SetConsumerWake([&](uint64_t) { ++waits; });
  // lossless, one sample per batch: a queue of 64 batches holds 64 ms of the run; nobody takes
  const uint64_t id = core.Subscribe({kPosition}, 1, 1, 2000ms);
  core.Start();
  // an execution context at 200 Hz until the queue has overflowed by 300 samples (about 0.4 s of
  // wall time; bounded at 2000 ticks)
  for (int i = 0; i < 2000 && core.status().steps < 400; ++i) {
    core.Advance(4ms);
    std::this_thread::sleep_for(5ms);
  }
  core.Pause();
  const Status s = core.status();
  ASSERT_GE(s.steps, 400u) << "the run did not advance";
  const FeedStatus status = core.SubscriptionStatus(id);  // not ended: it was never waited for
  EXPECT_EQ(waits.load(), 0) << "a real-time run waited for a consumer";
  EXPECT_EQ(status.waited_s, 0.0);
  // every step made one sample; the queue kept its newest 64, the rest were dropped and counted
  EXPECT_EQ(status.samples, s.steps);
  EXPECT_EQ(status.batches, s.steps);
  EXPECT_EQ(status.queued, 64u);
  EXPECT_EQ(status.dropped_batches, s.steps - 64);
  EXPECT_EQ(status.dropped_samples, s.steps - 64);
}

TEST(LosslessFeed, AStopOrPauseEndsAWaitAtOnce) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  std::atomic<int> waits{0};
  core.SetConsumerWake([&](uint64_t) { ++waits; });
  // a subscription whose wait (10 s) would end it: alive afterwards, the wait was cut short
  const uint64_t id = core.Subscribe({kPosition}, 1, 10, 10000ms);
  int rounds = 0;
  for (const std::string request : {"pause", "stop"}) {
    ++rounds;
    auto run = std::async(std::launch::async, [&] { return core.StepNow(100000); });
    // the queue fills after 330 steps, and the request waits (bounded: 20 s)
    for (int i = 0; i < 2000 && waits < rounds; ++i) std::this_thread::sleep_for(10ms);
    ASSERT_EQ(waits.load(), rounds) << request << ": the request never waited";
    ASSERT_EQ(run.wait_for(0ms), std::future_status::timeout) << request;
    if (request == "pause")
      core.Pause();
    else
      core.Stop();
    // a hang detector with margin: a wait the request does not end lasts the full 10 s
    ASSERT_EQ(run.wait_for(5s), std::future_status::ready) << request << " did not end the wait";
    EXPECT_LT(run.get(), 1000u) << request;
    // what the Model reports: it waited less than the subscription's 10 s, which is still there
    const FeedStatus status = core.SubscriptionStatus(id);
    EXPECT_GT(status.waited_s, 0.0) << request;
    EXPECT_LT(status.waited_s, 10.0 * rounds) << request;
    EXPECT_EQ(status.dropped_samples, 0u) << request;
  }
}

}  // namespace
}  // namespace caliper::simulation
