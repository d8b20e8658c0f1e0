#include "caliper/rtc/execution_context.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "test_component.h"

namespace caliper::rtc {
namespace {

using std::chrono::milliseconds;
using testing::TestComponent;

class ExecutionContextTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(lifecycle_.Initialize(), ReturnCode::kOk);
    ASSERT_EQ(lifecycle_.Activate(), ReturnCode::kOk);
  }

  TestComponent component_;
  Lifecycle lifecycle_{&component_, "test"};
};

// --- periodic

TEST_F(ExecutionContextTest, PeriodicTicksAtRoughlyItsRate) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 200);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  EXPECT_TRUE(context.is_running());
  std::this_thread::sleep_for(milliseconds(300));  // the rate is what is measured here
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  EXPECT_FALSE(context.is_running());

  const int executes = component_.count(testing::kExecute);
  EXPECT_GE(executes, 20);
  EXPECT_LE(executes, 80);
  EXPECT_EQ(context.statistics().ticks, static_cast<uint64_t>(executes));
  EXPECT_EQ(component_.count(testing::kStateUpdate), executes);
}

TEST_F(ExecutionContextTest, PeriodicCountsNoOverrunsForShortTicks) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 50);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(10, milliseconds(1500)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  const auto stats = context.statistics();
  EXPECT_GE(stats.ticks, 10u);
  EXPECT_LT(stats.overruns, stats.ticks / 2);  // a scheduling hiccup at most, not every tick
}

TEST_F(ExecutionContextTest, PeriodicCountsOverrunsWhenExecuteTakesLongerThanAPeriod) {
  component_.SetExecuteDuration(milliseconds(15));
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 200);  // 5 ms period
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(5, milliseconds(1500)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);

  const auto stats = context.statistics();
  EXPECT_GE(stats.ticks, 5u);
  EXPECT_GE(stats.overruns, stats.ticks - 1);  // every tick overran
  EXPECT_GE(stats.max_execute_time_s, 0.015);
  EXPECT_GE(stats.last_execute_time_s, 0.015);
  EXPECT_LT(stats.max_execute_time_s, 1.0);
}

TEST_F(ExecutionContextTest, PeriodicDoesNotCatchUpAfterOverruns) {
  component_.SetExecuteDuration(milliseconds(30));
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 100);  // 10 ms period
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(5, milliseconds(1500)));  // 100 ms behind schedule
  component_.SetExecuteDuration(milliseconds(0));
  const int before = component_.count(testing::kExecute);
  const auto begin = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(milliseconds(100));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  const auto elapsed =
      std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - begin);
  // one tick per period; catching up would add a burst of about ten more
  EXPECT_LE(component_.count(testing::kExecute) - before, elapsed.count() / 10 + 3);
}

TEST_F(ExecutionContextTest, StartRunsStartupBeforeTicksAndStopRunsShutdownAfterThem) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 500);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(3, milliseconds(1000)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);

  const auto calls = component_.calls();
  ASSERT_GE(calls.size(), 4u);
  EXPECT_EQ(calls[2], "on_startup");  // after on_initialize, on_activated
  EXPECT_EQ(calls[3], "on_execute");
  EXPECT_EQ(calls.back(), "on_shutdown");
  EXPECT_EQ(component_.count(testing::kStartup), 1);
  EXPECT_EQ(component_.count(testing::kShutdown), 1);
}

TEST_F(ExecutionContextTest, NoTicksAfterStop) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 500);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(2, milliseconds(1000)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  const int after_stop = component_.count(testing::kExecute);
  std::this_thread::sleep_for(milliseconds(30));  // fifteen periods
  EXPECT_EQ(component_.count(testing::kExecute), after_stop);
}

TEST_F(ExecutionContextTest, RejectsStartTwice) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 100);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  EXPECT_EQ(context.Start(), ReturnCode::kPreconditionNotMet);
  EXPECT_TRUE(context.is_running());
  EXPECT_EQ(component_.count(testing::kStartup), 1);
  EXPECT_EQ(context.Stop(), ReturnCode::kOk);
}

