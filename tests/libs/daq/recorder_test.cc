// The DAQ recorder: batches with contiguous sequence numbers, every-n sampling, the bounded queue
// that drops its oldest batch, stale ids after a registry change, and a sender thread.
#include "caliper/daq/recorder.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <thread>

namespace caliper::daq {
namespace {

/// A registry whose channels follow a fake step counter: `x` = step, `v` = (step, 2 step, 3 step).
struct Fixture : ::testing::Test {
  Fixture() { Populate(); }

  void Populate() {
    ChannelInfo x{"m.x", "m", Shape::Scalar(), false, false, "the step"};
    registry.Add(x, [this](double* out) { out[0] = static_cast<double>(step); });
    ChannelInfo v{"m.v", "m/s", Shape::Vector(3), false, false, "multiples of the step"};
    registry.Add(v, [this](double* out) {
      for (int i = 0; i < 3; ++i) out[i] = static_cast<double>((i + 1) * step);
    });
  }

  /// Steps the fake simulation from `step` + 1 to `last`, 1 ms per step.
  void RunTo(uint64_t last) {
    while (step < last) {
      ++step;
      recorder.OnStep(step, 1e-3 * static_cast<double>(step));
    }
  }

  SubscriptionOptions Options(std::vector<std::string> ids, uint64_t every_n, size_t batch,
                              size_t capacity = 1000) {
    SubscriptionOptions o;
    o.ids = std::move(ids);
    o.every_n_steps = every_n;
    o.batch_steps = batch;
    o.queue_capacity = capacity;
    return o;
  }

  Registry registry;
  Recorder recorder{registry};
  uint64_t step = 0;
};

TEST_F(Fixture, NumbersBatchesContiguouslyFromOne) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x"}, 1, 10));
  EXPECT_EQ(id, 1u);
  RunTo(95);
  auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 9u);
  for (size_t i = 0; i < batches.size(); ++i) {
    EXPECT_EQ(batches[i].subscription, id);
    EXPECT_EQ(batches[i].sequence, i + 1);
    EXPECT_EQ(batches[i].first_step, 10 * i + 1);
    EXPECT_EQ(batches[i].step_count, 10u);
    EXPECT_EQ(batches[i].times.size(), 10u);
    EXPECT_DOUBLE_EQ(batches[i].times[0], 1e-3 * static_cast<double>(10 * i + 1));
  }
  EXPECT_TRUE(recorder.TakeBatches(id).empty());
  recorder.Flush();
  batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  EXPECT_EQ(batches[0].sequence, 10u);
  EXPECT_EQ(batches[0].first_step, 91u);
  EXPECT_EQ(batches[0].step_count, 5u);
  EXPECT_EQ(batches[0].Values("m.x"), (std::vector<double>{91, 92, 93, 94, 95}));
  recorder.Flush();  // nothing pending: no empty batch
  EXPECT_TRUE(recorder.TakeBatches(id).empty());
  EXPECT_EQ(recorder.Stats(id).batches, 10u);
  EXPECT_EQ(recorder.Stats(id).samples, 95u);
}

TEST_F(Fixture, SamplesEveryNthStep) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x"}, 3, 4));
  RunTo(30);  // samples at 1, 4, ..., 28: ten of them
  recorder.Flush(id);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 3u);
  std::vector<double> all;
  for (const auto& b : batches) {
    EXPECT_EQ(b.every_n_steps, 3u);
    for (size_t k = 0; k < b.step_count; ++k) {
      const double x = b.Values(0)[k];
      EXPECT_EQ(x, static_cast<double>(b.first_step + 3 * k)) << "steps follow first_step";
      EXPECT_DOUBLE_EQ(b.times[k], 1e-3 * x);
      all.push_back(x);
    }
  }
  EXPECT_EQ(all, (std::vector<double>{1, 4, 7, 10, 13, 16, 19, 22, 25, 28}));
  EXPECT_EQ(batches[2].step_count, 2u);
}

