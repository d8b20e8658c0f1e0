#include "caliper/recording/recording.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "caliper/core/scratch_directory.h"

namespace caliper::recording {
namespace {

using std::chrono::milliseconds;

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSameBits(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(SameBits(a[i], b[i])) << "value " << i;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// numbers that text or float conversions would change: a third, -0, a subnormal, the largest
// double, a NaN with a payload, infinity
sgal::DynamicState AwkwardState() {
  sgal::DynamicState s;
  s.time = 1.0 / 3.0;
  s.steps = 123456789012345ull;
  for (int i = 0; i < 3; ++i) {
    sgal::BodyState b;
    b.pose.position = Eigen::Vector3d(0.1 * i, -0.0, std::nextafter(1.0, 2.0));
    b.pose.orientation = Eigen::Quaterniond(0.5, -0.5, 0.5, std::sqrt(0.25) + i * 1e-17);
    b.linear_velocity = Eigen::Vector3d(std::numeric_limits<double>::denorm_min(), 1e308, -7);
    b.angular_velocity = Eigen::Vector3d(2.0 / 3.0, 0, -1e-300);
    s.bodies.push_back(b);
  }
  s.joint_positions = {0.25, -1.0 / 7.0};
  s.actuators = {{1.0, 2.0, 3.0}, {}, {std::numeric_limits<double>::infinity()}};
  s.commands = {12.0, 0.0, -3.5};
  uint64_t nan_bits = 0x7ff8000000001234ull;
  double nan;
  std::memcpy(&nan, &nan_bits, 8);
  s.engine = {nan, 1.0 / 3.0, -0.0, 4.9e-324};
  s.measurements = {-0.0, 1.0 / 7.0, nan};
  return s;
}

void ExpectSameState(const sgal::DynamicState& a, const sgal::DynamicState& b) {
  EXPECT_TRUE(SameBits(a.time, b.time));
  EXPECT_EQ(a.steps, b.steps);
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    const auto &x = a.bodies[i], &y = b.bodies[i];
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(SameBits(x.pose.position[k], y.pose.position[k]));
      EXPECT_TRUE(SameBits(x.linear_velocity[k], y.linear_velocity[k]));
      EXPECT_TRUE(SameBits(x.angular_velocity[k], y.angular_velocity[k]));
    }
    for (int k = 0; k < 4; ++k)
      EXPECT_TRUE(SameBits(x.pose.orientation.coeffs()[k], y.pose.orientation.coeffs()[k]));
  }
  ExpectSameBits(a.joint_positions, b.joint_positions);
  ASSERT_EQ(a.actuators.size(), b.actuators.size());
  for (size_t i = 0; i < a.actuators.size(); ++i) ExpectSameBits(a.actuators[i], b.actuators[i]);
  ExpectSameBits(a.commands, b.commands);
  ExpectSameBits(a.engine, b.engine);
  ExpectSameBits(a.measurements, b.measurements);
}

Header ArmHeader() {
  Header h;
  h.model_name = "arm";
  h.scene_file_name = "ecce_arm.dae";
  h.time_step = 0.001;
  h.keyframe_every = 100;
  h.channels_every = 1;
  h.channels = {
      {"arm.hand.position", "m", 3, 1}, {"motor1.current", "A", 1, 1}, {"arm.inertia", "", 2, 2}};
  h.first_step = 0;
  return h;
}

SceneVersion Scene0() { return {0, 0, "ecce_arm.dae", std::string("<COLLADA>\0binary", 16)}; }

// the step's sample: values that tell their step apart
Sample SampleAt(uint64_t step) {
  Sample s;
  s.step = step;
  s.time = step * 0.001;
  const double t = s.time;
  s.values = {t, -t, 1.0 / (step + 3), 0.5 * step, 1, 2, 3, t * t};
  return s;
}

TEST(RecordingState, RoundTripIsBitExact) {
  const sgal::DynamicState s = AwkwardState();
  ExpectSameState(DecodeState(EncodeState(s)), s);
  ExpectSameState(DecodeState(EncodeState(sgal::DynamicState{})), sgal::DynamicState{});
}

TEST(RecordingState, RefusesTruncatedAndGarbageBytes) {
  const std::string bytes = EncodeState(AwkwardState());
  for (size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(DecodeState(bytes.substr(0, n)), RecordingError) << n << " bytes";
  EXPECT_THROW(DecodeState(bytes + "x"), RecordingError);
  try {
    DecodeState("garbage that is long enough to hold a header........");
    FAIL() << "garbage decoded";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("does not start with CLDS"), std::string::npos)
        << e.what();
  }
  // a body count far beyond the bytes is refused before anything is allocated
  std::string huge = bytes;
  const size_t bodies_at = 4 + 8 + 8 + 8;
  for (int i = 0; i < 8; ++i) huge[bodies_at + i] = static_cast<char>(0xff);
  try {
    DecodeState(huge);
    FAIL() << "a huge count decoded";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("the bodies counts"), std::string::npos) << e.what();
  }
  std::string version = bytes;
  version[4] = 3;
  EXPECT_THROW(DecodeState(version), RecordingError);
}