TEST_F(ExecutionContextTest, RejectsStopWhenStopped) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 100);
  EXPECT_EQ(context.Stop(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(component_.count(testing::kShutdown), 0);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  EXPECT_EQ(context.Stop(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(component_.count(testing::kShutdown), 1);
}

TEST_F(ExecutionContextTest, RestartsAfterStopWithFreshStatistics) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 500);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(5, milliseconds(1000)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  const int first_run = component_.count(testing::kExecute);

  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(first_run + 2, milliseconds(1000)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  const auto stats = context.statistics();
  EXPECT_EQ(stats.ticks, static_cast<uint64_t>(component_.count(testing::kExecute) - first_run));
  EXPECT_EQ(component_.count(testing::kStartup), 2);
  EXPECT_EQ(component_.count(testing::kShutdown), 2);
}

TEST_F(ExecutionContextTest, DestructorStopsARunningContext) {
  {
    ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 500);
    ASSERT_EQ(context.Start(), ReturnCode::kOk);
    ASSERT_TRUE(component_.WaitForExecutes(1, milliseconds(1000)));
  }
  EXPECT_EQ(component_.count(testing::kShutdown), 1);
  const int executes = component_.count(testing::kExecute);
  std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(component_.count(testing::kExecute), executes);
}

TEST_F(ExecutionContextTest, TicksOnlyWhatTheStateAllows) {
  ASSERT_EQ(lifecycle_.Deactivate(), ReturnCode::kOk);
  ExecutionContext context(&lifecycle_, ContextKind::kExternal, 100);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  EXPECT_EQ(context.Tick(), ReturnCode::kOk);
  EXPECT_EQ(context.statistics().ticks, 1u);
  EXPECT_EQ(component_.count(testing::kExecute), 0);  // INACTIVE: nothing runs
}

TEST_F(ExecutionContextTest, FailingExecuteMovesToErrorAndLaterTicksRunOnError) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 500);
  component_.Throw(testing::kExecute);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(1, milliseconds(1000)));
  EXPECT_TRUE(component_.WaitFor(testing::kOnError, 3, milliseconds(1000)));  // following ticks
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kExecute), 1);
  EXPECT_GE(component_.count(testing::kOnError), 3);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_execute threw: on_execute exploded");
}

// --- rate

TEST_F(ExecutionContextTest, RejectsRatesOutsideTheRange) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 100);
  EXPECT_EQ(context.SetRate(0), ReturnCode::kBadParameter);
  EXPECT_EQ(context.SetRate(-5), ReturnCode::kBadParameter);
  EXPECT_EQ(context.SetRate(2e6), ReturnCode::kBadParameter);
  EXPECT_EQ(context.SetRate(std::numeric_limits<double>::quiet_NaN()), ReturnCode::kBadParameter);
  EXPECT_EQ(context.SetRate(std::numeric_limits<double>::infinity()), ReturnCode::kBadParameter);
  // positive but so slow that the period overflows the clock (it ticked ~7 million times a second)
  EXPECT_EQ(context.SetRate(1e-300), ReturnCode::kBadParameter);
  EXPECT_EQ(context.SetRate(std::numeric_limits<double>::denorm_min()), ReturnCode::kBadParameter);
  EXPECT_EQ(context.SetRate(0.9e-3), ReturnCode::kBadParameter);
  EXPECT_DOUBLE_EQ(context.rate(), 100.0);
  EXPECT_EQ(component_.count(testing::kRateChanged), 0);
}

