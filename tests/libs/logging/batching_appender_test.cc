#include "caliper/logging/batching_appender.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <log4cpp/Category.hh>
#include <log4cpp/Priority.hh>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "caliper/core/system.h"

namespace caliper::logging {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// What the fake sink saw; shared between the test and the sink the appender owns.
struct SinkState {
  std::mutex mutex;
  bool reachable = true;
  /// the next n Sends store the batch, then throw (a lost acknowledgement)
  int store_then_fail = 0;
  int attempts = 0;
  std::vector<std::vector<Record>> batches;  ///< every batch stored, in arrival order

  void SetReachable(bool value) {
    std::lock_guard<std::mutex> lock(mutex);
    reachable = value;
  }
  void LoseNextAcknowledgements(int n) {
    std::lock_guard<std::mutex> lock(mutex);
    store_then_fail = n;
  }
  int attempt_count() {
    std::lock_guard<std::mutex> lock(mutex);
    return attempts;
  }
  std::vector<std::vector<Record>> stored_batches() {
    std::lock_guard<std::mutex> lock(mutex);
    return batches;
  }
  /// every record stored, as (source, seq), in arrival order
  std::vector<std::pair<std::string, uint64_t>> Received() {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::pair<std::string, uint64_t>> out;
    for (const auto& batch : batches)
      for (const auto& r : batch) out.emplace_back(r.source, r.seq);
    return out;
  }
  /// the seqs of every record stored, in arrival order
  std::vector<uint64_t> Seqs() {
    std::vector<uint64_t> out;
    for (const auto& [source, seq] : Received()) out.push_back(seq);
    return out;
  }
};

// A sink that stores everything it gets (deduplicating nothing) or throws SinkUnavailable.
class FakeSink : public RecordSink {
 public:
  explicit FakeSink(std::shared_ptr<SinkState> state) : state_(std::move(state)) {}
  void Send(const std::vector<Record>& batch) override {
    std::lock_guard<std::mutex> lock(state_->mutex);
    ++state_->attempts;
    if (!state_->reachable) throw SinkUnavailable("fake sink unreachable");
    state_->batches.push_back(batch);
    if (state_->store_then_fail > 0) {
      --state_->store_then_fail;
      throw SinkUnavailable("fake sink lost the acknowledgement");
    }
  }