TEST_F(Fixture, LaysOutShapedValuesSampleAfterSample) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.v", "m.x"}, 1, 2));
  RunTo(2);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  const Batch& b = batches[0];
  ASSERT_EQ(b.columns->size(), 2u);
  EXPECT_EQ((*b.columns)[0].id, "m.v");
  EXPECT_EQ((*b.columns)[0].unit, "m/s");
  EXPECT_EQ((*b.columns)[0].shape, Shape::Vector(3));
  EXPECT_EQ((*b.columns)[1].offset, 3u);
  EXPECT_EQ(b.values_per_sample, 4u);
  EXPECT_EQ(b.data, (std::vector<double>{1, 2, 3, 1, 2, 4, 6, 2}));
  EXPECT_EQ(b.Values("m.v"), (std::vector<double>{1, 2, 3, 2, 4, 6}));
  EXPECT_EQ(b.Values(1), (std::vector<double>{1, 2}));
  EXPECT_THROW(b.Values("m.y"), UnknownId);
}

TEST_F(Fixture, AFullQueueDropsItsOldestBatchAndCountsIt) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x"}, 1, 2, 3));
  RunTo(20);  // ten batches into a queue of three
  const auto stats = recorder.Stats(id);
  EXPECT_EQ(stats.batches, 10u);
  EXPECT_EQ(stats.dropped, 7u);
  EXPECT_EQ(stats.queued, 3u);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 3u);
  EXPECT_EQ(batches[0].sequence, 8u) << "the newest survive";
  EXPECT_EQ(batches[1].sequence, 9u);
  EXPECT_EQ(batches[2].sequence, 10u);
  EXPECT_EQ(batches[2].Values(0), (std::vector<double>{19, 20}));
  EXPECT_EQ(recorder.Stats(id).queued, 0u);
  EXPECT_EQ(recorder.Stats(id).dropped, 7u);
}

TEST_F(Fixture, ReusesTheMemoryOfDeliveredAndDroppedBatches) {
  // a fresh batch of megabytes costs a page fault per 4 KiB as it fills: the next batch is
  // filled in the memory of one already handed out or dropped, emptied first
  std::vector<const double*> buffers;
  std::vector<std::vector<double>> values;
  auto options = Options({"m.x", "m.v"}, 1, 4);
  options.consumer = [&](const Batch& b) {
    buffers.push_back(b.data.data());
    values.push_back(b.Values("m.x"));
  };
  const SubscriptionId delivered = recorder.Subscribe(std::move(options));
  const SubscriptionId dropping = recorder.Subscribe(Options({"m.x"}, 1, 2, 1));
  RunTo(4);
  EXPECT_EQ(recorder.Deliver(delivered), 1u);
  // memory of the first batch's size taken meanwhile: had the batch been freed, this would get it
  const std::vector<double> meanwhile(16, 0.0);
  RunTo(8);
  EXPECT_EQ(recorder.Deliver(delivered), 1u);
  ASSERT_EQ(buffers.size(), 2u);
  EXPECT_EQ(buffers[1], buffers[0]) << "the second batch reused the first one's memory";
  EXPECT_NE(meanwhile.data(), buffers[0]);
  EXPECT_EQ(values[1], (std::vector<double>{5, 6, 7, 8}));

  RunTo(12);  // the dropping subscription's queue of one keeps only its last batch
  const auto kept = recorder.TakeBatches(dropping);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].Values(0), (std::vector<double>{11, 12}));
  EXPECT_EQ(kept[0].data.size(), 2u);
  EXPECT_EQ(recorder.Stats(dropping).dropped, 5u);
}

