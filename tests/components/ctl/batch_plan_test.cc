// caliper-ctl batch's bookkeeping: runs handed out in order, the first result wins, a retry per
// attempt at most and at the front of the queue, giving up after the last attempt, and every run
// ending exactly once when several workers pull, retry and complete at the same time.
#include "batch_plan.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace caliper::ctl {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
using State = Outcome::State;

const milliseconds kNoWait(0);

double SecondsSince(Clock::time_point begin) {
  return std::chrono::duration<double>(Clock::now() - begin).count();
}

// a result as a Model reports it
Outcome Result(const std::string& model, uint64_t steps) {
  Outcome o;
  o.model = model;
  o.wall_s = 1.25;
  o.load_wall_s = 0.5;
  o.step_wall_s = 0.75;
  o.steps = steps;
  o.samples = static_cast<size_t>(steps / 10 + 1);
  return o;
}

TEST(OutcomeState, HasAName) {
  EXPECT_STREQ(ToString(State::kPending), "pending");
  EXPECT_STREQ(ToString(State::kRunning), "running");
  EXPECT_STREQ(ToString(State::kDone), "done");
  EXPECT_STREQ(ToString(State::kFailed), "failed");
}

TEST(BatchPlan, StartsWithEveryRunPending) {
  BatchPlan plan(3, 2);
  EXPECT_EQ(plan.size(), 3u);
  EXPECT_FALSE(plan.finished());
  EXPECT_EQ(plan.done(), 0u);
  EXPECT_EQ(plan.failed(), 0u);
  EXPECT_EQ(plan.running(), 0u);
  for (const Outcome& o : plan.outcomes()) {
    EXPECT_EQ(o.state, State::kPending);
    EXPECT_EQ(o.attempts, 0);
  }
}

TEST(BatchPlan, HandsOutRunsInOrderWithDistinctTokens) {
  BatchPlan plan(3, 2);
  const auto a = plan.Next("model1@a", kNoWait);
  const auto b = plan.Next("model2@b", kNoWait);
  const auto c = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->run, 0u);
  EXPECT_EQ(b->run, 1u);
  EXPECT_EQ(c->run, 2u);
  EXPECT_NE(a->token, b->token);
  EXPECT_NE(b->token, c->token);
  EXPECT_NE(a->token, c->token);
  EXPECT_EQ(plan.running(), 3u);
  EXPECT_EQ(plan.outcomes()[1].state, State::kRunning);
  EXPECT_EQ(plan.outcomes()[1].attempts, 1);
  EXPECT_FALSE(plan.Next("model3@c", kNoWait)) << "every run is taken";
}

TEST(BatchPlan, CompleteKeepsTheResultWithAttemptsAndRetries) {
  BatchPlan plan(1, 3);
  const auto first = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(first);
  plan.Retry(*first, "model1@a: TRANSIENT");
  const auto second = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(second);
  EXPECT_TRUE(plan.Complete(*second, Result("model2@b", 500)));

  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kDone);
  EXPECT_EQ(o.model, "model2@b");
  EXPECT_EQ(o.attempts, 2);
  ASSERT_EQ(o.retries.size(), 1u);
  EXPECT_EQ(o.retries[0].model, "model1@a");
  EXPECT_EQ(o.retries[0].reason, "model1@a: TRANSIENT");
  EXPECT_EQ(o.wall_s, 1.25);
  EXPECT_EQ(o.load_wall_s, 0.5);
  EXPECT_EQ(o.step_wall_s, 0.75);
  EXPECT_EQ(o.steps, 500u);
  EXPECT_EQ(o.samples, 51u);
  EXPECT_EQ(o.reason, "");
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_EQ(plan.running(), 0u);
  EXPECT_TRUE(plan.finished());
}

