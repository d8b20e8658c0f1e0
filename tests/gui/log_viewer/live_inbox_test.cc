// The live inbox: records pushed while the first query is in flight, answered twice, or from a
// new session after the logger restarted are each taken exactly once, in session order.
#include "live_inbox.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace caliper::log_viewer
