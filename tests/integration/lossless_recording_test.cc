// Recording that loses nothing, against a real Model over the IDL: `step 20000` next to a
// deliberately slow lossless consumer delivers every sample in order (and the same run without
// lossless drops, counted); caliper-ctl record next to `step 20000` writes every sample; a
// real-time run never waits for a slow consumer, keeps pace and reports what it drops; a stopped
// (SIGSTOP) recorder holds the Model for at most the push deadline, then is dropped with a log
// line and the recorder, continued, exits 1 saying why.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/corba.h"

namespace caliper::testing {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
using std::chrono::seconds;

const char* const kTension = "pendulum_tendon.line.tendon.tension";
const char* const kPosition = "pendulum_tendon.frame.position";

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// The test's ORB, serving the consumers; calls give up after 30 s.
CORBA::ORB_ptr Orb() {
  return TestOrb({"lossless_recording_test", "-ORBendPoint",
                  "giop:tcp:127.0.0.1:", "-ORBclientCallTimeOutPeriod", "30000"});
}

/// A DataConsumer that takes `delay` over each batch and checks that the samples follow one
/// another: batch numbers 1, 2, 3, ... and each batch's first step right after the last sample
/// of the one before.
class SlowConsumer : public virtual POA_Caliper::Daq::DataConsumer {
 public:
  explicit SlowConsumer(milliseconds delay) : delay_(delay) {}

  void on_samples(const D::SampleBatch& b) override {
    std::this_thread::sleep_for(delay_);
    std::lock_guard<std::mutex> lock(mutex_);
    const uint64_t count = b.times.length();
    if (b.batch != next_batch_) {
      ++gaps_;
      if (first_break_.empty())
        first_break_ =
            "batch " + std::to_string(b.batch) + " after " + std::to_string(next_batch_ - 1);
    } else if (next_step_ != 0 && b.first_step != next_step_ && first_break_.empty()) {
      first_break_ = "batch " + std::to_string(b.batch) + " starts at step " +
                     std::to_string(b.first_step) + ", " + std::to_string(next_step_) + " expected";
    }
    for (CORBA::ULong i = 0; i < count; ++i) {
      if (b.times[i] <= last_time_ && first_break_.empty())
        first_break_ =
            "time " + std::to_string(b.times[i]) + " after " + std::to_string(last_time_);
      last_time_ = b.times[i];
    }
    next_batch_ = b.batch + 1;
    next_step_ = b.first_step + count;  // every step sampled
    samples_ += count;
  }

  uint64_t samples() {
    std::lock_guard<std::mutex> lock(mutex_);
    return samples_;
  }
  uint64_t gaps() {
    std::lock_guard<std::mutex> lock(mutex_);
    return gaps_;
  }
  /// "" when every sample followed the one before; else the first break.
  std::string first_break() {
    std::lock_guard<std::mutex> lock(mutex_);
    return first_break_;
  }

 private:
  const milliseconds delay_;
  std::mutex mutex_;
  uint64_t next_batch_ = 1;
  uint64_t next_step_ = 0;
  double last_time_ = -1;
  uint64_t samples_ = 0;
  uint64_t gaps_ = 0;
  std::string first_break_;
};

// ------------------------------------------------------------------------ fixture

class LosslessRecordingTest : public ModelProcessTest {
 protected:
  LosslessRecordingTest() : ModelProcessTest(&Orb) {}

  /// A consumer served by this process (its POA owns it; it lives until the ORB goes).
  D::DataConsumer_ptr Serve(SlowConsumer* consumer) {
    CORBA::Object_var ref = Activate(Orb(), consumer);
    return D::DataConsumer::_narrow(ref);
  }