TEST(BatchPlan, AbandonedAttemptsNeitherCountNorFail) {
  // scancel: the Models die with the client; a run lost then waits again, with no retry and no
  // attempt used, however often it happens, and a stale ticket changes nothing
  BatchPlan plan(2, 2);
  for (int i = 0; i < 5; ++i) {
    const auto t = plan.Next("model1@a", kNoWait);
    ASSERT_TRUE(t);
    EXPECT_EQ(t->run, 0u) << "the abandoned run is first in line again";
    plan.Abandon(*t);
    plan.Abandon(*t);  // once per ticket: not queued twice, not refunded twice
  }
  {
    // run 0 once in the queue, then run 1
    const auto a = plan.Next("model1@a", kNoWait);
    const auto b = plan.Next("model1@a", kNoWait);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->run, 0u);
    EXPECT_EQ(b->run, 1u);
    EXPECT_FALSE(plan.Next("model1@a", kNoWait)) << "no run queued twice";
    EXPECT_EQ(plan.outcomes()[0].attempts, 1);
    plan.Abandon(*b);
    plan.Abandon(*a, true);  // in front again
    EXPECT_TRUE(plan.outcomes()[0].stopped) << "abandoned while the batch stopped";
    EXPECT_FALSE(plan.outcomes()[1].stopped);
  }
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kPending);
  EXPECT_EQ(o.attempts, 0);
  EXPECT_TRUE(o.retries.empty());
  EXPECT_EQ(plan.failed(), 0u);
  EXPECT_FALSE(plan.finished());
  // a run that ended meanwhile stays ended
  const auto a = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(a);
  EXPECT_TRUE(plan.Complete(*a, Result("model1@a", 10)));
  plan.Abandon(*a);
  EXPECT_EQ(plan.outcomes()[0].state, State::kDone);
  EXPECT_EQ(plan.outcomes()[0].attempts, 1);
}

TEST(BatchPlan, FirstResultWinsAndDuplicatesReturnFalse) {
  BatchPlan plan(2, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  EXPECT_TRUE(plan.Complete(*t, Result("model1@a", 100)));
  EXPECT_FALSE(plan.Complete(*t, Result("model9@z", 999)));
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.model, "model1@a");
  EXPECT_EQ(o.steps, 100u);
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_FALSE(plan.finished());
}

TEST(BatchPlan, AClosedPlanEndsNoRunAndHandsOutNone) {
  // a stopped batch closes its plan before the summary: what the summary says cannot change
  BatchPlan plan(5, 2);
  std::vector<BatchPlan::Ticket> t;
  for (const char* model : {"model1@a", "model2@b", "model3@c", "model4@d"}) {
    const auto ticket = plan.Next(model, kNoWait);
    ASSERT_TRUE(ticket);
    t.push_back(*ticket);
  }
  EXPECT_TRUE(plan.Complete(t[0], Result("model1@a", 100)));
  plan.Close();
  EXPECT_FALSE(plan.Complete(t[1], Result("model2@b", 200))) << "so no file is written for it";
  plan.Fail(t[2], "a fault after the stop");
  plan.Abandon(t[3], true);  // its Model went down with the batch
  const auto outcomes = plan.outcomes();
  EXPECT_EQ(outcomes[0].state, State::kDone);
  EXPECT_EQ(outcomes[1].state, State::kRunning) << "reported as interrupted, not done";
  EXPECT_EQ(outcomes[2].state, State::kRunning) << "nor failed";
  EXPECT_EQ(outcomes[3].state, State::kPending);
  EXPECT_TRUE(outcomes[3].stopped);
  EXPECT_EQ(outcomes[4].state, State::kPending);
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_EQ(plan.failed(), 0u);
  // the abandoned run waits again, but nothing is handed out, at once
  const auto begin = Clock::now();
  EXPECT_FALSE(plan.Next("model1@a", milliseconds(2000)));
  EXPECT_LT(SecondsSince(begin), 1.0) << "a closed plan does not wait";
  EXPECT_FALSE(plan.finished());
}

TEST(BatchPlan, CompleteAfterFailIsDropped) {
  BatchPlan plan(1, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  plan.Fail(*t, "unknown id 'arm.nothing'");
  EXPECT_FALSE(plan.Complete(*t, Result("model1@a", 100)));
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kFailed);
  EXPECT_EQ(o.reason, "unknown id 'arm.nothing'");
  EXPECT_EQ(o.model, "model1@a");
  EXPECT_EQ(plan.failed(), 1u);
  EXPECT_EQ(plan.done(), 0u);
  EXPECT_TRUE(plan.finished());
}

