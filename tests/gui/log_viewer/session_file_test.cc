// Reading and writing session logs: the known file, its malformed line, a malformed_* file per
// field that can be wrong, export round trips and exports that fail without harm.
#include "session_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "known_session.h"

#include "support/process.h"

namespace caliper::log_viewer {
namespace {

using testing::KnownSessionPath;

std::string TempPath(const std::string& name) {
  const char* base = std::getenv("TMPDIR");
  return std::string(base ? base : "/tmp") + "/log_viewer_" + std::to_string(getpid()) + "_" + name;
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SessionFileTest, ReadsEveryRecordOfTheKnownFile) {
  const SessionFileContents c = ReadSessionFile(KnownSessionPath());
  EXPECT_EQ(c.records.size(), static_cast<size_t>(testing::kKnownRecords));
  EXPECT_EQ(c.lines, 34u);
  EXPECT_EQ(c.records.front().component, "logger0");
  EXPECT_EQ(c.records.front().time_us, testing::kKnownStartUs + 1007);
  EXPECT_EQ(c.records[10].priority, logging::kError);
  EXPECT_EQ(c.records[10].message, "Tendon triceps exceeded max force 900 N");
  // escaped tab, newline and backslash come back as they were
  EXPECT_EQ(c.records[26].message, "tendon length\tbiceps 0.31 m\nsecond line \\ with a backslash");
}

TEST(SessionFileTest, KnownFileIsInTheFormatLineFormat) {
  // every line that is not a comment is FormatLine of what ParseLine makes of it
  std::istringstream in(Slurp(KnownSessionPath()));
  std::string line;
  int n = 0, records = 0;
  while (std::getline(in, line)) {
    ++n;
    logging::Record r;
    if (line.empty() || line[0] == '#' || n == testing::kKnownMalformedLine) continue;
    ASSERT_TRUE(logging::ParseLine(line, &r)) << "line " << n;
    EXPECT_EQ(logging::FormatLine(r), line) << "line " << n;
    ++records;
  }
  EXPECT_EQ(records, testing::kKnownRecords);
}

TEST(SessionFileTest, ReportsTheMalformedLineWithFileAndLineNumber) {
  const SessionFileContents c = ReadSessionFile(KnownSessionPath());
  EXPECT_EQ(c.malformed, 1u);
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_EQ(c.problems[0].rfind(KnownSessionPath() +
                                    ":19: not a log record (only 4 of the 9 tab-separated "
                                    "fields), skipped: '",
                                0),
            0u)
      << c.problems[0];
  EXPECT_NE(c.problems[0].find("torn line without the other fields"), std::string::npos);
}

TEST(SessionFileTest, ReportsATornLastLineAndCapsTheProblemList) {
  const std::string path = TempPath("torn.log");
  {
    std::ofstream out(path);
    out << "# comment\n\n";
    for (int i = 0; i < 30; ++i) out << "garbage " << i << "\n";
    out << "2024-03-05T10:00:00.000000Z\tINFO\tcaliper.x";  // no newline: being written
  }
  const SessionFileContents c = ReadSessionFile(path);
  EXPECT_TRUE(c.records.empty());
  EXPECT_EQ(c.malformed, 31u);
  ASSERT_EQ(c.problems.size(), SessionFileContents::kMaxProblems);
  EXPECT_EQ(c.problems[0],
            path +
                ":3: not a log record (only 1 of the 9 tab-separated fields), skipped: "
                "'garbage 0'");
  std::remove(path.c_str());
  const std::string torn = TempPath("torn2.log");
  {
    std::ofstream out(torn);
    out << "2024-03-05T10:00:00.000000Z\tINFO\tcaliper.x";
  }
  const SessionFileContents t = ReadSessionFile(torn);
  ASSERT_EQ(t.problems.size(), 1u);
  EXPECT_EQ(t.problems[0],
            torn + ":1: incomplete last line (is the file still being written?), skipped");
  std::remove(torn.c_str());
}

TEST(SessionFileTest, NamesTheWrongFieldOfAMalformedLine) {
  const struct {
    const char* file;
    const char* why;
  } cases[] = {
      {"malformed_fields.log", "only 4 of the 9 tab-separated fields"},
      {"malformed_time.log",
       "the time stamp '2024-03-05 10:00:02' is not YYYY-mm-ddTHH:MM:SS.uuuuuuZ"},
      {"malformed_priority.log", "the priority 'VERBOSE' is not FATAL..DEBUG or a number"},
      {"malformed_pid.log", "the pid 'pid4101' is not a number"},
      {"malformed_seq.log", "the seq '' is not a number"},
  };
  for (const auto& c : cases) {
    const std::string path = std::string(CALIPER_LOG_VIEWER_DATA_DIR) + "/" + c.file;
    const SessionFileContents contents = ReadSessionFile(path);
    EXPECT_EQ(contents.records.size(), 1u) << c.file;
    ASSERT_EQ(contents.problems.size(), 1u) << c.file;
    EXPECT_EQ(contents.problems[0].rfind(
                  path + ":3: not a log record (" + c.why + "), skipped: '2024-03-05", 0),
              0u)
        << contents.problems[0];
  }
}

TEST(SessionFileTest, MissingFileThrowsNamingIt) {
  try {
    ReadSessionFile("/nonexistent/dir/caliper-x.log");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot open /nonexistent/dir/caliper-x.log: No such file or directory");
  }
}

TEST(SessionFileTest, ExportedSelectionReadsBackIdentically) {
  const SessionFileContents c = ReadSessionFile(KnownSessionPath());
  std::vector<const logging::Record*> selection;
  for (int i : {2, 6, 10, 15, 26, 29}) selection.push_back(&c.records[static_cast<size_t>(i)]);
  const std::string path = TempPath("export.log");
  WriteSessionFile(path, selection, "exported\tfrom a test");
  const SessionFileContents back = ReadSessionFile(path);
  EXPECT_EQ(back.malformed, 0u);
  ASSERT_EQ(back.records.size(), selection.size());
  for (size_t i = 0; i < selection.size(); ++i) EXPECT_EQ(back.records[i], *selection[i]) << i;
  EXPECT_EQ(Slurp(path).rfind("# caliper session log; exported from a test\n", 0), 0u);
  std::remove(path.c_str());
}

TEST(SessionFileTest, UnwritableExportThrowsNamingThePath) {
  const SessionFileContents c = ReadSessionFile(KnownSessionPath());
  try {
    WriteSessionFile("/nonexistent/dir/out.log", {&c.records[0]});
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write /nonexistent/dir/out.log"),
              std::string::npos);
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos)
        << e.what();
  }
}

TEST(SessionFileTest, AFailedExportLeavesTheExistingFileAsItWas) {
  const SessionFileContents c = ReadSessionFile(KnownSessionPath());
  const std::string path = TempPath("kept.log");
  std::ofstream(path) << "# an earlier export\n";
  std::vector<const logging::Record*> all;
  for (const auto& r : c.records) all.push_back(&r);
  try {
    const caliper::testing::FileSizeLimit limit(200);  // writes past 200 bytes fail like a full disk
    WriteSessionFile(path, all);
    FAIL() << "an export past the file size limit succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cannot write " + path, 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Slurp(path), "# an earlier export\n");
  EXPECT_FALSE(std::ifstream(path + ".part-" + std::to_string(getpid())).good());
  std::remove(path.c_str());
}

}  // namespace
}  // namespace caliper::log_viewer
