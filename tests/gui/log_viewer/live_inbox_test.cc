// The live inbox: records pushed while the first query is in flight, answered twice, or from a
// new session after the logger restarted are each taken exactly once, in session order; a jump
// in the pushed serials is held back until the query for the gap fills it.
#include "live_inbox.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace caliper::log_viewer {
namespace {

std::vector<LiveRecord> Serials(uint64_t first, uint64_t last) {
  std::vector<LiveRecord> out;
  for (uint64_t s = first; s <= last; ++s) {
    LiveRecord r;
    r.serial = s;
    r.record.message = "#" + std::to_string(s);
    out.push_back(r);
  }
  return out;
}

std::vector<std::string> Messages(const std::vector<logging::Record>& records) {
  std::vector<std::string> out;
  for (const auto& r : records) out.push_back(r.message);
  return out;
}

TEST(LiveInboxTest, NothingIsTakenBeforeARegistration) {
  LiveInbox inbox;
  inbox.Push(Serials(1, 3));
  EXPECT_TRUE(inbox.Take().empty());
}

TEST(LiveInboxTest, PushesDuringTheFirstQueryAreMergedWithoutRepeats) {
  LiveInbox inbox;
  inbox.BeginSync("/logs/a.log");
  EXPECT_EQ(inbox.last_serial(), 0u);
  inbox.Push(Serials(4, 6));    // stored after the listener was added...
  inbox.Synced(Serials(1, 5));  // ...and partly answered by the query too
  inbox.Push(Serials(6, 8));
  EXPECT_EQ(Messages(inbox.Take()),
            (std::vector<std::string>{"#1", "#2", "#3", "#4", "#5", "#6", "#7", "#8"}));
  EXPECT_EQ(inbox.last_serial(), 8u);
  EXPECT_TRUE(inbox.Take().empty());
}

TEST(LiveInboxTest, TheSameSessionGoesOnAfterTheLastSerialAndANewOneStartsAfresh) {
  LiveInbox inbox;
  inbox.BeginSync("/logs/a.log");
  inbox.Synced(Serials(1, 3));
  inbox.Take();
  inbox.Stop();
  inbox.Push(Serials(4, 4));  // a stale push after the logger was lost is dropped
  EXPECT_TRUE(inbox.Take().empty());
  // the logger restarted on the same session file: serials go on
  inbox.BeginSync("/logs/a.log");
  EXPECT_EQ(inbox.last_serial(), 3u);
  inbox.Synced(Serials(4, 5));
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#4", "#5"}));
  // a new session: serials start at 1 again
  inbox.Stop();
  inbox.BeginSync("/logs/b.log");
  EXPECT_EQ(inbox.last_serial(), 0u);
  inbox.Synced(Serials(1, 2));
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#1", "#2"}));
}

// the worker's part: asked by the gap callback, it queries what follows last_serial() (the
// logger answers everything it holds after that serial, newest included)
struct Worker {
  explicit Worker(LiveInbox* inbox) : inbox(inbox) {
    inbox->set_on_gap([this] { ++woken; });
  }
  // the logger holds serials `first`..`newest`
  void QueryGap(uint64_t first, uint64_t newest) {
    ASSERT_TRUE(inbox->gap_pending());
    const uint64_t after = inbox->last_serial();
    asked.push_back(after);
    inbox->GapAnswered(after, Serials(std::max(first, after + 1), newest));
  }
  LiveInbox* inbox;
  int woken = 0;
  std::vector<uint64_t> asked;
};

TEST(LiveInboxTest, APushThatSkipsSerialsIsQueriedAndTakenCompleteAndInOrder) {
  LiveInbox inbox;
  Worker worker(&inbox);
  inbox.BeginSync("/logs/a.log");
  inbox.Synced(Serials(1, 3));
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#1", "#2", "#3"}));
  EXPECT_FALSE(inbox.gap_pending());
  // the logger dropped 4..6 from the listener's queue
  inbox.Push(Serials(7, 8));
  EXPECT_EQ(worker.woken, 1) << "the gap wakes the worker";
  EXPECT_TRUE(inbox.gap_pending());
  EXPECT_TRUE(inbox.Take().empty()) << "records after a gap wait for it to be filled";
  inbox.Push(Serials(9, 9));  // still behind the same gap
  EXPECT_EQ(worker.woken, 1);
  worker.QueryGap(1, 9);
  EXPECT_EQ(worker.asked, std::vector<uint64_t>{3}) << "the query asks for what follows #3";
  EXPECT_FALSE(inbox.gap_pending());
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#4", "#5", "#6", "#7", "#8", "#9"}));
  EXPECT_EQ(inbox.last_serial(), 9u);
  EXPECT_EQ(inbox.lost(), 0u);
  // pushes go on as before, the ones the query answered too are not repeated
  inbox.Push(Serials(9, 10));
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#10"}));
}

TEST(LiveInboxTest, SerialsTheLoggerNoLongerHoldsAreSkippedAndCounted) {
  LiveInbox inbox;
  Worker worker(&inbox);
  inbox.BeginSync("/logs/a.log");
  inbox.Synced(Serials(1, 3));
  inbox.Take();
  inbox.Push(Serials(9, 10));
  worker.QueryGap(6, 11);  // 4 and 5 are gone from the logger's memory; 11 arrived meanwhile
  EXPECT_EQ(Messages(inbox.Take()),
            (std::vector<std::string>{"#6", "#7", "#8", "#9", "#10", "#11"}));
  EXPECT_EQ(inbox.lost(), 2u);
  EXPECT_FALSE(inbox.gap_pending());
  // the records of a session's start that the logger no longer holds are not lost to us
  LiveInbox late;
  late.BeginSync("/logs/a.log");
  late.Synced(Serials(50001, 50002));
  EXPECT_EQ(Messages(late.Take()), (std::vector<std::string>{"#50001", "#50002"}));
  EXPECT_EQ(late.lost(), 0u);
}

TEST(LiveInboxTest, AGapAmongThePushesOfTheFirstQueryIsQueriedToo) {
  LiveInbox inbox;
  Worker worker(&inbox);
  inbox.BeginSync("/logs/a.log");
  inbox.Push(Serials(8, 9));  // 6 and 7 dropped while the first query was in flight
  inbox.Synced(Serials(1, 5));
  EXPECT_EQ(worker.woken, 1);
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#1", "#2", "#3", "#4", "#5"}));
  worker.QueryGap(1, 9);
  EXPECT_EQ(worker.asked, std::vector<uint64_t>{5});
  EXPECT_EQ(Messages(inbox.Take()), (std::vector<std::string>{"#6", "#7", "#8", "#9"}));
}

TEST(LiveInboxTest, AnAnswerAfterStopIsIgnored) {
  // the LogLink stopped while its worker was still inside the first query
  LiveInbox inbox;
  inbox.BeginSync("/logs/a.log");
  inbox.Stop();
  inbox.Synced(Serials(1, 3));
  inbox.Push(Serials(4, 4));
  EXPECT_TRUE(inbox.Take().empty());
  EXPECT_FALSE(inbox.gap_pending());
}

}  // namespace
}  // namespace caliper::log_viewer
