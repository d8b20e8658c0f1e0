// Whole-or-nothing file writes.
#include "caliper/core/system.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "support/process.h"

namespace caliper::core {
namespace {

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class WriteFileReplacingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper-system-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
    path_ = dir_ + "/out.csv";
    std::ofstream(path_) << "old contents\n";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }
  std::string dir_;
  std::string path_;
};

TEST_F(WriteFileReplacingTest, ReplacesTheFileWithWhatWasWritten) {
  WriteFileReplacing(path_, [](std::ostream& out) { out << "time [s],x [m]\n0,1\n"; });
  EXPECT_EQ(Read(path_), "time [s],x [m]\n0,1\n");
  EXPECT_FALSE(std::ifstream(path_ + ".part-" + std::to_string(::getpid())).good())
      << "no temporary file left";
}

TEST_F(WriteFileReplacingTest, AFailingWriterLeavesTheOldFile) {
  EXPECT_THROW(WriteFileReplacing(path_,
                                  [](std::ostream& out) {
                                    out << "half";
                                    throw std::runtime_error("stopped");
                                  }),
               std::runtime_error);
  EXPECT_EQ(Read(path_), "old contents\n");
  EXPECT_FALSE(std::ifstream(path_ + ".part-" + std::to_string(::getpid())).good());
}

TEST_F(WriteFileReplacingTest, AnUnwritablePlaceIsNamedWithTheReason) {
  const std::string bad = dir_ + "/no_such_dir/out.csv";
  try {
    WriteFileReplacing(bad, [](std::ostream& out) { out << "x"; });
    FAIL() << "wrote into a missing directory";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(bad), std::string::npos) << message;
    EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
  }
}

TEST_F(WriteFileReplacingTest, AFailedWriteIsReportedWithItsReasonAndTheOldFileKept) {
  try {
    const testing::FileSizeLimit limit(1000);  // writes past 1000 bytes fail like a full disk
    WriteFileReplacing(path_, [](std::ostream& out) { out << std::string(1 << 16, 'x'); });
    FAIL() << "a write past the limit succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Read(path_), "old contents\n");
  EXPECT_FALSE(std::ifstream(path_ + ".part-" + std::to_string(::getpid())).good());
}

TEST_F(WriteFileReplacingTest, ASymlinkedTargetIsReplacedWhereItPoints) {
  const std::string link = dir_ + "/link.csv";
  ASSERT_EQ(::symlink(path_.c_str(), link.c_str()), 0);
  WriteFileReplacing(link, [](std::ostream& out) { out << "new\n"; });
  EXPECT_EQ(Read(path_), "new\n") << "the file the link names";
  struct stat st = {};
  ASSERT_EQ(::lstat(link.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode)) << "the link stays a link";
}

TEST_F(WriteFileReplacingTest, KeepsTheFilesPermissionsAndRefusesAPlantedTemporaryName) {
  ASSERT_EQ(::chmod(path_.c_str(), 0600), 0);
  WriteFileReplacing(path_, [](std::ostream& out) { out << "private\n"; });
  struct stat st = {};
  ASSERT_EQ(::stat(path_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  // a link planted under the temporary's name is never written through
  const std::string victim = dir_ + "/victim";
  std::ofstream(victim) << "untouched\n";
  ASSERT_EQ(::symlink(victim.c_str(), (path_ + ".part-" + std::to_string(::getpid())).c_str()), 0);
  EXPECT_THROW(WriteFileReplacing(path_, [](std::ostream& out) { out << "x"; }),
               std::runtime_error);
  EXPECT_EQ(Read(victim), "untouched\n");
  EXPECT_EQ(Read(path_), "private\n");
}

}  // namespace
}  // namespace caliper::core
