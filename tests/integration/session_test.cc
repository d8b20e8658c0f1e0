// Real processes: a private omniNames, caliper-logger, caliper-sample, driven by caliper-ctl.
#include <gtest/gtest.h>
#include <signal.h>

#include <memory>
#include <algorithm>
#include <sstream>
#include <thread>

#include "caliper/logging/record.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

class SessionTest : public ::testing::Test {
 protected:
  void SetUp() override { naming_ = std::make_unique<NamingService>(dir_.path()); }

  Process& Start(const std::string& program, const std::string& out_name,
                 std::vector<std::string> options) {
    std::vector<std::string> argv = {Bin(program), "--nameservice", naming_->address(), "-o",
                                     "log.spool_dir=" + dir_.path() + "/spool"};
    argv.insert(argv.end(), options.begin(), options.end());
    processes_.push_back(std::make_unique<Process>(argv, dir_.path() + "/" + out_name + ".out"));
    return *processes_.back();
  }

  Process& StartLogger() {
    return Start("caliper-logger", "logger",
                 {"-o", "logger.directory=" + dir_.path() + "/logs", "-o", "logger.session=test",
                  "-o", "exec.auto_activate=true"});
  }

  bool Bound(const std::string& name) {
    return WaitFor([&] { return Ctl(naming_->address(), {"state", name}).exit_code == 0; },
                   seconds(10));
  }

  std::string StateOf(const std::string& name) {
    return Ctl(naming_->address(), {"state", name}).out;
  }

  bool Listed(const std::string& name) {
    const auto ls = Ctl(naming_->address(), {"ls"});
    return ls.exit_code == 0 && ls.out.find(name + " ") != std::string::npos;
  }

  std::string SessionLog() {
    const auto files = ListFiles(dir_.path() + "/logs", "caliper-");
    return files.size() == 1 ? files[0] : "";
  }

  /// Records of one category in the session log, in file order.
  std::vector<logging::Record> LoggedRecords(const std::string& category) {
    std::vector<logging::Record> records;
    std::istringstream in(ReadFile(SessionLog()));
    std::string line;
    logging::Record r;
    while (std::getline(in, line))
      if (logging::ParseLine(line, &r) && r.category == category) records.push_back(r);
    return records;
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::vector<std::unique_ptr<Process>> processes_;
};

TEST_F(SessionTest, CtlListsComponentsAndDrivesTheLifecycle) {
  StartLogger();
  Process& sample = Start("caliper-sample", "sample", {});
  ASSERT_TRUE(Bound("logger0"));
  ASSERT_TRUE(Bound("sample0"));

  const auto ls = Ctl(naming_->address(), {"ls"});
  EXPECT_EQ(ls.exit_code, 0);
  EXPECT_NE(ls.out.find("logger0          ACTIVE"), std::string::npos) << ls.out;
  EXPECT_NE(ls.out.find("sample0          INACTIVE"), std::string::npos) << ls.out;
  EXPECT_NE(ls.out.find(".host_cxt/sample0.rtc"), std::string::npos) << ls.out;

  EXPECT_EQ(Ctl(naming_->address(), {"activate", "sample0"}).exit_code, 0);
  EXPECT_EQ(StateOf("sample0"), "ACTIVE\n");
  const auto again = Ctl(naming_->address(), {"activate", "sample0"});
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("PRECONDITION_NOT_MET"), std::string::npos) << again.err;
  EXPECT_EQ(Ctl(naming_->address(), {"deactivate", "sample0"}).exit_code, 0);
  EXPECT_EQ(StateOf("sample0"), "INACTIVE\n");
  const auto reset = Ctl(naming_->address(), {"reset", "sample0"});
  EXPECT_EQ(reset.exit_code, 1);
  EXPECT_NE(reset.err.find("PRECONDITION_NOT_MET (state is INACTIVE)"), std::string::npos)
      << reset.err;

  // a second sample gets the next free name
  Start("caliper-sample", "sample-b", {});
  ASSERT_TRUE(Bound("sample1"));

  EXPECT_EQ(Ctl(naming_->address(), {"exit", "sample0"}).exit_code, 0);
  EXPECT_EQ(sample.Wait(seconds(10)), 0) << sample.Output();
  EXPECT_FALSE(Listed("sample0"));
  EXPECT_TRUE(Listed("sample1"));
}

TEST_F(SessionTest, FailingHookMovesToErrorAndResetRecovers) {
  StartLogger();
  Process& sample = Start("caliper-sample", "sample",
                          {"-o", "sample.fail_at_tick=3", "-o", "exec.rate=50"});
  ASSERT_TRUE(Bound("sample0"));
  ASSERT_EQ(Ctl(naming_->address(), {"activate", "sample0"}).exit_code, 0);
  ASSERT_TRUE(WaitFor([&] { return StateOf("sample0").rfind("ERROR", 0) == 0; }, seconds(5)));
  EXPECT_NE(StateOf("sample0").find("on_execute threw: configured to fail at tick 3"),
            std::string::npos);
  EXPECT_TRUE(sample.Running());

  const auto activate = Ctl(naming_->address(), {"activate", "sample0"});
  EXPECT_EQ(activate.exit_code, 1);
  EXPECT_NE(activate.err.find("PRECONDITION_NOT_MET (state is ERROR)"), std::string::npos);
  EXPECT_EQ(Ctl(naming_->address(), {"reset", "sample0"}).exit_code, 0);
  EXPECT_EQ(StateOf("sample0"), "INACTIVE\n");

  // the failure is in the session log with its reason
  ASSERT_TRUE(WaitFor([&] { return !LoggedRecords("caliper.sample.rtc").empty(); }, seconds(5)));
  bool found = false;
  for (const auto& r : LoggedRecords("caliper.sample.rtc"))
    found |= r.priority == logging::kError &&
             r.message.find("configured to fail at tick 3") != std::string::npos;
  EXPECT_TRUE(found);
}