  /// `step N` through the IDL; returns the wall time it took [s].
  double Step(CORBA::ULong n) {
    const auto begin = Clock::now();
    EXPECT_EQ(model()->step(n), n);
    return Seconds(Clock::now() - begin);
  }
};

S::StringSeq Ids(std::initializer_list<const char*> ids) {
  S::StringSeq out;
  out.length(static_cast<CORBA::ULong>(ids.size()));
  CORBA::ULong i = 0;
  for (const char* id : ids) out[i++] = id;
  return out;
}

// ------------------------------------------------------------------------ lock-step

TEST_F(LosslessRecordingTest, StepTwentyThousandDeliversEverySampleInOrderToASlowConsumer) {
  // 400 batches of 50 samples at 2 ms each: 0.8 s of consuming for 0.1 s of stepping
  auto* consumer = new SlowConsumer(milliseconds(2));
  D::DataConsumer_var ref = Serve(consumer);
  const CORBA::ULongLong id = model()->subscribe_lossless(Ids({kTension, kPosition}), 1, ref);
  const double took = Step(20000);
  ASSERT_TRUE(WaitFor([&] { return consumer->samples() >= 20000; }, seconds(20)))
      << consumer->samples() << " samples\n"
      << model_->Output();
  EXPECT_EQ(consumer->samples(), 20000u);
  EXPECT_EQ(consumer->gaps(), 0u);
  EXPECT_EQ(consumer->first_break(), "");
  const D::SubscriptionStatus status = model()->subscription_status(id);
  EXPECT_TRUE(status.lossless);
  EXPECT_EQ(status.samples, 20000u);
  EXPECT_EQ(status.batches, 400u);
  EXPECT_EQ(status.dropped_batches, 0u);
  EXPECT_EQ(status.dropped_samples, 0u);
  EXPECT_GT(status.waited, 0.1) << "the consumer was slower: the Model must have waited";
  EXPECT_GT(took, 0.5) << "400 batches at 2 ms each cannot arrive faster";
  model()->unsubscribe(id);
  EXPECT_THROW(model()->subscription_status(id), D::UnknownId);
}

TEST_F(LosslessRecordingTest, TheSameRunWithoutLosslessDropsAndCountsWhatItDropped) {
  // 50 ms per batch: the 400 batches would take 20 s to consume, and the steps take far less in
  // any build (step 20000 would have to take 1 ms a step), so the queue of 6 batches overflows
  auto* consumer = new SlowConsumer(milliseconds(50));
  D::DataConsumer_var ref = Serve(consumer);
  const CORBA::ULongLong id = model()->subscribe(Ids({kTension, kPosition}), 1, ref);
  Step(20000);  // nothing waits for a consumer that is not lossless: status.waited below
  D::SubscriptionStatus status{};
  // settles once the sender has sent what stayed queued
  ASSERT_TRUE(WaitFor(
      [&] {
        status = model()->subscription_status(id);
        return status.queued == 0 && consumer->samples() + status.dropped_samples == status.samples;
      },
      seconds(10)))
      << consumer->samples() << " received, " << status.dropped_samples << " dropped of "
      << status.samples;
  EXPECT_FALSE(status.lossless);
  EXPECT_EQ(status.samples, 20000u);
  EXPECT_EQ(status.batches, 400u);
  // dropped, counted in whole batches of 50 samples, and what arrived plus what was dropped is
  // every sample (the wait above)
  EXPECT_GT(status.dropped_samples, 0u);
  EXPECT_EQ(status.dropped_samples, 50 * status.dropped_batches);
  EXPECT_EQ(consumer->samples(), 20000u - status.dropped_samples);
  EXPECT_GT(consumer->gaps(), 0u);
  EXPECT_EQ(status.waited, 0.0);
  std::printf("[ measure  ] without lossless: %llu of 20000 samples dropped\n",
              static_cast<unsigned long long>(status.dropped_samples));
}

TEST_F(LosslessRecordingTest, CtlRecordNextToStepTwentyThousandWritesEverySample) {
  const std::string csv = dir_.path() + "/record.csv";
  Process record({Bin("caliper-ctl"), "--nameservice", naming_->address(), "record", kTension,
                  kPosition, "--csv", csv, "--duration", "20"},
                 dir_.path() + "/record.out");
  ASSERT_TRUE(WaitFor([&] { return Contains(record.Output(), "lossless:"); }, seconds(10)))
      << record.Output();
  const CommandResult step = Ctl(naming_->address(), {"step", "20000"});
  EXPECT_EQ(step.exit_code, 0) << step.err;
  ASSERT_EQ(record.Wait(seconds(20)), 0) << record.Output();
  EXPECT_TRUE(Contains(record.Output(), "wrote 20000 samples (t = 0.001 .. 20 s)"))
      << record.Output();
  EXPECT_TRUE(Contains(record.Output(), "no gaps: 400 batches")) << record.Output();
  EXPECT_TRUE(Contains(record.Output(), "dropped: none")) << record.Output();
  // every millisecond from 0.001 to 20 s, once, in order
  std::istringstream in(ReadFile(csv));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "time [s],pendulum_tendon.line.tendon.tension [N],pendulum_tendon.frame.position[0] "
            "[m],pendulum_tendon.frame.position[1] [m],pendulum_tendon.frame.position[2] [m]");
  long rows = 0;
  std::string first_break;
  while (std::getline(in, line)) {
    ++rows;
    const double t = std::strtod(line.c_str(), nullptr);
    if (first_break.empty() && std::abs(t - rows * 0.001) > 1e-9)
      first_break = "row " + std::to_string(rows) + ": " + line;
  }
  EXPECT_EQ(rows, 20000);
  EXPECT_EQ(first_break, "");
}

// ------------------------------------------------------------------------ real time

