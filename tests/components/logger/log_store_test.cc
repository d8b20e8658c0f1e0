#include "log_store.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <memory>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/core/system.h"
#include "caliper/logging/message_pattern.h"

namespace caliper::logger {
namespace {

namespace fs = std::filesystem;
using logging::Record;

Record MakeRecord(const std::string& source, uint64_t seq, const std::string& message = "") {
  Record r;
  r.time_us = 1700000000000000 + static_cast<int64_t>(seq);
  r.priority = logging::kInfo;
  r.category = "caliper.test.store";
  r.component = "test0";
  r.host = "host";
  r.pid = 1;
  r.source = source;
  r.seq = seq;
  r.message = message.empty() ? source + " #" + std::to_string(seq) : message;
  return r;
}

std::vector<uint64_t> Serials(const std::vector<StoredRecord>& stored) {
  std::vector<uint64_t> out;
  for (const auto& s : stored) out.push_back(s.serial);
  return out;
}

std::vector<std::string> Messages(const std::vector<StoredRecord>& stored) {
  std::vector<std::string> out;
  for (const auto& s : stored) out.push_back(s.record.message);
  return out;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The records in a session file; every line must be a comment or a record.
std::vector<Record> FileRecords(const std::string& path) {
  std::ifstream in(path);
  std::vector<Record> records;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') continue;
    Record r;
    EXPECT_TRUE(logging::ParseLine(line, &r)) << "not a record: " << line;
    records.push_back(r);
  }
  return records;
}

/// Limits the size of files this process writes (as a full disk would) while it exists.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_handler_ = signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead
    EXPECT_EQ(getrlimit(RLIMIT_FSIZE, &old_), 0);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  sighandler_t old_handler_;
};

class LogStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper_log_store_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string dir_;
};

TEST(SessionFileNameTest, StampsLocalStartTimeAndSession) {
  const char* old_tz = getenv("TZ");
  const std::string saved = old_tz ? old_tz : "";
  setenv("TZ", "UTC", 1);
  tzset();
  const std::string name = SessionFileName("run7", 1700000000123456);  // 2023-11-14 22:13:20 UTC
  if (old_tz) {
    setenv("TZ", saved.c_str(), 1);
  } else {
    unsetenv("TZ");
  }
  tzset();
  EXPECT_EQ(name, "caliper-20231114-221320-run7.log");
}

TEST_F(LogStoreTest, CreatesSessionFileNamedForStartTimeAndSession) {
  const std::string earliest = SessionFileName("s1", core::NowMicros());
  LogStore store(dir_ + "/logs", "s1", 100);
  const std::string latest = SessionFileName("s1", core::NowMicros());

  const std::string name = fs::path(store.path()).filename().string();
  EXPECT_TRUE(std::regex_match(name, std::regex(R"(caliper-\d{8}-\d{6}-s1\.log)"))) << name;
  EXPECT_GE(name, earliest);
  EXPECT_LE(name, latest);
  EXPECT_EQ(fs::path(store.path()).parent_path(), fs::path(dir_ + "/logs"));
  ASSERT_TRUE(fs::exists(store.path()));
  EXPECT_EQ(ReadFile(store.path()).rfind("# caliper session log; session s1; started ", 0), 0u);
  EXPECT_EQ(store.size(), 0u);
  EXPECT_TRUE(FileRecords(store.path()).empty());
}

TEST_F(LogStoreTest, ThrowsWhenDirectoryCannotBeCreated) {
  std::ofstream(dir_ + "/file") << "not a directory";
  EXPECT_THROW(LogStore(dir_ + "/file/logs", "s1", 100), std::runtime_error);
}

TEST_F(LogStoreTest, StoresRecordsWithIncreasingSerials) {
  LogStore store(dir_, "s1", 100);
  const auto stored = store.Submit({MakeRecord("a", 1), MakeRecord("a", 2), MakeRecord("b", 1)});
  EXPECT_EQ(Serials(stored), (std::vector<uint64_t>{1, 2, 3}));
  EXPECT_EQ(Messages(stored), (std::vector<std::string>{"a #1", "a #2", "b #1"}));
  EXPECT_EQ(store.size(), 3u);

  const auto records = FileRecords(store.path());
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[2].source, "b");
  EXPECT_EQ(records[2].message, "b #1");
}