TEST(RecordingState, AStateWithoutMeasurementsKeepsTheLayoutOfOlderRecordings) {
  // version 1 (no measurements) is what recordings held before the delayed channels: such a
  // state is still written so, and read back with no measurements
  sgal::DynamicState old = AwkwardState();
  old.measurements.clear();
  const std::string v1 = EncodeState(old);
  EXPECT_EQ(v1[4], 1);
  EXPECT_EQ(v1.size(), EncodeState(AwkwardState()).size() - 8 - 3 * 8);
  ExpectSameState(DecodeState(v1), old);
  EXPECT_TRUE(DecodeState(v1).measurements.empty());
  // with measurements: version 2, the measurements counted after the engine's numbers
  const std::string v2 = EncodeState(AwkwardState());
  EXPECT_EQ(v2[4], 2);
  EXPECT_EQ(v2.substr(0, 4), v1.substr(0, 4));
  EXPECT_EQ(v2.substr(5, v1.size() - 5), v1.substr(5));
  // version 2 without measurements is not how a state is written: refused (one encoding each)
  std::string empty = v1;
  empty[4] = 2;
  empty += std::string(8, '\0');
  try {
    DecodeState(empty);
    FAIL() << "a version 2 state without measurements decoded";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("version 2 with no measurements"), std::string::npos)
        << e.what();
  }
}

TEST(Recording, EveryRecordKindRoundTrips) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/run.caliper";
  const sgal::DynamicState state = AwkwardState();
  {
    Writer w(path, ArmHeader(), Scene0());
    for (uint64_t step = 0; step < 450; ++step) {
      if (step % 100 == 0) {
        sgal::DynamicState s = state;
        s.steps = step;
        w.AddKeyframe({step, step * 0.001, step < 300 ? 0u : 1u, s});
      }
      if (step == 40) w.AddEvent({40, "command", "motor1", {12.0}});
      if (step == 40) w.AddEvent({40, "parameter", "upper_arm.mass", {1.0 / 3.0}});
      if (step == 250) w.AddEvent({250, "release", "", {}});
      if (step == 300) {
        w.AddEvent({300, "edit", "remove via point", {}});
        w.AddScene({1, 300, "ecce_arm.dae", "<COLLADA edited/>"});
      }
      w.AddSample(SampleAt(step));
    }
    w.AddLog({1700000000.25, "WARN", "caliper.model", "model", "a tendon went slack"});
    w.AddLog({1700000000.5, "INFO", "caliper.model", "model", "second"});
    w.Flush();
    EXPECT_EQ(w.error(), "");
    EXPECT_GT(w.bytes_written(), 4096u);
    EXPECT_EQ(w.path(), path);
  }
  Reader r(path);
  const Header& h = r.header();
  EXPECT_EQ(h.model_name, "arm");
  EXPECT_EQ(h.scene_file_name, "ecce_arm.dae");
  EXPECT_TRUE(SameBits(h.time_step, 0.001));
  EXPECT_EQ(h.keyframe_every, 100u);
  EXPECT_EQ(h.channels_every, 1u);
  ASSERT_EQ(h.channels.size(), 3u);
  EXPECT_EQ(h.channels[0].id, "arm.hand.position");
  EXPECT_EQ(h.channels[0].rows, 3u);
  EXPECT_EQ(h.channels[2].unit, "");
  EXPECT_EQ(h.channels[2].cols, 2u);
  EXPECT_EQ(r.last_step(), 449u);
  EXPECT_DOUBLE_EQ(r.duration(), 0.449);

  const auto scenes = r.scenes();
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_EQ(scenes[0].bytes, Scene0().bytes);  // binary bytes, NUL included
  EXPECT_EQ(scenes[1].step, 300u);
  EXPECT_EQ(scenes[1].bytes, "<COLLADA edited/>");

  EXPECT_EQ(r.keyframe_steps(), (std::vector<uint64_t>{0, 100, 200, 300, 400}));
  const Keyframe k = r.KeyframeAtOrBefore(299);
  EXPECT_EQ(k.step, 200u);
  EXPECT_EQ(k.scene_version, 0u);
  EXPECT_TRUE(SameBits(k.time, 0.2));
  sgal::DynamicState expected = state;
  expected.steps = 200;
  ExpectSameState(k.state, expected);
  EXPECT_EQ(r.KeyframeAtOrBefore(300).step, 300u);
  EXPECT_EQ(r.KeyframeAtOrBefore(300).scene_version, 1u);
  EXPECT_EQ(r.KeyframeAtOrBefore(100000).step, 400u);

  const auto all = r.Events(0, 1000);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].kind, "command");
  EXPECT_EQ(all[0].target, "motor1");
  EXPECT_EQ(all[0].values, std::vector<double>{12.0});
  EXPECT_EQ(all[1].kind, "parameter");  // same step: in the order they were recorded
  EXPECT_TRUE(SameBits(all[1].values.at(0), 1.0 / 3.0));
  EXPECT_EQ(all[2].kind, "release");
  EXPECT_TRUE(all[2].values.empty());
  EXPECT_EQ(all[3].target, "remove via point");
  EXPECT_EQ(r.Events(41, 300).size(), 1u);  // last excluded
  EXPECT_EQ(r.Events(40, 41).size(), 2u);
  EXPECT_TRUE(r.Events(301, 449).empty());

  const auto samples = r.Samples(10, 20);
  ASSERT_EQ(samples.size(), 10u);
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample want = SampleAt(10 + i);
    EXPECT_EQ(samples[i].step, want.step);
    EXPECT_TRUE(SameBits(samples[i].time, want.time));
    ExpectSameBits(samples[i].values, want.values);
  }
  EXPECT_EQ(r.Samples(0, 1000).size(), 450u);

  const auto log = r.Log();
  ASSERT_EQ(log.size(), 2u);
  EXPECT_TRUE(SameBits(log[0].time, 1700000000.25));
  EXPECT_EQ(log[0].priority, "WARN");
  EXPECT_EQ(log[0].category, "caliper.model");
  EXPECT_EQ(log[0].component, "model");
  EXPECT_EQ(log[0].message, "a tendon went slack");
  EXPECT_EQ(log[1].message, "second");
}