 private:
  std::shared_ptr<SinkState> state_;
};

/// A consumer that stores each (source, seq) once, as the logger does.
std::vector<std::pair<std::string, uint64_t>> Deduplicate(
    const std::vector<std::pair<std::string, uint64_t>>& received) {
  std::set<std::pair<std::string, uint64_t>> seen;
  std::vector<std::pair<std::string, uint64_t>> stored;
  for (const auto& key : received)
    if (seen.insert(key).second) stored.push_back(key);
  return stored;
}

std::vector<uint64_t> Range(uint64_t first, uint64_t last) {
  std::vector<uint64_t> out;
  for (uint64_t i = first; i <= last; ++i) out.push_back(i);
  return out;
}

std::vector<uint64_t> Concat(std::vector<uint64_t> a, const std::vector<uint64_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

Record MakeRecord(const std::string& message) {
  Record r;
  r.time_us = core::NowMicros();
  r.priority = kInfo;
  r.category = "caliper.test.appender";
  r.component = "test0";
  r.host = "testhost";
  r.pid = getpid();
  r.source = "testhost:" + std::to_string(getpid()) + ":1";
  r.message = message;
  return r;
}

/// The seqs of the records in a spool file, in file order.
std::vector<uint64_t> SpoolSeqs(const std::string& path) {
  std::ifstream in(path);
  std::vector<uint64_t> seqs;
  std::string line;
  while (std::getline(in, line)) {
    Record r;
    EXPECT_TRUE(ParseLine(line, &r)) << line;
    seqs.push_back(r.seq);
  }
  return seqs;
}

class BatchingAppenderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper_appender_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    options_.spool_dir = dir_ + "/spool";
    options_.spool_name = "test-" + std::to_string(getpid());
    options_.flush_interval = milliseconds(5);
    options_.retry_interval = milliseconds(20);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::unique_ptr<BatchingAppender> MakeAppender() {
    return std::make_unique<BatchingAppender>("test", std::make_unique<FakeSink>(sink_), options_);
  }

  static void AppendMessages(BatchingAppender& appender, int first, int last) {
    for (int i = first; i <= last; ++i) appender.Append(MakeRecord("message " + std::to_string(i)));
  }

  /// Waits (giving the sender time through Flush) until `done` holds; false after `timeout`.
  template <typename Pred>
  static bool Eventually(BatchingAppender& appender, Pred done, milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (!done()) {
      if (Clock::now() > deadline) return false;
      appender.Flush(milliseconds(2));
    }
    return true;
  }

  /// Writes records of a dead process to `<spool_dir>/<name>`; the last one torn when asked.
  void WriteOrphan(const std::string& name, const std::string& source, int count, bool torn) {
    fs::create_directories(options_.spool_dir);
    std::ofstream out(options_.spool_dir + "/" + name);
    out << "# spool of a process that died\n";
    for (int i = 1; i <= count; ++i) {
      Record r = MakeRecord("orphan " + std::to_string(i));
      r.source = source;
      r.seq = i;
      out << FormatLine(r) << '\n';
    }
    if (torn) {
      Record r = MakeRecord("orphan torn");
      r.source = source;
      r.seq = count + 1;
      out << FormatLine(r).substr(0, 40);  // killed in the middle of a write: no newline
    }
  }

  std::vector<std::string> SpoolDirEntries() const {
    std::vector<std::string> names;
    if (!fs::exists(options_.spool_dir)) return names;
    for (const auto& entry : fs::directory_iterator(options_.spool_dir))
      names.push_back(entry.path().filename().string());
    return names;
  }

  std::string dir_;
  AppenderOptions options_;
  std::shared_ptr<SinkState> sink_ = std::make_shared<SinkState>();
};

TEST_F(BatchingAppenderTest, DeliversRecordsInOrderNumberedFromOne) {
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 100);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Range(1, 100));
  const auto batches = sink_->stored_batches();
  ASSERT_FALSE(batches.empty());
  EXPECT_EQ(batches.front().front().message, "message 1");
  EXPECT_EQ(batches.back().back().message, "message 100");
  const auto stats = appender->stats();
  EXPECT_EQ(stats.appended, 100u);
  EXPECT_EQ(stats.sent, 100u);
  EXPECT_EQ(stats.spooled, 0u);
  EXPECT_TRUE(stats.reachable);
  EXPECT_FALSE(fs::exists(appender->spool_path()));
}

TEST_F(BatchingAppenderTest, SendsBatchesOfAtMostMaxBatch) {
  options_.max_batch = 7;
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 50);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Range(1, 50));
  for (const auto& batch : sink_->stored_batches()) EXPECT_LE(batch.size(), 7u);
}

TEST_F(BatchingAppenderTest, NamesSpoolFileAfterSpoolName) {
  auto appender = MakeAppender();
  EXPECT_EQ(appender->spool_path(),
            options_.spool_dir + "/test-" + std::to_string(getpid()) + ".spool");
  EXPECT_TRUE(fs::is_directory(options_.spool_dir));  // created by the appender
}

TEST_F(BatchingAppenderTest, AnEmptySpoolFolderGoesWithTheAppenderAFullOneStays) {
  {
    auto appender = MakeAppender();
    AppendMessages(*appender, 1, 3);
    ASSERT_TRUE(appender->Flush(milliseconds(1000)));  // delivered: nothing waits
  }
  EXPECT_FALSE(fs::exists(options_.spool_dir)) << "an empty spool folder was left behind";
  sink_->SetReachable(false);
  {
    auto appender = MakeAppender();
    AppendMessages(*appender, 4, 6);
    appender->Stop(milliseconds(50));
  }
  // what waits for its session's logger stays, and so does its folder
  EXPECT_EQ(SpoolSeqs(options_.spool_dir + "/test-" + std::to_string(getpid()) + ".spool"),
            Range(1, 3));  // the second appender's three records (its own numbering)
}