TEST_F(ExecutionContextTest, SetRateChangesRateAndCallsOnRateChanged) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 100);
  EXPECT_EQ(context.SetRate(50), ReturnCode::kOk);
  EXPECT_DOUBLE_EQ(context.rate(), 50.0);
  EXPECT_EQ(component_.count(testing::kRateChanged), 1);
  EXPECT_EQ(context.SetRate(1e6), ReturnCode::kOk);  // the upper bound is allowed
  EXPECT_EQ(component_.count(testing::kRateChanged), 2);
  EXPECT_EQ(context.SetRate(1e-3), ReturnCode::kOk);  // and the lower one (exec.rate's)
  EXPECT_EQ(component_.count(testing::kRateChanged), 3);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
}

TEST_F(ExecutionContextTest, SetRateSpeedsUpARunningContext) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 5);  // 200 ms period
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(1, milliseconds(1000)));
  ASSERT_EQ(context.SetRate(500), ReturnCode::kOk);
  // at 5 Hz twenty ticks take four seconds
  EXPECT_TRUE(component_.WaitForExecutes(21, milliseconds(1000)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
}

TEST_F(ExecutionContextTest, FailingRateChangedMovesToError) {
  ExecutionContext context(&lifecycle_, ContextKind::kExternal, 100);
  component_.Fail(testing::kRateChanged);
  context.SetRate(50);
  EXPECT_EQ(component_.count(testing::kRateChanged), 1);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(lifecycle_.last_error(), "on_rate_changed returned RTC_ERROR");
}

// --- external

TEST_F(ExecutionContextTest, ExternalRunsExactlyOneExecutePerTick) {
  ExecutionContext context(&lifecycle_, ContextKind::kExternal, 100);
  EXPECT_EQ(context.kind(), ContextKind::kExternal);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  EXPECT_EQ(component_.count(testing::kStartup), 1);
  for (int i = 1; i <= 5; ++i) {
    ASSERT_EQ(context.Tick(), ReturnCode::kOk);
    EXPECT_EQ(component_.count(testing::kExecute), i);
    EXPECT_EQ(component_.count(testing::kStateUpdate), i);
  }
  std::this_thread::sleep_for(milliseconds(30));  // three nominal periods: no thread ticks
  EXPECT_EQ(component_.count(testing::kExecute), 5);
  EXPECT_EQ(context.statistics().ticks, 5u);
  EXPECT_EQ(context.statistics().overruns, 0u);
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  EXPECT_EQ(component_.count(testing::kShutdown), 1);
}

TEST_F(ExecutionContextTest, ExternalMeasuresExecuteTime) {
  component_.SetExecuteDuration(milliseconds(10));
  ExecutionContext context(&lifecycle_, ContextKind::kExternal, 100);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_EQ(context.Tick(), ReturnCode::kOk);
  EXPECT_GE(context.statistics().last_execute_time_s, 0.010);
  EXPECT_GE(context.statistics().max_execute_time_s, 0.010);
}

TEST_F(ExecutionContextTest, RejectsTickOnPeriodicContext) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 1);  // one tick a second
  EXPECT_EQ(context.Tick(), ReturnCode::kUnsupported);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_TRUE(component_.WaitForExecutes(1, milliseconds(1000)));  // the first tick is at once
  EXPECT_EQ(context.Tick(), ReturnCode::kUnsupported);
  EXPECT_EQ(component_.count(testing::kExecute), 1);
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
}