TEST_F(LogStoreTest, SkipsDuplicatesOfSourceAndSeq) {
  LogStore store(dir_, "s1", 100);
  store.Submit({MakeRecord("a", 1), MakeRecord("a", 2), MakeRecord("a", 3)});

  // a batch retried after a lost acknowledgement, with one new record of each source
  const auto stored = store.Submit(
      {MakeRecord("a", 2), MakeRecord("a", 3), MakeRecord("a", 4), MakeRecord("b", 1)});
  EXPECT_EQ(Serials(stored), (std::vector<uint64_t>{4, 5}));
  EXPECT_EQ(Messages(stored), (std::vector<std::string>{"a #4", "b #1"}));

  EXPECT_TRUE(store.Submit({MakeRecord("a", 4), MakeRecord("b", 1)}).empty());
  EXPECT_EQ(store.size(), 5u);
  EXPECT_EQ(FileRecords(store.path()).size(), 5u);
  EXPECT_EQ(Serials(store.Query({})), (std::vector<uint64_t>{1, 2, 3, 4, 5}));
}

TEST_F(LogStoreTest, SkipsDuplicatesWithinOneBatch) {
  LogStore store(dir_, "s1", 100);
  const auto stored = store.Submit({MakeRecord("a", 1), MakeRecord("a", 1), MakeRecord("a", 2)});
  EXPECT_EQ(Messages(stored), (std::vector<std::string>{"a #1", "a #2"}));
}

TEST_F(LogStoreTest, MemoryKeepsTheNewestWithinItsByteBound) {
  // 1 MiB for queries: about 64 messages of 16 KiB, however many records are allowed; the file
  // keeps them all
  LogStore store(dir_, "s1", 100000, size_t{1} << 20);
  for (uint64_t seq = 1; seq <= 1000; ++seq)
    store.Submit({MakeRecord("big", seq, std::to_string(seq) + std::string(16000, 'x'))});
  QueryFilter all;
  all.limit = 10000;
  const auto kept = store.Query(all);
  EXPECT_LT(kept.size(), 70u);
  EXPECT_GT(kept.size(), 50u);
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.back().record.seq, 1000u);  // the newest stay
  EXPECT_EQ(store.size(), 1000u);
}

TEST_F(LogStoreTest, StoresUnnumberedRecordsEveryTime) {
  LogStore store(dir_, "s1", 100);
  EXPECT_EQ(store.Submit({MakeRecord("a", 0)}).size(), 1u);
  EXPECT_EQ(store.Submit({MakeRecord("a", 0)}).size(), 1u);
  EXPECT_EQ(store.Submit({MakeRecord("a", 1)}).size(), 1u);  // seq 0 does not count as seen
  EXPECT_EQ(store.size(), 3u);
}

TEST_F(LogStoreTest, SeparatesSessions) {
  LogStore one(dir_, "one", 100);
  LogStore two(dir_, "two", 100);
  EXPECT_NE(one.path(), two.path());
  one.Submit({MakeRecord("a", 1)});
  EXPECT_EQ(two.Submit({MakeRecord("a", 1)}).size(), 1u);  // another session's duplicate is not
}

TEST_F(LogStoreTest, RestartReusesFileAndRecoversSeqsAndSerials) {
  std::string path;
  {
    LogStore store(dir_, "s1", 100);
    store.Submit({MakeRecord("a", 1), MakeRecord("a", 2), MakeRecord("b", 1)});
    store.Submit({MakeRecord("a", 3)});
    path = store.path();
  }
  LogStore store(dir_, "s1", 100);
  EXPECT_EQ(store.path(), path);
  EXPECT_EQ(store.size(), 4u);
  EXPECT_EQ(Messages(store.Query({})), (std::vector<std::string>{"a #1", "a #2", "b #1", "a #3"}));

  // what the previous run stored is still recognised
  const auto stored = store.Submit({MakeRecord("a", 2), MakeRecord("a", 3), MakeRecord("b", 1),
                                    MakeRecord("a", 4), MakeRecord("b", 2)});
  EXPECT_EQ(Messages(stored), (std::vector<std::string>{"a #4", "b #2"}));
  EXPECT_EQ(Serials(stored), (std::vector<uint64_t>{5, 6}));

  const std::string text = ReadFile(path);
  size_t headers = 0;
  for (size_t at = text.find("# caliper session log"); at != std::string::npos;
       at = text.find("# caliper session log", at + 1))
    ++headers;
  EXPECT_EQ(headers, 1u);
  EXPECT_EQ(FileRecords(path).size(), 6u);
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir_)) files.push_back(entry.path().string());
  EXPECT_EQ(files, std::vector<std::string>{path});  // still one file
}

