// The Model's data feeds on their own, over a registry of two fake channels: the refusals of a
// subscription and their messages, the bound on the values subscribed in all, the queue capacity
// derived from Limits, failed pushes counted as dropped, why the Model ended a subscription, and
// the lossless wait: it returns at once without lossless subscriptions, ends a consumer that
// takes nothing, lets the lock go until a take makes room, and gives up when interrupted.
#include "caliper/simulation/feeds.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace caliper::simulation {
namespace {

using namespace std::chrono_literals;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Limits that give every queue 4 batches: queued_bytes / (8 bytes * subscribed_values *
/// batch_steps of 1).
Limits SmallLimits() {
  Limits limits;
  limits.ids_per_call = 3;
  limits.subscribed_values = 10;
  limits.queued_bytes = 8 * 10 * 4;
  return limits;
}

/// `m.x` = step (1 value), `m.v` = (step, 2 step, 3 step).
struct FeedsTest : ::testing::Test {
  FeedsTest() {
    registry.Add({"m.x", "m", daq::Shape::Scalar(), false, false, "the step"},
                 [this](double* out) { out[0] = static_cast<double>(step); });
    registry.Add({"m.v", "m/s", daq::Shape::Vector(3), false, false, "multiples of the step"},
                 [this](double* out) {
                   for (int i = 0; i < 3; ++i) out[i] = static_cast<double>((i + 1) * step);
                 });
  }

  /// Steps the fake simulation `n` times, 1 ms per step.
  void Run(uint64_t n) {
    for (uint64_t k = 0; k < n; ++k) {
      ++step;
      feeds.OnStep(step, 1e-3 * static_cast<double>(step));
    }
  }

  /// The message of the UnknownId that Status throws for `id` ("" when it throws none).
  std::string StatusError(uint64_t id) {
    try {
      feeds.Status(id);
    } catch (const UnknownId& e) {
      EXPECT_EQ(e.id(), std::to_string(id));
      return e.what();
    }
    return "";
  }

  uint64_t step = 0;
  daq::Registry registry;
  Feeds feeds{registry, SmallLimits()};
  std::mutex mutex;  // stands for the Model's lock
};

TEST_F(FeedsTest, RefusesBadSubscriptionsSayingWhy) {
  try {
    feeds.Subscribe({"m.x"}, 0, 1, 0ms);
    FAIL() << "every_n_steps 0 accepted";
  } catch (const InvalidValue& e) {
    EXPECT_STREQ(e.what(), "every_n_steps must be at least 1");
  }
  EXPECT_THROW(feeds.Subscribe({}, 1, 1, 0ms), InvalidValue);
  try {
    feeds.Subscribe({"m.x", "m.gone"}, 1, 1, 0ms);
    FAIL() << "an unknown id accepted";
  } catch (const UnknownId& e) {
    EXPECT_EQ(e.id(), "m.gone");
  }
  try {
    feeds.Subscribe({"m.x", "m.x", "m.x", "m.x"}, 1, 1, 0ms);
    FAIL() << "4 ids accepted, at most 3 allowed";
  } catch (const LimitExceeded& e) {
    EXPECT_EQ(e.limit(), 3u);
    EXPECT_TRUE(Contains(e.what(), "4 ids in one subscription; at most 3")) << e.what();
  }
  EXPECT_EQ(feeds.subscribed_values(), 0u);  // nothing refused counts
}

TEST_F(FeedsTest, BoundsTheValuesOfAllSubscriptionsAndFreesThem) {
  const uint64_t a = feeds.Subscribe({"m.v", "m.x"}, 1, 1, 0ms);  // 4 values
  const uint64_t b = feeds.Subscribe({"m.v", "m.v"}, 1, 1, 0ms);  // 6: 10 in all, the limit
  EXPECT_NE(a, b);
  EXPECT_EQ(feeds.subscribed_values(), 10u);
  try {
    feeds.Subscribe({"m.x"}, 1, 1, 0ms);
    FAIL() << "an 11th value accepted";
  } catch (const LimitExceeded& e) {
    EXPECT_EQ(e.limit(), 10u);
    EXPECT_TRUE(Contains(e.what(), "subscribing 1 values to the 10 subscribed already"))
        << e.what();
  }
  feeds.Unsubscribe(a, "");
  EXPECT_EQ(feeds.subscribed_values(), 6u);
  feeds.Unsubscribe(a, "");  // again: nothing
  EXPECT_EQ(feeds.subscribed_values(), 6u);
  EXPECT_NO_THROW(feeds.Subscribe({"m.v", "m.x"}, 1, 1, 0ms));
}

TEST_F(FeedsTest, QueueHoldsWhatTheLimitsAllowAndCountsItsDrops) {
  const uint64_t id = feeds.Subscribe({"m.x"}, 1, 1, 0ms);
  Run(10);
  const FeedStatus s = feeds.Status(id);
  EXPECT_FALSE(s.lossless);
  EXPECT_EQ(s.samples, 10u);
  EXPECT_EQ(s.batches, 10u);
  EXPECT_EQ(s.queued, 4u);  // queued_bytes / (8 * subscribed_values * 1 step)
  EXPECT_EQ(s.dropped_batches, 6u);
  EXPECT_EQ(s.dropped_samples, 6u);
  bool gone = true;
  uint64_t dropped = 0;
  const std::vector<daq::Batch> batches = feeds.TakeBatches(id, &gone, &dropped);
  EXPECT_FALSE(gone);
  EXPECT_EQ(dropped, 6u);
  ASSERT_EQ(batches.size(), 4u);
  EXPECT_EQ(batches.front().sequence, 7u);  // the oldest went first
  EXPECT_EQ(feeds.Status(id).queued, 0u);
}

TEST_F(FeedsTest, UndeliveredBatchesCountAsDropped) {
  const uint64_t id = feeds.Subscribe({"m.x"}, 1, 1, 0ms);
  Run(2);
  EXPECT_EQ(feeds.TakeBatches(id).size(), 2u);
  feeds.NoteUndelivered(id, 2, 2);
  feeds.NoteUndelivered(id + 100, 5, 5);  // unknown: nothing
  const FeedStatus s = feeds.Status(id);
  EXPECT_EQ(s.dropped_batches, 2u);
  EXPECT_EQ(s.dropped_samples, 2u);
}

TEST_F(FeedsTest, StatusSaysWhyTheModelEndedASubscription) {
  const uint64_t by_model = feeds.Subscribe({"m.x"}, 1, 1, 0ms);
  const uint64_t by_client = feeds.Subscribe({"m.x"}, 1, 1, 0ms);
  feeds.Unsubscribe(by_model, "the scene went away");
  feeds.Unsubscribe(by_client, "");
  EXPECT_EQ(StatusError(by_model), "subscription " + std::to_string(by_model) +
                                       " was ended by the Model: the scene went away");
  EXPECT_EQ(StatusError(by_client), "no subscription " + std::to_string(by_client));
  bool gone = false;
  EXPECT_TRUE(feeds.TakeBatches(by_model, &gone).empty());
  EXPECT_TRUE(gone);
  EXPECT_FALSE(feeds.WaitForBatches(by_model, 1ms));
}

TEST_F(FeedsTest, AwaitRoomReturnsAtOnceWithoutLosslessSubscriptions) {
  const uint64_t id = feeds.Subscribe({"m.x"}, 1, 1, 0ms);
  Run(10);  // a full queue, but lossy
  std::unique_lock<std::mutex> lock(mutex);
  EXPECT_EQ(feeds.lossless(), 0u);
  EXPECT_FALSE(feeds.AwaitRoom(lock, [] { return false; }));
  EXPECT_TRUE(lock.owns_lock());
  EXPECT_EQ(feeds.Status(id).waited_s, 0.0);
}

TEST_F(FeedsTest, AwaitRoomEndsAConsumerThatTakesNothing) {
  const uint64_t id = feeds.Subscribe({"m.x"}, 1, 1, 20ms);
  EXPECT_EQ(feeds.lossless(), 1u);
  EXPECT_TRUE(feeds.Status(id).lossless);
  Run(3);  // 3 queued + 2 for the next step > 4: no room
  std::vector<uint64_t> woken;
  feeds.SetConsumerWake([&](uint64_t s) { woken.push_back(s); });
  std::unique_lock<std::mutex> lock(mutex);
  EXPECT_TRUE(feeds.AwaitRoom(lock, [] { return false; }));
  EXPECT_TRUE(lock.owns_lock());
  EXPECT_EQ(woken, std::vector<uint64_t>{id});
  EXPECT_EQ(feeds.lossless(), 0u);
  EXPECT_EQ(feeds.subscribed_values(), 0u);
  EXPECT_TRUE(Contains(StatusError(id), "its consumer took no batch for 20 ms while the "
                                        "simulation waited for it (lossless)"))
      << StatusError(id);
}

TEST_F(FeedsTest, AwaitRoomLetsTheLockGoUntilATakeMakesRoom) {
  const uint64_t id = feeds.Subscribe({"m.x"}, 1, 1, 10s);
  Run(3);
  std::atomic<bool> took{false};
  std::thread taker;
  feeds.SetConsumerWake([&](uint64_t s) {
    taker = std::thread([&, s] {
      std::this_thread::sleep_for(20ms);
      // the Model's lock is free while the stepping waits
      { const std::lock_guard<std::mutex> held(mutex); }
      took = !feeds.TakeBatches(s).empty();  // wakes the wait
    });
  });
  std::unique_lock<std::mutex> lock(mutex);
  const auto begin = std::chrono::steady_clock::now();
  EXPECT_TRUE(feeds.AwaitRoom(lock, [] { return false; }));
  EXPECT_LT(std::chrono::steady_clock::now() - begin, 5s);  // woken, not timed out
  taker.join();
  EXPECT_TRUE(took);
  const FeedStatus s = feeds.Status(id);  // still subscribed
  EXPECT_EQ(s.queued, 0u);
  EXPECT_GT(s.waited_s, 0.0);
}

TEST_F(FeedsTest, AwaitRoomGivesUpWhenInterrupted) {
  const uint64_t id = feeds.Subscribe({"m.x"}, 1, 1, 10s);
  Run(3);
  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(20ms);
    stop = true;
    feeds.NotifyRoom();  // as a pause does
  });
  std::unique_lock<std::mutex> lock(mutex);
  const auto begin = std::chrono::steady_clock::now();
  int asked = 0;
  EXPECT_TRUE(feeds.AwaitRoom(lock, [&] {
    ++asked;
    return stop.load();
  }));
  EXPECT_LT(std::chrono::steady_clock::now() - begin, 5s);
  stopper.join();
  EXPECT_GE(asked, 1);
  EXPECT_EQ(feeds.Status(id).queued, 3u);  // still there, nothing taken
}

}  // namespace
}  // namespace caliper::simulation