TEST_F(LosslessRecordingTest, ARealTimeRunKeepsPaceWithASlowConsumerAndReportsTheDrops) {
  // batches of 50 ms of simulated time, taken 500 ms each: in 2.5 s at most 6 arrive and 6 wait
  // in the queue, of the 25 even a Model at half speed makes
  auto* consumer = new SlowConsumer(milliseconds(500));
  D::DataConsumer_var ref = Serve(consumer);
  const CORBA::ULongLong id = model()->subscribe_lossless(Ids({kTension}), 1, ref);
  model()->start();
  const auto begin = Clock::now();
  std::this_thread::sleep_for(milliseconds(2500));
  M::SimulationStatus_var s = model()->status();
  const double wall = Seconds(Clock::now() - begin);
  model()->pause();
  const uint64_t received = consumer->samples();  // before the status: none counted twice
  const D::SubscriptionStatus status = model()->subscription_status(id);
  EXPECT_TRUE(status.lossless);
  // the Model was not held: its own count of the time it waited for the consumer
  EXPECT_EQ(status.waited, 0.0) << "a real-time run must not wait for a consumer";
  // and it kept going (with margin for a loaded machine: a held Model would show ~0.1)
  EXPECT_GT(s->sim_time, 0.5 * wall) << s->sim_time << " s simulated in " << wall << " s";
  EXPECT_GT(s->achieved_real_time_factor, 0.5);
  // what did not fit was dropped and counted, in whole batches of 50 samples
  EXPECT_GT(status.dropped_samples, 0u);
  EXPECT_EQ(status.dropped_samples, 50 * status.dropped_batches);
  EXPECT_LE(received + status.dropped_samples + 50 * status.queued, status.samples);
  EXPECT_GT(consumer->gaps(), 0u);
  std::printf(
      "[ measure  ] real time: %.2f s simulated in %.2f s (factor %.2f), %llu of %llu "
      "samples dropped\n",
      s->sim_time, wall, s->achieved_real_time_factor,
      static_cast<unsigned long long>(status.dropped_samples),
      static_cast<unsigned long long>(status.samples));
  EXPECT_TRUE(
      WaitFor([&] { return Contains(model_->Output(), "samples dropped so far"); }, seconds(5)))
      << model_->Output();
  model()->unsubscribe(id);
  EXPECT_TRUE(WaitFor([&] { return Contains(model_->Output(), "of them dropped"); }, seconds(5)))
      << model_->Output();
}

// ------------------------------------------------------------------------ bound

TEST_F(LosslessRecordingTest, AStoppedRecorderHoldsTheModelAtMostThePushDeadlineThenIsDropped) {
  const std::string csv = dir_.path() + "/stopped.csv";
  Process record({Bin("caliper-ctl"), "--nameservice", naming_->address(), "record", kTension,
                  "--csv", csv, "--duration", "20"},
                 dir_.path() + "/record.out");
  ASSERT_TRUE(WaitFor([&] { return Contains(record.Output(), "lossless:"); }, seconds(10)))
      << record.Output();
  record.Signal(SIGSTOP);
  // the Model fills the queue, waits, its push times out after 1 s: dropped, then it goes on
  const double held = Step(20000);
  EXPECT_GT(held, 0.9) << "the Model did not wait for the lossless recorder";
  // the push deadline (1 s) ends it, the Model's own backstop (2 s) at the latest; margin for a
  // loaded machine
  EXPECT_LT(held, 5.0) << "the Model waited longer than the push deadline and its backstop";
  EXPECT_TRUE(Contains(model_->Output(), "dropping subscription")) << model_->Output();
  EXPECT_TRUE(Contains(model_->Output(), "a lossless subscription ends at its first failed push"))
      << model_->Output();
  // nothing holds it now: the same steps take a fraction of the held ones
  EXPECT_LT(Step(20000), 0.5 * held);
  record.Signal(SIGCONT);
  EXPECT_EQ(record.Wait(seconds(10)), 1) << record.Output();
  EXPECT_TRUE(Contains(record.Output(), "was ended by the Model: a push failed: TIMEOUT"))
      << record.Output();
}

// A recording waiting on a Model that no longer runs says so instead of waiting without a word.
TEST_F(LosslessRecordingTest, CtlRecordOnAPausedModelSaysItWaitsForIt) {
  const CommandResult start = Ctl(naming_->address(), {"start"});
  ASSERT_EQ(start.exit_code, 0) << start.err;
  const std::string csv = dir_.path() + "/record.csv";
  Process record({Bin("caliper-ctl"), "--nameservice", naming_->address(), "record", kTension,
                  "--csv", csv, "--duration", "1000"},
                 dir_.path() + "/record.out");
  ASSERT_TRUE(WaitFor([&] { return Contains(record.Output(), "lossless:"); }, seconds(10)))
      << record.Output();
  EXPECT_FALSE(Contains(record.Output(), "PAUSED")) << record.Output();
  const CommandResult pause = Ctl(naming_->address(), {"pause"});
  ASSERT_EQ(pause.exit_code, 0) << pause.err;
  // checked once a second, after a second without samples
  EXPECT_TRUE(WaitFor(
      [&] {
        return Contains(record.Output(),
                        "model0 is PAUSED: waiting until it runs (caliper-ctl start) or steps");
      },
      seconds(5)))
      << record.Output();
  record.Signal(SIGTERM);
  EXPECT_EQ(record.Wait(seconds(10)), 0) << record.Output();
  EXPECT_TRUE(Contains(record.Output(), "terminated (SIGTERM)")) << record.Output();
}

}  // namespace
}  // namespace caliper::testing