TEST(BatchPlan, FailAfterCompleteChangesNothing) {
  BatchPlan plan(1, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  EXPECT_TRUE(plan.Complete(*t, Result("model1@a", 100)));
  plan.Fail(*t, "late");
  plan.Retry(*t, "later");
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kDone);
  EXPECT_EQ(o.reason, "");
  EXPECT_TRUE(o.retries.empty());
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_EQ(plan.failed(), 0u);
  EXPECT_FALSE(plan.Next("model1@a", kNoWait));
}

TEST(BatchPlan, RequeuesARetriedRunAtTheFront) {
  BatchPlan plan(3, 3);
  const auto r0 = plan.Next("model1@a", kNoWait);
  const auto r1 = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(r0 && r1);
  plan.Retry(*r1, "model2@b: COMM_FAILURE");
  EXPECT_EQ(plan.outcomes()[1].state, State::kPending);
  EXPECT_EQ(plan.running(), 1u);
  const auto again = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->run, 1u) << "the retried run before run 2";
  EXPECT_NE(again->token, r1->token);
  EXPECT_EQ(plan.outcomes()[1].attempts, 2);
  const auto last = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->run, 2u);
}

TEST(BatchPlan, RetriesOnlyOncePerTicket) {
  BatchPlan plan(1, 5);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  plan.Retry(*t, "no answer for 5.0 s");
  plan.Retry(*t, "no answer for 6.0 s");
  plan.Retry(*t, "TRANSIENT");
  EXPECT_EQ(plan.outcomes()[0].retries.size(), 1u);
  EXPECT_EQ(plan.outcomes()[0].retries[0].reason, "no answer for 5.0 s");
  const auto again = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(again);
  EXPECT_FALSE(plan.Next("model3@c", kNoWait)) << "the run was queued once, not three times";
  // a second late retry of the old ticket does not take the run from the new attempt
  plan.Retry(*t, "TRANSIENT");
  EXPECT_EQ(plan.outcomes()[0].state, State::kRunning);
  EXPECT_EQ(plan.outcomes()[0].retries.size(), 1u);
  EXPECT_FALSE(plan.Next("model3@c", kNoWait));
}

TEST(BatchPlan, GivesUpAfterMaxAttempts) {
  BatchPlan plan(1, 3);
  const char* models[] = {"model1@a", "model2@b", "model3@c"};
  for (int attempt = 1; attempt <= 3; ++attempt) {
    EXPECT_FALSE(plan.finished());
    const auto t = plan.Next(models[attempt - 1], kNoWait);
    ASSERT_TRUE(t) << "attempt " << attempt;
    plan.Retry(*t, std::string(models[attempt - 1]) + ": TRANSIENT");
  }
  EXPECT_TRUE(plan.finished());
  EXPECT_EQ(plan.failed(), 1u);
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kFailed);
  EXPECT_EQ(o.reason, "gave up after 3 attempts");
  EXPECT_EQ(o.attempts, 3);
  ASSERT_EQ(o.retries.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(o.retries[i].model, models[i]);
    EXPECT_EQ(o.retries[i].reason, std::string(models[i]) + ": TRANSIENT");
  }
  EXPECT_FALSE(plan.Next("model1@a", kNoWait));
}

TEST(BatchPlan, TriesAtLeastOnce) {
  BatchPlan plan(1, 0);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  plan.Retry(*t, "TRANSIENT");
  EXPECT_EQ(plan.outcomes()[0].reason, "gave up after 1 attempts");
  EXPECT_TRUE(plan.finished());
}

TEST(BatchPlan, StaleCompleteAfterRetryCountsWhenFirst) {
  BatchPlan plan(2, 3);
  const auto old = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(old);
  plan.Retry(*old, "model1@a: no answer for 5.0 s");
  // the Model that was given up on finishes after all, before anyone took the run again
  EXPECT_TRUE(plan.Complete(*old, Result("model1@a", 42)));
  EXPECT_EQ(plan.outcomes()[0].state, State::kDone);
  EXPECT_EQ(plan.outcomes()[0].model, "model1@a");
  EXPECT_EQ(plan.outcomes()[0].retries.size(), 1u);
  // the queued copy of run 0 is skipped
  const auto next = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->run, 1u);
  EXPECT_EQ(plan.outcomes()[0].attempts, 1);
}