TEST_F(Fixture, ReportsIdsThatDisappearAsStaleAndPicksThemUpAgain) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x", "m.v"}, 1, 10));
  RunTo(3);
  registry.Clear();  // a scene reload
  RunTo(5);
  EXPECT_EQ(recorder.Stats(id).stale, (std::vector<std::string>{"m.x", "m.v"}));
  recorder.Flush();
  auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 2u) << "the layout changed: the partial batch went out first";
  EXPECT_EQ(batches[0].step_count, 3u);
  EXPECT_TRUE(batches[0].StaleIds().empty());
  EXPECT_EQ(batches[1].sequence, 2u);
  EXPECT_EQ(batches[1].first_step, 4u);
  EXPECT_EQ(batches[1].StaleIds(), (std::vector<std::string>{"m.x", "m.v"}));
  EXPECT_EQ(batches[1].values_per_sample, 4u) << "stale columns keep their shape";
  for (double v : batches[1].data) EXPECT_TRUE(std::isnan(v));

  Populate();  // the reloaded scene has the ids again
  RunTo(7);
  recorder.Flush();
  batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  EXPECT_EQ(batches[0].sequence, 3u);
  EXPECT_TRUE(batches[0].StaleIds().empty());
  EXPECT_EQ(batches[0].Values("m.x"), (std::vector<double>{6, 7}));
  EXPECT_TRUE(recorder.Stats(id).stale.empty());
}

TEST_F(Fixture, ALayoutNumberTellsWhenAReloadMovedTheValues) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.v", "m.x"}, 1, 10));
  RunTo(2);
  registry.Clear();  // reloaded with the same channels: the values stay where they were
  Populate();
  RunTo(4);
  registry.Clear();  // reloaded with m.v two long: m.x moves from offset 3 to 2
  registry.Add({"m.v", "m/s", Shape::Vector(2), false, false, "shorter"},
               [this](double* out) { out[0] = out[1] = -static_cast<double>(step); });
  registry.Add({"m.x", "m", Shape::Scalar(), false, false, "the step"},
               [this](double* out) { out[0] = static_cast<double>(step); });
  RunTo(6);
  recorder.Flush();
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 2u) << "one batch per layout";
  EXPECT_EQ(batches[0].layout, 1u);
  EXPECT_EQ(batches[0].step_count, 4u) << "an unchanged reload keeps the layout and the batch";
  EXPECT_EQ(batches[0].values_per_sample, 4u);
  EXPECT_EQ(batches[1].layout, 2u);
  EXPECT_EQ(batches[1].values_per_sample, 3u);
  EXPECT_EQ(batches[1].Values("m.x"), (std::vector<double>{5, 6}));
}

TEST_F(Fixture, ARemovedIdOnlyAffectsItsColumn) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x", "m.v"}, 1, 2));
  registry.Remove("m.v");
  RunTo(2);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  EXPECT_EQ(batches[0].Values("m.x"), (std::vector<double>{1, 2}));
  for (double v : batches[0].Values("m.v")) EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(recorder.Stats(id).stale, std::vector<std::string>{"m.v"});
}

TEST_F(Fixture, AFailingGetterGivesNaNAndIsReported) {
  registry.Add({"m.bad", "", Shape::Scalar(), false, false, "throws"},
               [](double*) { throw std::runtime_error("engine said no"); });
  const SubscriptionId id = recorder.Subscribe(Options({"m.bad", "m.x"}, 1, 1));
  RunTo(1);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  EXPECT_TRUE(std::isnan(batches[0].data[0]));
  EXPECT_EQ(batches[0].data[1], 1.0);
  EXPECT_EQ(recorder.Stats(id).last_error, "m.bad: engine said no");
}

/// Values read in place: Update() sets value k to 100 * step + k and counts the updates.
struct StepBlock : SourceBlock {
  explicit StepBlock(const uint64_t& step_) : step(step_) {}
  void Update() override {
    ++updates;
    if (counter) ++*counter;
    if (fail) throw std::runtime_error("no states");
    for (size_t k = 0; k < 6; ++k) values[k] = 100.0 * static_cast<double>(step) + k;
  }
  const uint64_t& step;
  double values[6] = {};
  int updates = 0;
  int* counter = nullptr;  // counts the updates too, beyond the block's life
  bool fail = false;
};