TEST_F(LogStoreTest, RestartRecoversRecordTimesAndFields) {
  Record r = MakeRecord("a", 1, "tab\there, newline\nthere");
  r.priority = logging::kError;
  r.time_us = 1700000000654321;
  { LogStore(dir_, "s1", 100).Submit({r}); }
  LogStore store(dir_, "s1", 100);
  const auto all = store.Query({});
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0].record, r) << "every field read back from the file";
  EXPECT_EQ(all[0].serial, 1u);
}

TEST_F(LogStoreTest, CutsOffTornLastLineOnRestart) {
  std::string path;
  uint64_t good_size = 0;
  {
    LogStore store(dir_, "s1", 100);
    store.Submit({MakeRecord("a", 1), MakeRecord("a", 2)});
    path = store.path();
  }
  good_size = fs::file_size(path);
  {
    // a logger killed in the middle of writing a record (all fields, but no newline)
    std::ofstream out(path, std::ios::app | std::ios::binary);
    out << logging::FormatLine(MakeRecord("a", 3, "torn"));
  }

  LogStore store(dir_, "s1", 100);
  EXPECT_EQ(fs::file_size(path), good_size);
  EXPECT_EQ(store.size(), 2u);
  EXPECT_EQ(ReadFile(path).find("torn"), std::string::npos);

  // the torn record was never stored: its resend is taken, on a line of its own
  const auto stored = store.Submit({MakeRecord("a", 3, "resent")});
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_EQ(stored[0].serial, 3u);
  const auto records = FileRecords(path);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[2].message, "resent");
}

TEST_F(LogStoreTest, CutsOffTornPartialFieldsOnRestart) {
  std::string path;
  {
    LogStore store(dir_, "s1", 100);
    store.Submit({MakeRecord("a", 1)});
    path = store.path();
  }
  const auto good_size = fs::file_size(path);
  { std::ofstream(path, std::ios::app | std::ios::binary) << "2024-01-01T00:00:00.0000"; }

  LogStore store(dir_, "s1", 100);
  EXPECT_EQ(fs::file_size(path), good_size);
  store.Submit({MakeRecord("a", 2)});
  EXPECT_EQ(FileRecords(path).size(), 2u);
}

TEST_F(LogStoreTest, FailedWriteStoresNothingSoThatTheRetryIsTaken) {
  LogStore store(dir_, "s1", 100);
  store.Submit({MakeRecord("a", 1)});
  const auto good_size = fs::file_size(store.path());
  {
    FileSizeLimit disk_full(good_size + 10);  // room for a fragment of the next line only
    try {
      store.Submit({MakeRecord("a", 2), MakeRecord("b", 1)});
      ADD_FAILURE() << "a write past the file size limit succeeded";
    } catch (const std::runtime_error& e) {
      // the system's reason is named (EFBIG here; ENOSPC on a full disk)
      EXPECT_EQ(std::string(e.what()),
                "cannot write session log " + store.path() + ": " + std::strerror(EFBIG));
    }
  }
  EXPECT_EQ(fs::file_size(store.path()), good_size);  // no fragment left in the file
  EXPECT_EQ(store.size(), 1u);
  EXPECT_EQ(Serials(store.Query({})), (std::vector<uint64_t>{1}));

  // the sender retries the batch once the disk has room again: nothing may be lost
  const auto stored = store.Submit({MakeRecord("a", 2), MakeRecord("b", 1)});
  EXPECT_EQ(Serials(stored), (std::vector<uint64_t>{2, 3}));
  EXPECT_EQ(Messages(store.Query({})), (std::vector<std::string>{"a #1", "a #2", "b #1"}));
  const auto records = FileRecords(store.path());
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[1].message, "a #2");
  EXPECT_EQ(records[2].message, "b #1");
  EXPECT_TRUE(store.Submit({MakeRecord("a", 2)}).empty());  // and stored once
}