TEST_F(ExecutionContextTest, RejectsTickWhenNotStarted) {
  ExecutionContext context(&lifecycle_, ContextKind::kExternal, 100);
  EXPECT_EQ(context.Tick(), ReturnCode::kPreconditionNotMet);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  EXPECT_EQ(context.Tick(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(component_.count(testing::kExecute), 0);
  EXPECT_EQ(context.statistics().ticks, 0u);
}

TEST_F(ExecutionContextTest, ExternalTicksRunOnErrorInError) {
  ExecutionContext context(&lifecycle_, ContextKind::kExternal, 100);
  ASSERT_EQ(context.Start(), ReturnCode::kOk);
  component_.Fail(testing::kExecute);
  ASSERT_EQ(context.Tick(), ReturnCode::kOk);
  ASSERT_EQ(lifecycle_.state(), State::kError);
  ASSERT_EQ(context.Tick(), ReturnCode::kOk);
  ASSERT_EQ(context.Tick(), ReturnCode::kOk);
  EXPECT_EQ(component_.count(testing::kOnError), 2);
  EXPECT_EQ(component_.count(testing::kExecute), 1);
  EXPECT_EQ(component_.count(testing::kStateUpdate), 0);
}

// --- concurrent control (clients calling start/stop and activate/deactivate at once)

TEST_F(ExecutionContextTest, ConcurrentStartsAndStopsFromSixThreadsKeepStartupAndShutdownPaired) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 1000);
  constexpr int kThreads = 6;
  constexpr int kPairs = 300;
  std::atomic<int> started{0}, stopped{0}, refused{0}, other{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < kThreads; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < kPairs; ++i) {
        for (const bool start : {true, false}) {
          const ReturnCode rc = start ? context.Start() : context.Stop();
          if (rc == ReturnCode::kOk)
            ++(start ? started : stopped);
          else if (rc == ReturnCode::kPreconditionNotMet)
            ++refused;
          else
            ++other;
        }
      }
    });
  for (auto& c : clients) c.join();

  EXPECT_EQ(other.load(), 0);
  EXPECT_EQ(started + stopped + refused, 2 * kThreads * kPairs);
  EXPECT_GT(started.load(), 0);
  // every accepted start ran on_startup once, every accepted stop on_shutdown once, alternately
  EXPECT_EQ(component_.count(testing::kStartup), started.load());
  EXPECT_EQ(component_.count(testing::kShutdown), stopped.load());
  EXPECT_EQ(started - stopped, context.is_running() ? 1 : 0);
  std::string previous;
  for (const std::string& call : component_.calls()) {
    if (call != "on_startup" && call != "on_shutdown") continue;
    EXPECT_NE(call, previous) << "two " << call << " in a row";
    previous = call;
  }
  // the context still works: started once more it ticks, stopped it does not
  if (!context.is_running()) {
    ASSERT_EQ(context.Start(), ReturnCode::kOk);
  }
  const int executes = component_.count(testing::kExecute);
  EXPECT_TRUE(component_.WaitForExecutes(executes + 5, milliseconds(5000)));
  ASSERT_EQ(context.Stop(), ReturnCode::kOk);
  const int after_stop = component_.count(testing::kExecute);
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_EQ(component_.count(testing::kExecute), after_stop);
}

TEST_F(ExecutionContextTest, ConcurrentActivateDeactivateWhileStartingAndStoppingStayConsistent) {
  ExecutionContext context(&lifecycle_, ContextKind::kPeriodic, 1000);
  std::atomic<int> activated{0}, deactivated{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 3; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < 300; ++i) {
        context.Start();
        context.Stop();
      }
    });
  for (int t = 0; t < 3; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < 300; ++i) {
        if (lifecycle_.Deactivate() == ReturnCode::kOk) ++deactivated;
        if (lifecycle_.Activate() == ReturnCode::kOk) ++activated;
      }
    });
  for (auto& c : clients) c.join();
  // the component was ACTIVE before: each deactivation was followed by one activation or none
  const int open = deactivated - activated;
  EXPECT_TRUE(open == 0 || open == 1) << deactivated << " deactivated, " << activated
                                      << " activated";
  EXPECT_EQ(lifecycle_.state(), open == 0 ? State::kActive : State::kInactive);
  EXPECT_EQ(component_.count(testing::kActivated), activated.load() + 1) << "one in SetUp";
  EXPECT_EQ(component_.count(testing::kDeactivated), deactivated.load());
  EXPECT_EQ(component_.count(testing::kAborting), 0);
}

}  // namespace
}  // namespace caliper::rtc