TEST(BatchPlan, StaleCompleteWinsOverTheNewAttempt) {
  BatchPlan plan(1, 3);
  const auto old = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(old);
  plan.Retry(*old, "model1@a: no answer for 5.0 s");
  const auto fresh = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(fresh);
  EXPECT_TRUE(plan.Complete(*old, Result("model1@a", 42)));
  EXPECT_FALSE(plan.Complete(*fresh, Result("model2@b", 43)));
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.model, "model1@a");
  EXPECT_EQ(o.steps, 42u);
  EXPECT_EQ(o.attempts, 2);
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_TRUE(plan.finished());
}

TEST(BatchPlan, RetryOfANewAttemptAfterAStaleCompleteChangesNothing) {
  BatchPlan plan(1, 3);
  const auto old = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(old);
  plan.Retry(*old, "stall");
  const auto fresh = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(fresh);
  EXPECT_TRUE(plan.Complete(*old, Result("model1@a", 42)));
  plan.Retry(*fresh, "model2@b: TRANSIENT");
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kDone);
  EXPECT_EQ(o.retries.size(), 1u);
  EXPECT_FALSE(plan.Next("model2@b", kNoWait));
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_EQ(plan.failed(), 0u);
}

TEST(BatchPlan, CountsDoneFailedAndRunning) {
  BatchPlan plan(4, 1);
  std::vector<BatchPlan::Ticket> t;
  for (int i = 0; i < 4; ++i) {
    const auto ticket = plan.Next("model1@a", kNoWait);
    ASSERT_TRUE(ticket);
    t.push_back(*ticket);
  }
  EXPECT_TRUE(plan.Complete(t[0], Result("model1@a", 1)));
  plan.Fail(t[1], "physics fault");
  plan.Retry(t[2], "TRANSIENT");  // one attempt only: gives up
  EXPECT_EQ(plan.done(), 1u);
  EXPECT_EQ(plan.failed(), 2u);
  EXPECT_EQ(plan.running(), 1u);
  EXPECT_FALSE(plan.finished());
  EXPECT_TRUE(plan.Complete(t[3], Result("model1@a", 1)));
  EXPECT_EQ(plan.done(), 2u);
  EXPECT_EQ(plan.running(), 0u);
  EXPECT_TRUE(plan.finished());
  EXPECT_EQ(plan.outcomes()[2].reason, "gave up after 1 attempts");
}