TEST_F(BatchingAppenderTest, SpoolsWhileSinkIsUnreachable) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 20);

  EXPECT_FALSE(appender->Flush(milliseconds(50)));  // cannot reach the sink
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 20; }, milliseconds(1000)));
  const auto stats = appender->stats();
  EXPECT_FALSE(stats.reachable);
  EXPECT_EQ(stats.sent, 0u);
  EXPECT_GE(sink_->attempt_count(), 1);
  EXPECT_TRUE(sink_->Seqs().empty());
  ASSERT_TRUE(fs::exists(appender->spool_path()));
  EXPECT_EQ(SpoolSeqs(appender->spool_path()), Range(1, 20));
}

TEST_F(BatchingAppenderTest, DropsRecordsBeyondTheSpoolBoundAndSaysHowManyOnceDelivered) {
  sink_->SetReachable(false);
  options_.max_spool_bytes = 1000;  // a few records' lines
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 200);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled + appender->stats().dropped == 200; },
      milliseconds(2000)));
  const auto kept = appender->stats().spooled;
  EXPECT_GT(kept, 0u);
  EXPECT_LE(fs::file_size(appender->spool_path()), 1000u);  // the bound holds
  EXPECT_EQ(appender->stats().dropped, 200 - kept);

  // the sink is back: what was kept arrives in order, then one warning with the count
  sink_->SetReachable(true);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return sink_->Seqs().size() == kept + 1; }, milliseconds(2000)))
      << sink_->Seqs().size() << " of " << kept + 1 << ", dropped " << appender->stats().dropped;
  const auto seqs = sink_->Seqs();
  EXPECT_EQ(std::vector<uint64_t>(seqs.begin(), seqs.end() - 1), Range(1, static_cast<int>(kept)));
  EXPECT_EQ(seqs.back(), 201u);  // numbered after the dropped ones: the gap is theirs
  const Record warning = sink_->stored_batches().back().back();
  EXPECT_EQ(warning.priority, kWarn);
  EXPECT_EQ(warning.message.rfind(std::to_string(200 - kept) + " log records of this process were "
                                  "dropped", 0),
            0u)
      << warning.message;
  EXPECT_FALSE(fs::exists(appender->spool_path()));
}

TEST_F(BatchingAppenderTest, RetriesUnreachableSinkPeriodically) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 3);
  // retry_interval is 20 ms: several attempts within a second, not one per flush interval
  ASSERT_TRUE(Eventually(
      *appender, [&] { return sink_->attempt_count() >= 3; }, milliseconds(1000)));
  const int before = sink_->attempt_count();
  const auto begin = Clock::now();
  appender->Flush(milliseconds(100));
  const int during = sink_->attempt_count() - before;
  const auto elapsed = std::chrono::duration_cast<milliseconds>(Clock::now() - begin);
  EXPECT_GE(during, 1);
  EXPECT_LE(during, elapsed.count() / 20 + 2);
}

TEST_F(BatchingAppenderTest, ReplaysSpoolInOrderOnceSinkIsBack) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 20);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 20; }, milliseconds(1000)));

  sink_->SetReachable(true);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Range(1, 20));  // nothing lost, nothing duplicated
  const auto stats = appender->stats();
  EXPECT_TRUE(stats.reachable);
  EXPECT_EQ(stats.sent, 20u);
  EXPECT_FALSE(fs::exists(appender->spool_path()));  // replayed spool is removed
}

TEST_F(BatchingAppenderTest, ReplaysInBatchesOfAtMostMaxBatch) {
  options_.max_batch = 4;
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 18);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 18; }, milliseconds(1000)));

  sink_->SetReachable(true);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));
  EXPECT_EQ(sink_->Seqs(), Range(1, 18));
  EXPECT_GE(sink_->stored_batches().size(), 5u);
  for (const auto& batch : sink_->stored_batches()) EXPECT_LE(batch.size(), 4u);
}

TEST_F(BatchingAppenderTest, KeepsNewRecordsBehindTheBacklog) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 10);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 10; }, milliseconds(1000)));
  AppendMessages(*appender, 11, 20);  // still unreachable
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 20; }, milliseconds(1000)));

  sink_->SetReachable(true);
  AppendMessages(*appender, 21, 30);  // may arrive before the backlog is replayed
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));
  AppendMessages(*appender, 31, 40);  // straight through again
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Range(1, 40));
  EXPECT_EQ(appender->stats().sent, 40u);
}