TEST_F(LogStoreTest, KeepsOnlyTheNewestRecordsInMemory) {
  {
    LogStore store(dir_, "s1", 3);
    for (uint64_t i = 1; i <= 5; ++i) store.Submit({MakeRecord("a", i)});
    EXPECT_EQ(store.size(), 5u);
    EXPECT_EQ(Serials(store.Query({})), (std::vector<uint64_t>{3, 4, 5}));
  }
  LogStore store(dir_, "s1", 3);
  EXPECT_EQ(store.size(), 5u);
  EXPECT_EQ(Serials(store.Query({})), (std::vector<uint64_t>{3, 4, 5}));
  EXPECT_TRUE(store.Submit({MakeRecord("a", 1)}).empty());  // dedup does not depend on memory
}

class LogStoreQueryTest : public LogStoreTest {
 protected:
  void SetUp() override {
    LogStoreTest::SetUp();
    store_ = std::make_unique<LogStore>(dir_, "q", 100);
    auto make = [](uint64_t seq, int64_t time_us, int priority, const std::string& category,
                   const std::string& component, const std::string& message) {
      Record r = MakeRecord("src", seq, message);
      r.time_us = time_us;
      r.priority = priority;
      r.category = category;
      r.component = component;
      return r;
    };
    store_->Submit({
        make(1, 1000, logging::kInfo, "caliper.model.physics", "model0", "joint 1 ok"),
        make(2, 2000, logging::kWarn, "caliper.model.io", "model1", "joint 2 above limit"),
        make(3, 3000, logging::kError, "caliper.sample.main", "sample0", "cannot open port 7"),
        make(4, 4000, logging::kDebug, "caliper.model.physics", "model0", "step 4"),
        make(5, 5000, logging::kFatal, "caliper.modelx.a", "model0", "Joint 5 broken"),
    });
  }

  std::vector<uint64_t> Query(const QueryFilter& filter) const {
    return Serials(store_->Query(filter));
  }

  std::unique_ptr<LogStore> store_;
};

using Serial = std::vector<uint64_t>;

TEST_F(LogStoreQueryTest, ReturnsEverythingOldestFirstByDefault) {
  EXPECT_EQ(Query({}), (Serial{1, 2, 3, 4, 5}));
}

TEST_F(LogStoreQueryTest, FiltersByMaxPriority) {
  QueryFilter f;
  f.max_priority = logging::kWarn;
  EXPECT_EQ(Query(f), (Serial{2, 3, 5}));
  f.max_priority = logging::kFatal;
  EXPECT_EQ(Query(f), (Serial{5}));
  f.max_priority = logging::kInfo;
  EXPECT_EQ(Query(f), (Serial{1, 2, 3, 5}));
}

TEST_F(LogStoreQueryTest, FiltersByCategoryPrefix) {
  QueryFilter f;
  f.category_prefix = "caliper.model.";
  EXPECT_EQ(Query(f), (Serial{1, 2, 4}));
  f.category_prefix = "caliper.model";
  EXPECT_EQ(Query(f), (Serial{1, 2, 4, 5}));
  f.category_prefix = "model";  // a prefix, not a substring
  EXPECT_EQ(Query(f), Serial{});
}

TEST_F(LogStoreQueryTest, FiltersByExactComponent) {
  QueryFilter f;
  f.component = "model0";
  EXPECT_EQ(Query(f), (Serial{1, 4, 5}));
  f.component = "model";
  EXPECT_EQ(Query(f), Serial{});
}

TEST_F(LogStoreQueryTest, FiltersByRegexOnMessage) {
  QueryFilter f;
  f.regex = "joint [0-9]";
  EXPECT_EQ(Query(f), (Serial{1, 2}));  // case-sensitive
  f.regex = "^step";
  EXPECT_EQ(Query(f), (Serial{4}));
  f.regex = R"(port \d+$)";
  EXPECT_EQ(Query(f), (Serial{3}));
  f.regex = "(?:J|j)oint";
  EXPECT_EQ(Query(f), (Serial{1, 2, 5}));
}

/// The message of the PatternError that `store.Query(filter)` throws, or "" when it answers.
std::string QueryError(const LogStore& store, const QueryFilter& filter) {
  try {
    store.Query(filter);
  } catch (const logging::PatternError& e) {
    return e.what();
  }
  return "";
}