TEST(Recording, NoKeyframeBeforeTheFirstIsAnError) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/late.caliper";
  {
    Writer w(path, ArmHeader(), Scene0());
    w.AddKeyframe({100, 0.1, 0, AwkwardState()});
  }
  Reader r(path);
  EXPECT_EQ(r.KeyframeAtOrBefore(100).step, 100u);
  try {
    r.KeyframeAtOrBefore(99);
    FAIL() << "a keyframe before the first";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no keyframe at or before step 99"), std::string::npos)
        << e.what();
  }
}

TEST(Recording, ExportsChannelsAsCsvWithUnits) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/run.caliper";
  {
    Writer w(path, ArmHeader(), Scene0());
    for (uint64_t step = 1; step <= 3; ++step) w.AddSample(SampleAt(step));
  }
  Reader(path).ExportCsv(dir.path() + "/run.csv");
  EXPECT_EQ(ReadFile(dir.path() + "/run.csv"),
            "time [s],arm.hand.position[0] [m],arm.hand.position[1] [m],"
            "arm.hand.position[2] [m],motor1.current [A],arm.inertia[0][0] [-],"
            "arm.inertia[0][1] [-],arm.inertia[1][0] [-],arm.inertia[1][1] [-]\n"
            "0.001,0.001,-0.001,0.25,0.5,1,2,3,1e-06\n"
            "0.002,0.002,-0.002,0.2,1,1,2,3,4e-06\n"
            "0.003,0.003,-0.003,0.16666666666666666,1.5,1,2,3,9e-06\n");

  Header none = ArmHeader();
  none.channels.clear();
  const std::string empty = dir.path() + "/none.caliper";
  { Writer w(empty, none, Scene0()); }
  EXPECT_THROW(Reader(empty).ExportCsv(dir.path() + "/none.csv"), RecordingError);
}