TEST_F(BatchingAppenderTest, ResendsBatchWhoseAcknowledgementWasLost) {
  sink_->LoseNextAcknowledgements(1);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 10);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  // the first batch was stored but reported as failed: it is sent again
  const auto batches = sink_->stored_batches();
  ASSERT_GE(batches.size(), 2u);
  std::vector<uint64_t> first;
  for (const auto& r : batches[0]) first.push_back(r.seq);
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first, Range(1, first.size()));
  std::vector<uint64_t> rest;
  for (size_t b = 1; b < batches.size(); ++b)
    for (const auto& r : batches[b]) rest.push_back(r.seq);
  EXPECT_EQ(rest, Range(1, 10));
  EXPECT_EQ(sink_->Seqs().size(), 10 + first.size());

  // a consumer that drops (source, seq) duplicates stores each record once, in order
  const auto stored = Deduplicate(sink_->Received());
  ASSERT_EQ(stored.size(), 10u);
  for (size_t i = 0; i < stored.size(); ++i) EXPECT_EQ(stored[i].second, i + 1);
  EXPECT_TRUE(appender->stats().reachable);
}

TEST_F(BatchingAppenderTest, ResendsReplayedBatchWhoseAcknowledgementWasLost) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 10);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 10; }, milliseconds(1000)));

  sink_->LoseNextAcknowledgements(1);
  sink_->SetReachable(true);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Concat(Range(1, 10), Range(1, 10)));
  EXPECT_EQ(Deduplicate(sink_->Received()).size(), 10u);
  EXPECT_FALSE(fs::exists(appender->spool_path()));
}

TEST_F(BatchingAppenderTest, ReplaysOrphanSpoolOfDeadProcessBeforeNewRecords) {
  const long dead_pid = 999999;
  ASSERT_FALSE(core::ProcessAlive(dead_pid)) << "pick another pid for this test";
  const std::string dead_source = "deadhost:999999:1";
  WriteOrphan("x-999999.spool", dead_source, 5, /*torn=*/true);

  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 3);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  const std::string own_source = MakeRecord("").source;
  const std::vector<std::pair<std::string, uint64_t>> expected = {
      {dead_source, 1}, {dead_source, 2}, {dead_source, 3}, {dead_source, 4},
      {dead_source, 5}, {own_source, 1},  {own_source, 2},  {own_source, 3}};
  EXPECT_EQ(sink_->Received(), expected);  // the torn sixth line is dropped
  EXPECT_EQ(sink_->stored_batches().front().front().message, "orphan 1");
  EXPECT_EQ(appender->stats().sent, 8u);
  EXPECT_TRUE(SpoolDirEntries().empty()) << SpoolDirEntries().front();  // claimed file removed
}

TEST_F(BatchingAppenderTest, KeepsOrphanWhileSinkIsUnreachable) {
  WriteOrphan("x-999999.spool", "deadhost:999999:1", 4, /*torn=*/false);
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 2);
  EXPECT_FALSE(appender->Flush(milliseconds(60)));

  sink_->SetReachable(true);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));
  EXPECT_EQ(sink_->Seqs(), Concat(Range(1, 4), Range(1, 2)));
}

TEST_F(BatchingAppenderTest, LeavesSpoolOfLiveProcessAlone) {
  const std::string live = "other-" + std::to_string(getpid()) + ".spool";
  WriteOrphan(live, "livehost:1:1", 2, /*torn=*/false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 2);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Range(1, 2));
  EXPECT_TRUE(fs::exists(options_.spool_dir + "/" + live));
}

TEST_F(BatchingAppenderTest, DoesNotReplayOrphansWhenTold) {
  options_.replay_orphans = false;
  WriteOrphan("x-999999.spool", "deadhost:999999:1", 2, /*torn=*/false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 2);
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  EXPECT_EQ(sink_->Seqs(), Range(1, 2));
  EXPECT_TRUE(fs::exists(options_.spool_dir + "/x-999999.spool"));
}

TEST_F(BatchingAppenderTest, StopDeliversWhatIsQueued) {
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 25);
  appender->Stop(milliseconds(1000));

  EXPECT_EQ(sink_->Seqs(), Range(1, 25));
  EXPECT_FALSE(fs::exists(appender->spool_path()));
}