TEST_F(LogStoreQueryTest, RefusesBadRegexWithRe2sReason) {
  QueryFilter f;
  f.regex = "joint (";
  EXPECT_EQ(QueryError(*store_, f), "bad regular expression 'joint (': missing ): joint (");
  f.regex = "[";
  EXPECT_EQ(QueryError(*store_, f), "bad regular expression '[': missing ]: [");
  // ECMAScript's lookahead is not RE2 syntax
  f.regex = "joint(?= 2)";
  EXPECT_EQ(QueryError(*store_, f),
            "bad regular expression 'joint(?= 2)': invalid perl operator: (?=");
}

TEST_F(LogStoreQueryTest, RefusesTooLongRegex) {
  QueryFilter f;
  f.regex = std::string(logging::kMaxPatternBytes, 'j');
  EXPECT_EQ(QueryError(*store_, f), "");
  f.regex += "j";
  EXPECT_EQ(QueryError(*store_, f),
            "regular expression too long: " + std::to_string(logging::kMaxPatternBytes + 1) +
                " bytes, at most " + std::to_string(logging::kMaxPatternBytes));
}

TEST_F(LogStoreQueryTest, FiltersByInclusiveTimeRange) {
  QueryFilter f;
  f.from_time_us = 2000;
  f.to_time_us = 4000;
  EXPECT_EQ(Query(f), (Serial{2, 3, 4}));
  f.to_time_us = 0;  // no upper bound
  f.from_time_us = 4000;
  EXPECT_EQ(Query(f), (Serial{4, 5}));
  f.from_time_us = 0;  // no lower bound
  f.to_time_us = 1500;
  EXPECT_EQ(Query(f), (Serial{1}));
}

TEST_F(LogStoreQueryTest, FiltersByAfterSerial) {
  QueryFilter f;
  f.after_serial = 3;
  EXPECT_EQ(Query(f), (Serial{4, 5}));
  f.after_serial = 5;
  EXPECT_EQ(Query(f), Serial{});
  store_->Submit({MakeRecord("src", 6)});
  EXPECT_EQ(Query(f), (Serial{6}));  // what a follower polls for
}

TEST_F(LogStoreQueryTest, LimitKeepsTheNewestMatches) {
  QueryFilter f;
  f.limit = 2;
  EXPECT_EQ(Query(f), (Serial{4, 5}));
  f.limit = 10;
  EXPECT_EQ(Query(f), (Serial{1, 2, 3, 4, 5}));
  f.limit = 2;
  f.max_priority = logging::kWarn;  // newest two of the matches, not of everything
  EXPECT_EQ(Query(f), (Serial{3, 5}));
}

TEST_F(LogStoreQueryTest, CombinesFilters) {
  QueryFilter f;
  f.component = "model0";
  f.max_priority = logging::kInfo;
  f.after_serial = 1;
  EXPECT_EQ(Query(f), (Serial{5}));
  f.after_serial = 0;
  f.regex = "joint";
  EXPECT_EQ(Query(f), (Serial{1}));
}

// ------------------------------------------------------------------------ hostile clients

/// `letters` characters alternating a and b.
std::string Ab(size_t letters) {
  std::string text;
  for (size_t i = 0; i < letters; ++i) text += i % 2 == 0 ? 'a' : 'b';
  return text;
}

TEST_F(LogStoreTest, AlternationOverTwentyKilobyteMessageAnswersNormally) {
  // std::regex recursed once per character here and overflowed the stack: the logger died
  LogStore store(dir_, "s1", 100);
  store.Submit({MakeRecord("a", 1, Ab(kMaxMessageBytes)),  // kept whole, no `c` in it
                MakeRecord("a", 2, Ab(20 * 1024))});       // kept cut: its marker has a `c`
  QueryFilter f;
  f.regex = "(a|b)*c";
  EXPECT_EQ(Serials(store.Query(f)), (std::vector<uint64_t>{2}));
  f.regex = "^(a|b)*$";
  EXPECT_EQ(Serials(store.Query(f)), (std::vector<uint64_t>{1}));
  // and the store goes on
  EXPECT_EQ(store.Submit({MakeRecord("a", 3, "after")}).size(), 1u);
  f.regex = "^after$";
  EXPECT_EQ(Serials(store.Query(f)), (std::vector<uint64_t>{3}));
}