TEST_F(SessionTest, TenThousandRecordsSurviveAKilledLoggerExactlyOnceInOrder) {
  constexpr int kRecords = 10000;
  Process* first_logger = &StartLogger();
  Start("caliper-sample", "sample",
        {"-o", "sample.records_per_tick=25", "-o", "exec.rate=100", "-o",
         "sample.record_limit=" + std::to_string(kRecords), "-o", "exec.auto_activate=true"});
  ASSERT_TRUE(Bound("sample0"));

  // kill the logger while the records flow, keep it away for a second, start it again
  ASSERT_TRUE(WaitFor([&] { return LoggedRecords("caliper.sample.records").size() >= 1000; },
                      seconds(10)));
  first_logger->Signal(SIGKILL);
  first_logger->Wait(seconds(5));
  const size_t at_kill = LoggedRecords("caliper.sample.records").size();
  EXPECT_LT(at_kill, static_cast<size_t>(kRecords)) << "the logger must die mid-stream";
  std::this_thread::sleep_for(seconds(1));
  StartLogger();

  ASSERT_TRUE(WaitFor(
      [&] { return LoggedRecords("caliper.sample.records").size() >= kRecords; }, seconds(40)))
      << "only " << LoggedRecords("caliper.sample.records").size() << " records arrived";
  std::this_thread::sleep_for(milliseconds(500));  // anything duplicated would show up by now

  const auto records = LoggedRecords("caliper.sample.records");
  ASSERT_EQ(records.size(), static_cast<size_t>(kRecords));
  for (int i = 0; i < kRecords; ++i) {
    ASSERT_EQ(records[i].message,
              "record " + std::to_string(i + 1) + " of " + std::to_string(kRecords))
        << "at position " << i;
    if (i > 0) {
      ASSERT_GT(records[i].seq, records[i - 1].seq);
    }
  }
  EXPECT_EQ(ListFiles(dir_.path() + "/logs", "caliper-").size(), 1u) << "one file per session";
}

TEST_F(SessionTest, ComponentRegistersAgainWhenTheNamingServiceRestarts) {
  constexpr double kInterval = 1.0;
  Start("caliper-sample", "sample",
        {"-o", "naming.update.interval=" + std::to_string(kInterval), "-o", "log.service=none"});
  ASSERT_TRUE(Bound("sample0"));
  naming_->Stop();
  naming_->Start(/*fresh=*/true);  // all bindings lost
  const auto restarted = std::chrono::steady_clock::now();
  EXPECT_FALSE(Listed("sample0"));
  ASSERT_TRUE(WaitFor([&] { return Listed("sample0"); }, seconds(10)));
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - restarted).count();
  EXPECT_LE(took, 2 * kInterval) << "listed again after " << took << " s";
}

TEST_F(SessionTest, SigtermShutsDownCleanlyAndUnbinds) {
  Process& sample = Start("caliper-sample", "sample", {"-o", "exec.auto_activate=true"});
  ASSERT_TRUE(Bound("sample0"));
  sample.Signal(SIGTERM);
  EXPECT_EQ(sample.Wait(seconds(10)), 0) << sample.Output();
  EXPECT_FALSE(Listed("sample0"));
  EXPECT_NE(sample.Output().find("deactivated after"), std::string::npos) << sample.Output();
}

TEST_F(SessionTest, LogFollowPrintsNewRecordsUntilInterrupted) {
  StartLogger();
  Start("caliper-sample", "sample",
        {"-o", "sample.record_limit=30", "-o", "sample.records_per_tick=3", "-o", "exec.rate=20"});
  ASSERT_TRUE(Bound("logger0"));
  ASSERT_TRUE(Bound("sample0"));
  Process follow({Bin("caliper-ctl"), "--nameservice", naming_->address(), "log", "--follow",
                  "--category", "caliper.sample.records"},
                 dir_.path() + "/follow.out");
  std::this_thread::sleep_for(milliseconds(300));
  ASSERT_EQ(Ctl(naming_->address(), {"activate", "sample0"}).exit_code, 0);
  EXPECT_TRUE(WaitFor([&] { return follow.Output().find("record 30 of 30") != std::string::npos; },
                      seconds(10)))
      << follow.Output();
  EXPECT_EQ(follow.Output().find("lifecycle"), std::string::npos) << "category filter";
  follow.Signal(SIGINT);
  EXPECT_EQ(follow.Wait(seconds(5)), 0);

  const auto grep = Ctl(naming_->address(), {"log", "--grep", "record 1[0-9] of", "--limit", "3"});
  EXPECT_EQ(grep.exit_code, 0);
  EXPECT_EQ(std::count(grep.out.begin(), grep.out.end(), '\n'), 3) << grep.out;
  EXPECT_NE(grep.out.find("record 19 of 30"), std::string::npos) << grep.out;
}

}  // namespace
}  // namespace caliper::testing