// the ```python block of docs/recording.md's "## The file", run as written
TEST(Recording, ReadmePythonExampleReadsAChannel) {
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "run through ctest (it sets CALIPER_SOURCE_DIR)";
  const std::string readme = ReadFile(std::string(source) + "/docs/recording.md");
  const size_t section = readme.find("\n## The file\n");
  ASSERT_NE(section, std::string::npos) << "docs/recording.md has no '## The file'";
  const size_t begin = readme.find("```python\n", section);
  ASSERT_NE(begin, std::string::npos) << "no python example after '## The file'";
  const size_t end = readme.find("```\n", begin + 10);
  ASSERT_NE(end, std::string::npos);
  const std::string script = readme.substr(begin + 10, end - begin - 10);

  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/run.caliper";
  {
    Writer w(path, ArmHeader(), Scene0());
    for (uint64_t step = 0; step < 50; ++step) w.AddSample(SampleAt(step));
  }
  WriteFile(dir.path() + "/read_channel.py", script);
  const std::string out = dir.path() + "/out.txt";
  const std::string command = "python3 " + dir.path() + "/read_channel.py " + path +
                              " arm.hand.position > " + out + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadFile(out);
  std::istringstream lines(ReadFile(out));
  std::string line;
  uint64_t step = 0;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::vector<double> v;
    std::string field;
    while (fields >> field) v.push_back(std::strtod(field.c_str(), nullptr));
    const Sample want = SampleAt(step);
    ASSERT_EQ(v.size(), 4u) << line;
    EXPECT_TRUE(SameBits(v[0], want.time)) << line;
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(SameBits(v[1 + k], want.values[k])) << line;
    ++step;
  }
  EXPECT_EQ(step, 50u);
  const std::string missing =
      "python3 " + dir.path() + "/read_channel.py " + path + " no.such > " + out + " 2>&1";
  EXPECT_NE(std::system(missing.c_str()), 0);
  EXPECT_NE(ReadFile(out).find("has no channel no.such"), std::string::npos) << ReadFile(out);
}

void ExpectRefused(const std::string& path, const std::string& why) {
  try {
    Reader r(path);
    FAIL() << path << " opened";
  } catch (const RecordingError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(why), std::string::npos) << what;
  }
}

TEST(Recording, RefusesFilesThatAreNotRecordings) {
  core::ScratchDirectory dir("recording_test");
  ExpectRefused(dir.path() + "/missing.caliper", "does not exist");

  const std::string garbage = dir.path() + "/garbage.caliper";
  WriteFile(garbage, std::string(5000, 'x'));
  ExpectRefused(garbage, "not an SQLite file");

  const std::string other = dir.path() + "/other.sqlite";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(other.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE t(x)", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  ExpectRefused(other, "not a Caliper recording (it has no meta table)");

  const std::string newer = dir.path() + "/newer.caliper";
  { Writer w(newer, ArmHeader(), Scene0()); }
  ASSERT_EQ(sqlite3_open(newer.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE meta SET value='2' WHERE key='format_version'", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  ExpectRefused(newer, "format version 2, this build reads version 1");

  // the writer never overwrites: the earlier recording is still there, whole
  const std::string before = ReadFile(newer);
  try {
    Writer w(newer, ArmHeader(), Scene0());
    FAIL() << "an existing file was overwritten";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find(newer + ": the file exists"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(ReadFile(newer), before);
}

TEST(Recording, SizeLimitStopsTheRecordingAndKeepsWhatWasCommitted) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/small.caliper";
  constexpr uint64_t kLimit = 256 * 1024;
  uint64_t step = 0;
  {
    Writer w(path, ArmHeader(), Scene0(), milliseconds(500), kLimit);
    // 500 samples of 8 values per batch (~48 KiB): the limit comes within a few batches
    for (int batch = 0; batch < 40 && w.error().empty(); ++batch) {
      for (int i = 0; i < 500; ++i) w.AddSample(SampleAt(step++));
      w.Flush();
    }
    const std::string error = w.error();
    ASSERT_FALSE(error.empty()) << "no error after " << step << " samples";
    EXPECT_NE(error.find("recording to " + path + " stopped at step "), std::string::npos) << error;
    EXPECT_NE(error.find("limit of 262144 bytes"), std::string::npos) << error;
    EXPECT_LE(w.bytes_written(), kLimit);
    // later calls do nothing and throw nothing
    w.AddSample(SampleAt(step++));
    w.AddKeyframe({step, 0, 0, AwkwardState()});
    w.AddEvent({step, "command", "motor1", {1}});
    w.AddLog({0, "INFO", "c", "m", "after"});
    w.Flush();
    EXPECT_EQ(w.error(), error);
  }
  Reader r(path);
  const auto samples = r.Samples(0, step);
  EXPECT_GT(samples.size(), 500u);
  EXPECT_LT(samples.size(), step - 1);
  EXPECT_EQ(samples.size() % 500, 0u);  // whole transactions only
  EXPECT_TRUE(r.Log().empty());
  EXPECT_TRUE(r.keyframe_steps().empty());
}

// a disk that does not keep up (here: a writer that commits only every hour) must not let the
// queue fill the Model's memory: the recording stops saying why, the caller goes on
TEST(Recording, ADiskThatDoesNotKeepUpStopsTheRecording) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/slow.caliper";
  Writer w(path, ArmHeader(), Scene0(), std::chrono::hours(1));
  uint64_t step = 0;
  for (; step < 150000 && w.error().empty(); ++step) w.AddSample(SampleAt(step));
  EXPECT_NE(w.error().find("the disk did not keep up (100000 records"), std::string::npos)
      << w.error();
  EXPECT_LE(step, 100001u);
  w.AddSample(SampleAt(step));  // a no-op, no throw
}

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

TEST(Recording, KilledWriterLosesAtMostOneCommitInterval) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/killed.caliper";
  Header h = ArmHeader();
  h.channels = {{"wall_clock", "s", 1, 1}};
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // a Model at about 1 kHz: each sample carries the wall clock when it was queued; bounded
    // to 10 s in case the parent dies
    Writer w(path, h, Scene0());
    const double start = WallSeconds();
    for (uint64_t step = 0; WallSeconds() - start < 10; ++step) {
      w.AddSample({step, step * 0.001, {WallSeconds()}});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    _exit(0);
  }
  std::this_thread::sleep_for(milliseconds(1200));
  const double killed_at = WallSeconds();
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));

  // the write-ahead log is still there: the reader recovers it
  Reader r(path);
  const auto samples = r.Samples(0, std::numeric_limits<int64_t>::max());
  ASSERT_FALSE(samples.empty());
  const double last = samples.back().values.at(0);
  std::printf("[ recording ] killed writer: %zu samples, the last %.3f s before the kill\n",
              samples.size(), killed_at - last);
  EXPECT_LE(killed_at - last, 0.5 + 0.2);
  EXPECT_GT(killed_at - last, 0.0);
  for (size_t i = 0; i < samples.size(); ++i) ASSERT_EQ(samples[i].step, i);
}

