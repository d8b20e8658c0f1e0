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

TEST_F(WriteFileReplacingTest, AFullDeviceIsReportedAndTheOldFileKept) {
  // /dev/full accepts the open and fails every write with ENOSPC; a symlink beside the target
  // is not needed: writing the temporary file itself must fail, so point the directory there
  const std::string link = dir_ + "/full";
  ASSERT_EQ(::symlink("/dev/full", (link + ".part-" + std::to_string(::getpid())).c_str()), 0);
  std::ofstream(link) << "kept\n";
  try {
    WriteFileReplacing(link, [](std::ostream& out) { out << std::string(1 << 16, 'x'); });
    FAIL() << "a write to a full device succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Read(link), "kept\n");
}

}  // namespace
}  // namespace caliper::core
