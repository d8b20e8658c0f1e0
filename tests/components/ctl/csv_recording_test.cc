// caliper-ctl record's CSV: header with units, samples up to the end time, gaps in batch numbers,
// and the recording ending when the simulated time goes back.
#include "csv_recording.h"

#include <gtest/gtest.h>

#include <sstream>
#include <vector>

namespace caliper::ctl {
namespace {

const std::vector<RecordedChannel> kChannels = {
    {"arm.hand.position", "m", 3, 1}, {"arm.line.tension", "N", 1, 1}, {"arm.q", "", 1, 2}};

std::vector<double> Rows(size_t count, double value) {
  return std::vector<double>(count * 6, value);
}

TEST(CsvHeader, NamesOneColumnPerScalarElementWithItsUnit) {
  EXPECT_EQ(CsvHeader(kChannels),
            "time [s],arm.hand.position[0] [m],arm.hand.position[1] [m],"
            "arm.hand.position[2] [m],arm.line.tension [N],arm.q[0] [-],arm.q[1] [-]");
  EXPECT_EQ(CsvHeader({{"arm.hand.rotation", "", 2, 2}}),
            "time [s],arm.hand.rotation[0][0] [-],arm.hand.rotation[0][1] [-],"
            "arm.hand.rotation[1][0] [-],arm.hand.rotation[1][1] [-]");
}

TEST(CsvRecording, WritesSamplesUpToTheEndTime) {
  std::ostringstream out;
  CsvRecording r(out, kChannels, 0.05);
  const double first[] = {0.01, 0.02, 0.03};
  EXPECT_FALSE(r.Add(1, first, 3, Rows(3, 1.5).data(), 6));
  const double second[] = {0.04, 0.05, 0.06};
  EXPECT_TRUE(r.Add(2, second, 3, Rows(3, 2.5).data(), 6));
  EXPECT_EQ(r.samples(), 5u);
  EXPECT_EQ(r.first_time(), 0.01);
  EXPECT_EQ(r.last_time(), 0.05);
  EXPECT_EQ(r.missing_batches(), 0u);
  EXPECT_EQ(r.error(), "");
  const std::string csv = out.str();
  EXPECT_NE(csv.find("\n0.01,1.5,1.5,1.5,1.5,1.5,1.5\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n0.05,2.5,2.5,2.5,2.5,2.5,2.5\n"), std::string::npos) << csv;
  EXPECT_EQ(csv.find("0.06"), std::string::npos) << "past the end";
}

TEST(CsvRecording, EndsAtTheFirstSamplePastTheEndTime) {
  std::ostringstream out;
  CsvRecording r(out, kChannels, 0.045);
  const double times[] = {0.02, 0.04};
  EXPECT_FALSE(r.Add(1, times, 2, Rows(2, 0).data(), 6));
  const double late[] = {0.06};
  EXPECT_TRUE(r.Add(2, late, 1, Rows(1, 0).data(), 6));
  EXPECT_EQ(r.samples(), 2u);
}

TEST(CsvRecording, CountsBatchesThatNeverArrived) {
  std::ostringstream out;
  CsvRecording r(out, kChannels);
  double t = 0;
  for (uint64_t batch : {1, 2, 5, 6, 8}) {
    t += 0.01;
    r.Add(batch, &t, 1, Rows(1, 0).data(), 6);
  }
  EXPECT_EQ(r.missing_batches(), 3u);
  EXPECT_EQ(r.gaps(), "3-4, 7");
  EXPECT_EQ(r.samples(), 5u);
  EXPECT_FALSE(r.done());
}

TEST(CsvRecording, StopsWhenTheSimulatedTimeGoesBack) {
  std::ostringstream out;
  CsvRecording r(out, kChannels);
  const double before[] = {1.0, 1.1};
  r.Add(1, before, 2, Rows(2, 0).data(), 6);
  const double after[] = {0.001};
  EXPECT_TRUE(r.Add(2, after, 1, Rows(1, 0).data(), 6));
  EXPECT_NE(r.error().find("went back from 1.1 s to 0.001 s"), std::string::npos) << r.error();
  EXPECT_EQ(r.samples(), 2u);
}

TEST(CsvRecording, RefusesABatchOfAnotherLayout) {
  std::ostringstream out;
  CsvRecording r(out, kChannels);
  const double t = 0.1;
  EXPECT_TRUE(r.Add(1, &t, 1, Rows(1, 0).data(), 4));
  EXPECT_NE(r.error().find("4 values per sample, 6 expected"), std::string::npos) << r.error();
  EXPECT_EQ(r.samples(), 0u);
}

}  // namespace
}  // namespace caliper::ctl