TEST_F(Fixture, CopiesChannelsReadInPlaceBesideGetterChannels) {
  auto block = std::make_shared<StepBlock>(step);
  registry.Add({"b.p", "m", Shape::Vector(3), false, false, "values 0-2"},
               Source{block, block->values});
  registry.Add({"b.q", "", Shape::Vector(2), false, false, "values 3-4"},
               Source{block, block->values + 3});
  registry.Add({"b.r", "", Shape::Scalar(), false, false, "value 5"},
               Source{block, block->values + 5});
  // q and r lie next to each other in the block, p before them and m.x between
  const SubscriptionId id = recorder.Subscribe(Options({"b.q", "b.r", "m.x", "b.p"}, 1, 2));
  RunTo(2);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  EXPECT_EQ(batches[0].values_per_sample, 7u);
  EXPECT_EQ(batches[0].data, (std::vector<double>{103, 104, 105, 1, 100, 101, 102,  //
                                                  203, 204, 205, 2, 200, 201, 202}));
  EXPECT_EQ(block->updates, 2) << "one update per sample, whatever the number of channels";
}

TEST_F(Fixture, ABlockThatFailsToUpdateGivesNaNForItsColumnsOnly) {
  auto block = std::make_shared<StepBlock>(step);
  registry.Add({"b.p", "m", Shape::Vector(3), false, false, "values 0-2"},
               Source{block, block->values});
  const SubscriptionId id = recorder.Subscribe(Options({"m.x", "b.p"}, 1, 1));
  block->fail = true;
  RunTo(1);
  block->fail = false;
  RunTo(2);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 2u);
  EXPECT_EQ(batches[0].data[0], 1.0);
  for (double v : batches[0].Values("b.p")) EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(batches[1].data, (std::vector<double>{2, 200, 201, 202}));
  EXPECT_EQ(recorder.Stats(id).last_error, "b.p: no states");
}

TEST_F(Fixture, AChannelReadInPlaceIsNeverReadAfterItIsRemoved) {
  auto block = std::make_shared<StepBlock>(step);
  int updates = 0;
  block->counter = &updates;
  const std::weak_ptr<StepBlock> watch = block;
  registry.Add({"b.p", "m", Shape::Vector(3), false, false, "values 0-2"},
               Source{block, block->values});
  const SubscriptionId id = recorder.Subscribe(Options({"b.p", "m.x"}, 1, 1));
  RunTo(1);
  // the owner goes (as a scene does on a reload): removed from the registry, then freed
  registry.Remove("b.p");
  block.reset();
  EXPECT_TRUE(watch.expired()) << "the recorder keeps no reference to a removed block";
  RunTo(3);
  EXPECT_EQ(updates, 1) << "updated for step 1 only";
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 3u);
  for (double v : batches[2].Values("b.p")) EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(batches[2].Values("m.x"), std::vector<double>{3});
  EXPECT_EQ(recorder.Stats(id).stale, std::vector<std::string>{"b.p"});
}

TEST_F(Fixture, AResetStartsANewBatch) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x"}, 1, 10));
  RunTo(4);
  step = 0;  // the simulation was reset
  RunTo(2);
  recorder.Flush();
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 2u);
  EXPECT_EQ(batches[0].first_step, 1u);
  EXPECT_EQ(batches[0].step_count, 4u);
  EXPECT_EQ(batches[1].first_step, 1u);
  EXPECT_EQ(batches[1].step_count, 2u);
  EXPECT_EQ(batches[1].sequence, 2u);
}

TEST_F(Fixture, RejectsBadSubscriptions) {
  try {
    recorder.Subscribe(Options({"m.x", "m.nope"}, 1, 10));
    FAIL();
  } catch (const UnknownId& e) {
    EXPECT_EQ(e.id(), "m.nope");
    EXPECT_STREQ(e.what(), "unknown id 'm.nope'");
  }
  EXPECT_THROW(recorder.Subscribe(Options({}, 1, 10)), std::invalid_argument);
  EXPECT_THROW(recorder.Subscribe(Options({"m.x"}, 0, 10)), std::invalid_argument);
  EXPECT_THROW(recorder.Subscribe(Options({"m.x"}, 1, 0)), std::invalid_argument);
  EXPECT_THROW(recorder.Subscribe(Options({"m.x"}, 1, 1, 0)), std::invalid_argument);
  EXPECT_TRUE(recorder.subscriptions().empty());
}