TEST(Recording, KilledWritersFileOpensWithoutItsShm) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/killed.caliper";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    Writer w(path, ArmHeader(), Scene0(), milliseconds(20));
    for (uint64_t step = 0; step < 100; ++step) w.AddSample(SampleAt(step));
    w.Flush();
    raise(SIGKILL);
    _exit(1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  std::ifstream wal(path + "-wal");
  ASSERT_TRUE(wal.good()) << "the killed writer left no write-ahead log";
  // the index of the log goes too: the reader rebuilds it from the log
  ASSERT_EQ(::unlink((path + "-shm").c_str()), 0);
  Reader r(path);
  EXPECT_EQ(r.Samples(0, 1000).size(), 100u);
}

// numbers for the report, not asserted: the cost of AddSample and the file's growth
TEST(Recording, MeasuresAddSampleCostAndBytesPerSample) {
  core::ScratchDirectory dir("recording_test");
  const std::string path = dir.path() + "/measure.caliper";
  Header h = ArmHeader();
  h.channels = {{"arm.values", "m", 20, 1}};
  Writer w(path, h, Scene0());
  // batches of 400 samples (0.4 s at 1 kHz, within one commit interval), queued as the step
  // loop does and then committed; 20 batches for the file's growth
  constexpr int kBatch = 400, kBatches = 20, kCount = kBatch * kBatches;
  std::vector<Sample> samples(kCount);
  for (int i = 0; i < kCount; ++i)
    samples[i] = {static_cast<uint64_t>(i), i * 0.001, std::vector<double>(20, i * 0.5)};
  const uint64_t before = w.bytes_written();
  double queue_ns = 0;
  for (int b = 0; b < kBatches; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = b * kBatch; i < (b + 1) * kBatch; ++i) w.AddSample(std::move(samples[i]));
    queue_ns +=
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    w.Flush();
  }
  EXPECT_EQ(w.error(), "");
  std::printf(
      "[ recording ] AddSample: %.0f ns per call; %.0f bytes per 1000 samples of 20 values\n",
      queue_ns / kCount, (w.bytes_written() - before) * 1000.0 / kCount);
  EXPECT_EQ(Reader(path).Samples(0, kCount).size(), static_cast<size_t>(kCount));
}

}  // namespace
}  // namespace caliper::recording