TEST_F(BatchingAppenderTest, StopWithUnreachableSinkLeavesRecordsInSpool) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 10);
  const auto begin = Clock::now();
  appender->Stop(milliseconds(100));
  EXPECT_LT(Clock::now() - begin, milliseconds(1000));

  ASSERT_TRUE(fs::exists(appender->spool_path()));
  EXPECT_EQ(SpoolSeqs(appender->spool_path()), Range(1, 10));
  EXPECT_EQ(appender->stats().spooled, 10u);
  EXPECT_EQ(appender->stats().sent, 0u);

  // after Stop, records go straight to the spool
  AppendMessages(*appender, 11, 12);
  EXPECT_EQ(SpoolSeqs(appender->spool_path()), Range(1, 12));
  EXPECT_FALSE(appender->Flush(milliseconds(10)));
}

TEST_F(BatchingAppenderTest, StopWithBacklogAndUnreachableSinkKeepsEverything) {
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 10);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 10; }, milliseconds(1000)));
  AppendMessages(*appender, 11, 15);
  appender->Stop(milliseconds(50));

  EXPECT_EQ(SpoolSeqs(appender->spool_path()), Range(1, 15));  // each once, in order
}

TEST_F(BatchingAppenderTest, StopReplaysBacklogWhenSinkIsBack) {
  options_.retry_interval = milliseconds(10000);  // no retry before Stop
  sink_->SetReachable(false);
  auto appender = MakeAppender();
  AppendMessages(*appender, 1, 10);
  ASSERT_TRUE(Eventually(
      *appender, [&] { return appender->stats().spooled == 10; }, milliseconds(1000)));
  sink_->SetReachable(true);
  appender->Stop(milliseconds(1000));

  EXPECT_EQ(sink_->Seqs(), Range(1, 10));
  EXPECT_FALSE(fs::exists(appender->spool_path()));
}

TEST_F(BatchingAppenderTest, SpoolLeftByStopIsReplayedByTheNextProcess) {
  sink_->SetReachable(false);
  std::string spool;
  {
    auto appender = MakeAppender();
    AppendMessages(*appender, 1, 6);
    appender->Stop(milliseconds(50));
    spool = appender->spool_path();
  }
  ASSERT_TRUE(fs::exists(spool));
  // as if this process had died: the file now carries the pid of a dead process
  fs::rename(spool, options_.spool_dir + "/test-999999.spool");

  auto next_sink = std::make_shared<SinkState>();
  BatchingAppender next("next", std::make_unique<FakeSink>(next_sink), options_);
  ASSERT_TRUE(next.Flush(milliseconds(1000)));
  EXPECT_EQ(next_sink->Seqs(), Range(1, 6));
  EXPECT_TRUE(SpoolDirEntries().empty());
}

TEST_F(BatchingAppenderTest, TurnsLog4cppEventsIntoRecords) {
  auto appender = MakeAppender();
  log4cpp::Category& category = log4cpp::Category::getInstance("caliper.test.appender_events");
  category.setPriority(log4cpp::Priority::DEBUG);
  category.setAdditivity(false);
  category.addAppender(*appender);  // by reference: the category does not own it
  const int64_t before = core::NowMicros();
  category.warn("joint %d above limit", 3);
  category.debug("second");
  category.removeAppender(appender.get());
  ASSERT_TRUE(appender->Flush(milliseconds(1000)));

  const auto batches = sink_->stored_batches();
  std::vector<Record> records;
  for (const auto& b : batches) records.insert(records.end(), b.begin(), b.end());
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].category, "caliper.test.appender_events");
  EXPECT_EQ(records[0].priority, kWarn);
  EXPECT_EQ(records[0].message, "joint 3 above limit");
  EXPECT_EQ(records[0].seq, 1u);
  EXPECT_GE(records[0].time_us, before - 1000);
  EXPECT_LE(records[0].time_us, core::NowMicros());
  EXPECT_EQ(records[1].priority, kDebug);
  EXPECT_EQ(records[1].seq, 2u);
}

}  // namespace
}  // namespace caliper::logging