TEST_F(LogStoreTest, NestedQuantifiersReturnWithoutBacktracking) {
  // exponential backtracking with std::regex: more than 30 s for 20 letters
  LogStore store(dir_, "s1", 100);
  store.Submit({MakeRecord("a", 1, std::string(20, 'a')), MakeRecord("a", 2, "aaab")});
  QueryFilter f;
  f.regex = "(a*)*b";
  EXPECT_EQ(Serials(store.Query(f)), (std::vector<uint64_t>{2}));
}

TEST_F(LogStoreTest, SubmitCompletesWhileAQueryMatches) {
  LogStore store(dir_, "s1", 100);
  store.Submit({MakeRecord("a", 1, std::string(20, 'a'))});
  std::future<size_t> submitted;
  bool done_during_match = false;
  // runs inside Query, after the candidates are picked and before the expression runs
  store.set_before_match([&] {
    submitted =
        std::async(std::launch::async, [&] { return store.Submit({MakeRecord("b", 1)}).size(); });
    done_during_match = submitted.wait_for(std::chrono::seconds(20)) == std::future_status::ready;
  });
  QueryFilter f;
  f.regex = "(a*)*b";
  EXPECT_TRUE(store.Query(f).empty()) << "the record submitted meanwhile is not a candidate";
  EXPECT_TRUE(done_during_match) << "the submit waited for the query's lock";
  EXPECT_EQ(submitted.get(), 1u);
  store.set_before_match(nullptr);
  EXPECT_EQ(Messages(store.Query({})), (std::vector<std::string>{std::string(20, 'a'), "b #1"}));
}