TEST(BatchPlan, NextReturnsNothingAtOnceWhenAllEnded) {
  BatchPlan plan(1, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  EXPECT_TRUE(plan.Complete(*t, Result("model1@a", 1)));
  const auto begin = Clock::now();
  EXPECT_FALSE(plan.Next("model1@a", milliseconds(5000)));
  EXPECT_LT(SecondsSince(begin), 1.0);
}

TEST(BatchPlan, EmptyPlanIsFinished) {
  BatchPlan plan(0, 2);
  EXPECT_TRUE(plan.finished());
  const auto begin = Clock::now();
  EXPECT_FALSE(plan.Next("model1@a", milliseconds(5000)));
  EXPECT_LT(SecondsSince(begin), 1.0);
}

TEST(BatchPlan, NextWaitsForItsTimeout) {
  BatchPlan plan(1, 2);
  ASSERT_TRUE(plan.Next("model1@a", kNoWait));
  const auto begin = Clock::now();
  EXPECT_FALSE(plan.Next("model2@b", milliseconds(100)));
  const double waited = SecondsSince(begin);
  EXPECT_GE(waited, 0.095);
  EXPECT_LT(waited, 2.0);
}

TEST(BatchPlan, NextWakesWhenARunIsRequeued) {
  BatchPlan plan(1, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  std::optional<BatchPlan::Ticket> got;
  double waited = 0;
  std::thread waiter([&] {
    const auto begin = Clock::now();
    got = plan.Next("model2@b", milliseconds(10000));
    waited = SecondsSince(begin);
  });
  std::this_thread::sleep_for(milliseconds(100));
  plan.Retry(*t, "TRANSIENT");
  waiter.join();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->run, 0u);
  EXPECT_GE(waited, 0.05);
  EXPECT_LT(waited, 5.0);
}

TEST(BatchPlan, NextWakesWhenTheLastRunEnds) {
  BatchPlan plan(1, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  bool got = true;
  double waited = 0;
  std::thread waiter([&] {
    const auto begin = Clock::now();
    got = plan.Next("model2@b", milliseconds(10000)).has_value();
    waited = SecondsSince(begin);
  });
  std::this_thread::sleep_for(milliseconds(100));
  plan.Fail(*t, "physics fault");
  waiter.join();
  EXPECT_FALSE(got);
  EXPECT_LT(waited, 5.0);
}

TEST(BatchPlan, WaitForChangeTimesOutWithoutAnEnd) {
  BatchPlan plan(2, 2);
  const auto t = plan.Next("model1@a", kNoWait);
  ASSERT_TRUE(t);
  const auto begin = Clock::now();
  plan.WaitForChange(milliseconds(100));
  EXPECT_GE(SecondsSince(begin), 0.095);
}

TEST(BatchPlan, WaitForChangeReturnsWhenARunEnds) {
  BatchPlan plan(2, 1);
  const auto a = plan.Next("model1@a", kNoWait);
  const auto b = plan.Next("model2@b", kNoWait);
  ASSERT_TRUE(a && b);
  double waited_for_complete = 0;
  double waited_for_give_up = 0;
  std::thread waiter([&] {
    auto begin = Clock::now();
    plan.WaitForChange(milliseconds(10000));
    waited_for_complete = SecondsSince(begin);
    begin = Clock::now();
    plan.WaitForChange(milliseconds(10000));
    waited_for_give_up = SecondsSince(begin);
  });
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_TRUE(plan.Complete(*a, Result("model1@a", 1)));
  std::this_thread::sleep_for(milliseconds(150));
  plan.Retry(*b, "TRANSIENT");  // the last attempt: the run ends failed
  waiter.join();
  EXPECT_GE(waited_for_complete, 0.1);
  EXPECT_LT(waited_for_complete, 5.0);
  EXPECT_LT(waited_for_give_up, 5.0);
  EXPECT_TRUE(plan.finished());
}

// workers that pull runs until the plan is finished; some attempts are lost and retried, some
// lost ones still report, some results arrive twice
struct Worker {
  std::string model;
  unsigned seed;
  int retry_percent;
};

TEST(BatchPlan, EveryRunCompletesExactlyOnceUnderConcurrentWorkers) {
  constexpr size_t kRuns = 200;
  BatchPlan plan(kRuns, 1000);
  std::vector<std::atomic<int>> wins(kRuns);
  std::vector<std::string> winner(kRuns);  // each written by the one worker whose result won
  std::atomic<int> retries{0};
  std::atomic<int> duplicates_accepted{0};
  std::vector<std::thread> threads;
  for (unsigned w = 0; w < 4; ++w) {
    threads.emplace_back([&, w] {
      const std::string model = "model" + std::to_string(w) + "@host";
      std::mt19937 random(w + 1);
      std::uniform_int_distribution<int> percent(0, 99);
      while (!plan.finished()) {
        const auto t = plan.Next(model, milliseconds(20));
        if (!t) continue;
        if (percent(random) < 30) {
          plan.Retry(*t, model + ": TRANSIENT");
          ++retries;
          if (percent(random) < 30) std::this_thread::yield();
          if (percent(random) < 50) {
            // the lost attempt reports after all
            if (plan.Complete(*t, Result(model, t->run))) {
              ++wins[t->run];
              winner[t->run] = model;
            }
          }
          continue;
        }
        if (plan.Complete(*t, Result(model, t->run))) {
          ++wins[t->run];
          winner[t->run] = model;
        }
        if (percent(random) < 10 && plan.Complete(*t, Result(model, t->run))) ++duplicates_accepted;
      }
    });
  }
  for (auto& t : threads) t.join();

  EXPECT_TRUE(plan.finished());
  EXPECT_EQ(plan.done(), kRuns);
  EXPECT_EQ(plan.failed(), 0u);
  EXPECT_EQ(plan.running(), 0u);
  EXPECT_EQ(duplicates_accepted.load(), 0);
  EXPECT_GT(retries.load(), 0);
  size_t total_retries = 0;
  const auto outcomes = plan.outcomes();
  for (size_t run = 0; run < kRuns; ++run) {
    EXPECT_EQ(wins[run].load(), 1) << "run " << run;
    const Outcome& o = outcomes[run];
    EXPECT_EQ(o.state, State::kDone) << "run " << run;
    EXPECT_EQ(o.steps, run) << "the result of another run";
    EXPECT_EQ(o.model, winner[run]) << "run " << run;
    EXPECT_GE(o.attempts, 1) << "run " << run;
    EXPECT_LE(o.retries.size(), static_cast<size_t>(o.attempts)) << "run " << run;
    total_retries += o.retries.size();
  }
  // a retry is recorded unless a lost attempt's result ended the run first
  EXPECT_GT(total_retries, 0u);
  EXPECT_LE(total_retries, static_cast<size_t>(retries.load()));
  EXPECT_FALSE(plan.Next("late@host", kNoWait));
}

TEST(BatchPlan, EveryRunEndsExactlyOnceWhenWorkersGiveUp) {
  constexpr size_t kRuns = 200;
  BatchPlan plan(kRuns, 2);
  std::vector<std::atomic<int>> wins(kRuns);
  std::vector<std::thread> threads;
  for (unsigned w = 0; w < 4; ++w) {
    threads.emplace_back([&, w] {
      const std::string model = "model" + std::to_string(w) + "@host";
      std::mt19937 random(100 + w);
      std::uniform_int_distribution<int> percent(0, 99);
      while (!plan.finished()) {
        const auto t = plan.Next(model, milliseconds(20));
        if (!t) continue;
        const int roll = percent(random);
        if (roll < 50) {
          plan.Retry(*t, "TRANSIENT");
        } else if (roll < 60) {
          plan.Fail(*t, "physics fault");
        } else if (plan.Complete(*t, Result(model, t->run))) {
          ++wins[t->run];
        }
      }
    });
  }
  for (auto& t : threads) t.join();

  EXPECT_EQ(plan.done() + plan.failed(), kRuns);
  EXPECT_GT(plan.done(), 0u);
  EXPECT_GT(plan.failed(), 0u);
  const auto outcomes = plan.outcomes();
  size_t gave_up = 0;
  for (size_t run = 0; run < kRuns; ++run) {
    const Outcome& o = outcomes[run];
    EXPECT_EQ(wins[run].load(), o.state == State::kDone ? 1 : 0) << "run " << run;
    EXPECT_LE(o.attempts, 2) << "run " << run;
    if (o.state == State::kFailed && o.reason == "gave up after 2 attempts") {
      ++gave_up;
      EXPECT_EQ(o.retries.size(), 2u) << "run " << run;
    }
  }
  EXPECT_GT(gave_up, 0u);
}

TEST(BatchPlan, FailureOfARetriedAttemptDoesNotEndTheRun) {
  BatchPlan plan(1, 3);
  const auto first = plan.Next("model0@a", kNoWait);
  ASSERT_TRUE(first);
  plan.Retry(*first, "model0@a: no answer for 5 s");
  const auto second = plan.Next("model1@b", kNoWait);
  ASSERT_TRUE(second);
  plan.Fail(*first, "late failure from the Model given up on");
  EXPECT_FALSE(plan.finished());
  EXPECT_TRUE(plan.Complete(*second, Result("model1@b", 100)));
  const Outcome o = plan.outcomes()[0];
  EXPECT_EQ(o.state, State::kDone);
  EXPECT_EQ(o.model, "model1@b");
}

}  // namespace
}  // namespace caliper::ctl