TEST_F(Fixture, UnsubscribeHandsBackWhatIsLeft) {
  const SubscriptionId a = recorder.Subscribe(Options({"m.x"}, 1, 4));
  const SubscriptionId b = recorder.Subscribe(Options({"m.v"}, 2, 4));
  EXPECT_EQ(recorder.subscriptions(), (std::vector<SubscriptionId>{a, b}));
  RunTo(6);
  const auto rest = recorder.Unsubscribe(a);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_EQ(rest[0].sequence, 1u);
  EXPECT_EQ(rest[1].sequence, 2u);
  EXPECT_EQ(rest[1].step_count, 2u);
  EXPECT_EQ(recorder.subscriptions(), std::vector<SubscriptionId>{b});
  try {
    recorder.TakeBatches(a);
    FAIL();
  } catch (const UnknownId& e) {
    EXPECT_STREQ(e.what(), "unknown subscription '1'");
  }
  EXPECT_THROW(recorder.Unsubscribe(a), UnknownId);
  RunTo(8);
  EXPECT_EQ(recorder.Stats(b).samples, 4u);
}

TEST_F(Fixture, DeliversToTheConsumerOnTheCallingThread) {
  std::vector<uint64_t> sequences;
  std::thread::id where;
  auto options = Options({"m.x"}, 1, 5);
  options.consumer = [&](const Batch& b) {
    sequences.push_back(b.sequence);
    where = std::this_thread::get_id();
  };
  const SubscriptionId id = recorder.Subscribe(std::move(options));
  const SubscriptionId silent = recorder.Subscribe(Options({"m.x"}, 1, 5));
  RunTo(20);
  EXPECT_EQ(recorder.Deliver(id, 1), 1u);
  EXPECT_EQ(recorder.DeliverAll(), 3u) << "only subscriptions with a consumer";
  EXPECT_EQ(sequences, (std::vector<uint64_t>{1, 2, 3, 4}));
  EXPECT_EQ(where, std::this_thread::get_id());
  EXPECT_THROW(recorder.Deliver(silent), std::logic_error);
  EXPECT_EQ(recorder.TakeBatches(silent).size(), 4u);
}

TEST_F(Fixture, ASenderThreadReceivesEveryBatchInOrder) {
  auto options = Options({"m.x", "m.v"}, 1, 7, 100000);
  std::vector<Batch> received;
  options.consumer = [&](const Batch& b) { received.push_back(b); };
  const SubscriptionId id = recorder.Subscribe(std::move(options));
  std::atomic<bool> done{false};
  std::thread sender([&] {
    while (!done) {
      if (recorder.WaitForBatches(id, std::chrono::milliseconds(50))) recorder.Deliver(id);
    }
    recorder.Deliver(id);
  });
  RunTo(7000);
  recorder.Flush();
  done = true;
  sender.join();
  ASSERT_EQ(received.size(), 1000u);
  uint64_t next_step = 1;
  for (size_t i = 0; i < received.size(); ++i) {
    EXPECT_EQ(received[i].sequence, i + 1);
    EXPECT_EQ(received[i].first_step, next_step);
    next_step += received[i].step_count;
  }
  EXPECT_EQ(received.back().Values("m.x").back(), 7000.0);
  EXPECT_EQ(recorder.Stats(id).dropped, 0u);
}

TEST_F(Fixture, UnsubscribingWakesAWaitingSender) {
  const SubscriptionId id = recorder.Subscribe(Options({"m.x"}, 1, 10));
  std::atomic<bool> woke{false};
  std::thread sender([&] {
    try {
      recorder.WaitForBatches(id, std::chrono::seconds(30));
    } catch (const UnknownId&) {
      // unsubscribed before it started waiting: just as good
    }
    woke = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto start = std::chrono::steady_clock::now();
  recorder.Unsubscribe(id);
  sender.join();
  EXPECT_TRUE(woke);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

}  // namespace
}  // namespace caliper::daq