TEST_F(LogStoreTest, QueriesAndSubmitsFromSeveralThreads) {
  LogStore store(dir_, "s1", 5000);
  std::vector<Record> batch;
  for (uint64_t i = 1; i <= 1000; ++i) batch.push_back(MakeRecord("a", i, std::string(20, 'a')));
  store.Submit(batch);
  std::atomic<bool> submitting{true};
  auto queries = std::async(std::launch::async, [&] {
    QueryFilter f;
    f.regex = "(a*)*q";
    size_t runs = 0;
    // bounded: at least one, then until the submits are done, at most 10,000
    do {
      EXPECT_TRUE(store.Query(f).empty());
    } while (++runs < 10000 && submitting);
    return runs;
  });
  auto submits = std::async(std::launch::async, [&] {
    size_t stored = 0;
    for (uint64_t i = 1; i <= 200; ++i)
      stored += store.Submit({MakeRecord("c", i, "later")}).size();
    submitting = false;
    return stored;
  });
  ASSERT_EQ(submits.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  ASSERT_EQ(queries.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  EXPECT_EQ(submits.get(), 200u);
  EXPECT_GE(queries.get(), 1u);
  EXPECT_EQ(store.size(), 1200u);
}

TEST_F(LogStoreTest, KeepsTooLongMessageTruncatedWithMarker) {
  const std::string original = Ab(100 * 1024);
  std::string path, kept;
  {
    LogStore store(dir_, "s1", 100);
    const auto stored = store.Submit({MakeRecord("a", 1, original)});
    ASSERT_EQ(stored.size(), 1u);
    kept = stored[0].record.message;
    EXPECT_LE(kept.size(), kMaxMessageBytes);
    const size_t marker_at = kept.find("\xE2\x80\xA6 [truncated ");
    ASSERT_NE(marker_at, std::string::npos) << kept.substr(kept.size() - 40);
    EXPECT_EQ(kept.substr(0, marker_at), original.substr(0, marker_at));
    EXPECT_EQ(kept.substr(marker_at), TruncationMarker(original.size() - marker_at));
    EXPECT_GT(marker_at, kMaxMessageBytes - 64) << "not more cut than the marker needs";
    path = store.path();
    EXPECT_EQ(Messages(store.Query({})), std::vector<std::string>{kept});
    const auto records = FileRecords(path);
    ASSERT_EQ(records.size(), 1u);
    EXPECT_EQ(records[0].message, kept);
  }
  // read back the same after a restart
  LogStore store(dir_, "s1", 100);
  EXPECT_EQ(Messages(store.Query({})), std::vector<std::string>{kept});
}

TEST_F(LogStoreTest, KeepsMessagesUpToTheBoundWhole) {
  LogStore store(dir_, "s1", 100);
  const std::string longest = Ab(kMaxMessageBytes);
  EXPECT_EQ(Messages(store.Submit({MakeRecord("a", 1, longest)})),
            std::vector<std::string>{longest});
}

TEST(TruncateTest, CutsBetweenUtf8CharactersAndSaysHowMuch) {
  EXPECT_EQ(Truncate("short", 100), "short");
  EXPECT_EQ(TruncationMarker(12345), "\xE2\x80\xA6 [truncated 12345 bytes]");
  // 2-byte characters: a cut never leaves half of one
  std::string text;
  for (int i = 0; i < 100; ++i) text += "\xC3\xA9";  // é
  for (size_t max = 40; max < 60; ++max) {
    const std::string cut = Truncate(text, max);
    EXPECT_LE(cut.size(), max);
    const size_t kept = cut.find("\xE2\x80\xA6");
    ASSERT_NE(kept, std::string::npos);
    EXPECT_EQ(kept % 2, 0u) << "half a character kept at max " << max;
    EXPECT_EQ(cut.substr(kept), TruncationMarker(text.size() - kept));
  }
}

TEST_F(LogStoreTest, BoundsTheOtherTextFields) {
  LogStore store(dir_, "s1", 100);
  Record r = MakeRecord(std::string(100000, 's'), 1);
  r.category = std::string(100000, 'c');
  const auto stored = store.Submit({r});
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_LE(stored[0].record.source.size(), kMaxFieldBytes);
  EXPECT_LE(stored[0].record.category.size(), kMaxFieldBytes);
  EXPECT_NE(stored[0].record.category.find("[truncated "), std::string::npos);
  EXPECT_TRUE(store.Submit({r}).empty()) << "the same record again is still a duplicate";
}

TEST_F(LogStoreTest, ForgedFarAheadSeqDoesNotSilenceTheSource) {
  std::string path;
  {
    LogStore store(dir_, "s1", 100);
    store.Submit({MakeRecord("victim", 1), MakeRecord("victim", 2)});
    // another client names the victim's source with huge seqs
    const auto forged = store.Submit({MakeRecord("victim", uint64_t{1} << 62, "forged"),
                                      MakeRecord("victim", ~uint64_t{0}, "forged max")});
    EXPECT_EQ(forged.size(), 2u) << "the forged records are records too";
    // the victim's later records are all stored, its retries still are not
    for (uint64_t seq = 3; seq <= 50; ++seq)
      EXPECT_EQ(store.Submit({MakeRecord("victim", seq)}).size(), 1u) << seq;
    EXPECT_TRUE(store.Submit({MakeRecord("victim", 2), MakeRecord("victim", 50)}).empty());
    EXPECT_TRUE(store.Submit({MakeRecord("victim", ~uint64_t{0})}).empty());
    EXPECT_EQ(store.size(), 52u);
    path = store.path();
  }
  // the same after a restart, which rebuilds what was seen from the file
  LogStore store(dir_, "s1", 100);
  EXPECT_EQ(store.Submit({MakeRecord("victim", 51)}).size(), 1u);
  EXPECT_TRUE(store.Submit({MakeRecord("victim", 7)}).empty());
}

TEST_F(LogStoreTest, ManyForgedSeqsDoNotSilenceTheSourceEither) {
  LogStore store(dir_, "s1", 100);
  for (uint64_t seq = 1; seq <= 10; ++seq) store.Submit({MakeRecord("victim", seq)});
  // scattered far-ahead seqs, more than the ranges remembered per source
  std::vector<Record> forged;
  for (uint64_t i = 1; i <= 3 * SeenSequences::kMaxRanges; ++i)
    forged.push_back(MakeRecord("victim", 1000000 * i, "forged"));
  store.Submit(forged);
  EXPECT_EQ(store.Submit({MakeRecord("victim", 11)}).size(), 1u);
  // the victim's own range is the large one: it is what stays remembered
  EXPECT_TRUE(store.Submit({MakeRecord("victim", 1), MakeRecord("victim", 11)}).empty());
}

TEST_F(LogStoreTest, QueryReturnsAtMostTheResultLimit) {
  LogStore store(dir_, "s1", kMaxQueryRecords + 100);
  std::vector<Record> batch;
  for (uint64_t i = 1; i <= kMaxQueryRecords + 5; ++i) batch.push_back(MakeRecord("a", i, "m"));
  store.Submit(batch);
  QueryFilter f;  // limit 0: as many as allowed
  auto all = Serials(store.Query(f));
  ASSERT_EQ(all.size(), kMaxQueryRecords);
  EXPECT_EQ(all.front(), 6u) << "the newest";
  EXPECT_EQ(all.back(), kMaxQueryRecords + 5u);
  f.limit = std::numeric_limits<uint32_t>::max();
  EXPECT_EQ(store.Query(f).size(), kMaxQueryRecords);
  f.regex = "^m$";
  EXPECT_EQ(store.Query(f).size(), kMaxQueryRecords);
  f.limit = 3;
  EXPECT_EQ(
      Serials(store.Query(f)),
      (std::vector<uint64_t>{kMaxQueryRecords + 3u, kMaxQueryRecords + 4u, kMaxQueryRecords + 5u}));
}

// ------------------------------------------------------------------------ seen sequences

TEST(SeenSequencesTest, RemembersExactlyWhatWasInserted) {
  SeenSequences seen;
  for (uint64_t seq : {1, 2, 3, 5, 4, 10}) seen.Insert("a", seq);
  for (uint64_t seq : {1, 2, 3, 4, 5, 10}) EXPECT_TRUE(seen.Contains("a", seq)) << seq;
  for (uint64_t seq : {0, 6, 9, 11}) EXPECT_FALSE(seen.Contains("a", seq)) << seq;
  EXPECT_FALSE(seen.Contains("b", 1));
  EXPECT_EQ(seen.ranges("a"), 2u) << "1-5 and 10";
  seen.Insert("a", ~uint64_t{0});
  EXPECT_TRUE(seen.Contains("a", ~uint64_t{0}));
  EXPECT_FALSE(seen.Contains("a", ~uint64_t{0} - 1));
  seen.Insert("a", 0);
  EXPECT_TRUE(seen.Contains("a", 0));
}

TEST(SeenSequencesTest, MergesRangesThatMeet) {
  SeenSequences seen;
  seen.Insert("a", 1);
  seen.Insert("a", 3);
  EXPECT_EQ(seen.ranges("a"), 2u);
  seen.Insert("a", 2);
  EXPECT_EQ(seen.ranges("a"), 1u);
  for (uint64_t seq = 4; seq < 1000; ++seq) seen.Insert("a", seq);
  EXPECT_EQ(seen.ranges("a"), 1u) << "a process counting up needs one range";
}

TEST(SeenSequencesTest, ForgetsTheSmallestOtherRangeBeyondTheBound) {
  SeenSequences seen(10, 3);
  for (uint64_t seq = 1; seq <= 100; ++seq) seen.Insert("a", seq);
  seen.Insert("a", 1000);
  seen.Insert("a", 2000);
  seen.Insert("a", 3000);  // a fourth range: the smallest other one (1000) goes
  EXPECT_EQ(seen.ranges("a"), 3u);
  EXPECT_FALSE(seen.Contains("a", 1000));
  EXPECT_TRUE(seen.Contains("a", 2000));
  EXPECT_TRUE(seen.Contains("a", 3000)) << "the range just inserted stays";
  EXPECT_TRUE(seen.Contains("a", 50)) << "the large range stays";
}

TEST(SeenSequencesTest, ForgetsTheLeastRecentlyInsertedSourceBeyondTheBound) {
  SeenSequences seen(3, 8);
  seen.Insert("a", 1);
  seen.Insert("b", 1);
  seen.Insert("c", 1);
  seen.Insert("a", 2);  // a is the most recent now, b the least
  seen.Insert("d", 1);
  EXPECT_EQ(seen.sources(), 3u);
  EXPECT_FALSE(seen.Contains("b", 1));
  EXPECT_TRUE(seen.Contains("a", 1));
  EXPECT_TRUE(seen.Contains("c", 1));
  EXPECT_TRUE(seen.Contains("d", 1));
  for (int i = 0; i < 10000; ++i) seen.Insert("s" + std::to_string(i), 1);
  EXPECT_EQ(seen.sources(), 3u) << "bounded whatever the number of sources";
}

}  // namespace
}  // namespace caliper::logger
