// The Graph Plotter's data classes on their own (no Qt, no CORBA): the ring buffer and its cap,
// time window queries, rewinds, min/max thinning for drawing, CSV export of every sample with
// units, layouts written and read back (and rejected with the line named, also for a buffer past
// the memory budget), files that fail to be written leaving the old ones, stale series,
// subscription layouts checked against a fresh channel listing, the quiet-stream watch.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "channel_layout.h"
#include "csv_export.h"
#include "decimate.h"
#include "number_format.h"
#include "plot_layout.h"
#include "sample_store.h"
#include "stream_watch.h"
#include "support/process.h"

namespace caliper::plotter {
namespace {

using testing::FileSizeLimit;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Appends samples t = first*dt ... with one value per series: value(series, i).
template <typename F>
void Fill(SampleStore* store, size_t first, size_t count, double dt, F value) {
  const size_t n = store->series_count();
  std::vector<double> times, data;
  std::vector<SampleStore::Column> columns;
  for (size_t s = 0; s < n; ++s) columns.push_back({s, s});
  for (size_t i = first; i < first + count; ++i) {
    times.push_back(static_cast<double>(i) * dt);
    for (size_t s = 0; s < n; ++s) data.push_back(value(s, i));
  }
  store->Append(times.data(), count, data.data(), n, columns);
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> f;
  std::istringstream in(line);
  for (std::string x; std::getline(in, x, ',');) f.push_back(x);
  return f;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

TEST(SampleStoreTest, KeepsTheNewestSamplesUpToItsCapacity) {
  SampleStore store(1000);
  store.AddSeries("a.x", "m");
  Fill(&store, 1, 2500, 0.001, [](size_t, size_t i) { return static_cast<double>(i); });
  ASSERT_EQ(store.size(), 1000u);
  EXPECT_EQ(store.samples_appended(), 2500u);
  EXPECT_EQ(store.samples_overwritten(), 1500u);
  // the oldest held is sample 1501, the newest 2500, in order across the ring's seam
  EXPECT_DOUBLE_EQ(store.value(0, 0), 1501.0);
  EXPECT_DOUBLE_EQ(store.value(0, 999), 2500.0);
  for (size_t i = 1; i < store.size(); ++i) {
    ASSERT_GT(store.time(i), store.time(i - 1)) << i;
    ASSERT_DOUBLE_EQ(store.value(0, i), store.value(0, i - 1) + 1) << i;
  }
  EXPECT_DOUBLE_EQ(store.first_time(), 1.501);
  EXPECT_DOUBLE_EQ(store.last_time(), 2.5);
}

TEST(SampleStoreTest, ShrinkingTheCapacityKeepsTheNewestAndGrowingKeepsAll) {
  SampleStore store(1000);
  store.AddSeries("a", "");
  Fill(&store, 1, 1700, 0.001, [](size_t, size_t i) { return static_cast<double>(i); });
  store.SetCapacity(300);
  ASSERT_EQ(store.size(), 300u);
  EXPECT_DOUBLE_EQ(store.value(0, 0), 1401.0);
  EXPECT_DOUBLE_EQ(store.value(0, 299), 1700.0);
  store.SetCapacity(5000);
  Fill(&store, 1701, 100, 0.001, [](size_t, size_t i) { return static_cast<double>(i); });
  ASSERT_EQ(store.size(), 400u);
  EXPECT_DOUBLE_EQ(store.value(0, 399), 1800.0);
  EXPECT_THROW(store.SetCapacity(0), std::invalid_argument);
  EXPECT_THROW(SampleStore(0), std::invalid_argument);
}

TEST(SampleStoreTest, IndexRangeFindsTheSamplesOfATimeWindow) {
  SampleStore store(500);
  store.AddSeries("a", "");
  Fill(&store, 1, 800, 0.01, [](size_t, size_t i) { return static_cast<double>(i); });
  // held: t = 3.01 .. 8.00 (ring wrapped)
  auto [first, last] = store.IndexRange(5.0, 6.0);
  EXPECT_DOUBLE_EQ(store.time(first), 5.0);
  EXPECT_DOUBLE_EQ(store.time(last - 1), 6.0);
  EXPECT_EQ(last - first, 101u);
  std::tie(first, last) = store.IndexRange(0.0, 3.5);
  EXPECT_EQ(first, 0u);
  EXPECT_DOUBLE_EQ(store.time(last - 1), 3.5);
  std::tie(first, last) = store.IndexRange(9.0, 10.0);
  EXPECT_EQ(first, last);
  std::tie(first, last) = store.IndexRange(6.0, 5.0);
  EXPECT_EQ(first, last);
}

TEST(SampleStoreTest, ATimeGoingBackStartsTheBufferAnewAndDuplicatesAreSkipped) {
  SampleStore store(100);
  store.AddSeries("a", "");
  Fill(&store, 1, 50, 0.001, [](size_t, size_t) { return 1.0; });
  const double again[] = {0.050, 0.051};
  const double values[] = {7, 8};
  auto r = store.Append(again, 2, values, 1, {{0, 0}});
  EXPECT_EQ(r.duplicates, 1u);
  EXPECT_EQ(r.appended, 1u);
  EXPECT_FALSE(r.rewound);
  EXPECT_EQ(store.size(), 51u);
  // a reset: t = 0.001 again
  const double rewound[] = {0.001, 0.002};
  r = store.Append(rewound, 2, values, 1, {{0, 0}});
  EXPECT_TRUE(r.rewound);
  EXPECT_EQ(store.rewinds(), 1u);
  ASSERT_EQ(store.size(), 2u);
  EXPECT_DOUBLE_EQ(store.value(0, 0), 7.0);
  EXPECT_DOUBLE_EQ(store.first_time(), 0.001);
}

TEST(SampleStoreTest, ClearDropsSamplesKeepsSeriesAndTheRingWorksAfterwards) {
  for (const size_t before : {30u, 250u}) {  // growing and full (wrapped) buffers
    SCOPED_TRACE(before);
    SampleStore store(100);
    store.AddSeries("a", "");
    Fill(&store, 1, before, 0.001, [](size_t, size_t i) { return static_cast<double>(i); });
    const uint64_t version = store.version();
    store.Clear();
    EXPECT_NE(store.version(), version);
    EXPECT_TRUE(store.empty());
    EXPECT_TRUE(std::isnan(store.last_time()));
    EXPECT_EQ(store.series_count(), 1u);
    Fill(&store, 1000, 150, 0.001, [](size_t, size_t i) { return static_cast<double>(i); });
    ASSERT_EQ(store.size(), 100u);
    for (size_t i = 0; i < store.size(); ++i) ASSERT_DOUBLE_EQ(store.value(0, i), 1050.0 + i);
  }
}

TEST(SampleStoreTest, ASeriesAddedLaterHasNaNForTheSamplesBefore) {
  SampleStore store(100);
  store.AddSeries("a", "m");
  Fill(&store, 1, 10, 0.1, [](size_t, size_t) { return 1.0; });
  EXPECT_EQ(store.AddSeries("a", ""), 0u) << "an existing key keeps its index";
  EXPECT_EQ(store.series(0).unit, "m") << "and its unit when none is given";
  const size_t b = store.AddSeries("b", "N");
  EXPECT_EQ(b, 1u);
  EXPECT_TRUE(std::isnan(store.value(b, 9)));
  const double t[] = {1.1};
  const double v[] = {3.0, 4.0};
  store.Append(t, 1, v, 2, {{0, 0}, {1, 1}});
  EXPECT_DOUBLE_EQ(store.value(b, 10), 4.0);
  EXPECT_THROW(store.Append(t, 1, v, 2, {{0, 2}}), std::invalid_argument);
  EXPECT_THROW(store.Append(t, 1, v, 2, {{5, 0}}), std::invalid_argument);
  EXPECT_TRUE(store.RemoveSeries("a"));
  EXPECT_FALSE(store.RemoveSeries("a"));
  EXPECT_EQ(store.Find("b"), 0);
  EXPECT_DOUBLE_EQ(store.value(0, 10), 4.0);
}

TEST(SampleStoreTest, StaleMarksASeriesAndChangesTheVersion) {
  SampleStore store(10);
  const size_t a = store.AddSeries("pendulum.angle", "rad");
  EXPECT_FALSE(store.series(a).stale);
  const uint64_t v0 = store.version();
  store.SetStale(a, true);
  EXPECT_TRUE(store.series(a).stale);
  EXPECT_GT(store.version(), v0);
  const uint64_t v1 = store.version();
  store.SetStale(a, true);
  EXPECT_EQ(store.version(), v1) << "no change, no new version";
  store.SetStale(a, false);
  EXPECT_FALSE(store.series(a).stale);
}

TEST(SampleStoreTest, KeysSplitIntoIdAndElementIndices) {
  EXPECT_EQ(SplitKey("a.b").id, "a.b");
  EXPECT_TRUE(SplitKey("a.b").indices.empty());
  const KeyParts v = SplitKey("arm.hand.position[2]");
  EXPECT_EQ(v.id, "arm.hand.position");
  EXPECT_EQ(v.indices, std::vector<unsigned>{2});
  const KeyParts m = SplitKey("arm.hand.rotation[1][0]");
  EXPECT_EQ(m.id, "arm.hand.rotation");
  EXPECT_EQ(m.indices, (std::vector<unsigned>{1, 0}));
  EXPECT_EQ(SplitKey("odd[x]").id, "odd[x]");
  EXPECT_EQ(ElementOffset(SplitKey("s"), 1, 1), 0);
  EXPECT_EQ(ElementOffset(SplitKey("v"), 3, 1), -1) << "a vector needs an index";
  EXPECT_EQ(ElementOffset(SplitKey("v[2]"), 3, 1), 2);
  EXPECT_EQ(ElementOffset(SplitKey("v[3]"), 3, 1), -1);
  EXPECT_EQ(ElementOffset(SplitKey("m[1][2]"), 3, 3), 5);
  EXPECT_EQ(ElementOffset(SplitKey("m[4]"), 3, 3), -1) << "a matrix needs two indices";
}

// ------------------------------------------------------------------------ thinning

TEST(DecimateTest, KeepsEverySampleWhenThereAreFewPerColumn) {
  SampleStore store(1000);
  store.AddSeries("a", "");
  Fill(&store, 0, 100, 0.01, [](size_t, size_t i) { return std::sin(0.1 * i); });
  DrawPoints p;
  Decimate(store, 0, 0.0, 0.99, 500, &p);
  ASSERT_EQ(p.t.size(), 100u);
  EXPECT_EQ(p.samples, 100u);
  for (size_t i = 0; i < 100; ++i) EXPECT_DOUBLE_EQ(p.v[i], std::sin(0.1 * i));
}

TEST(DecimateTest, AMillionPointsBecomeAboutTwoPerPixelKeepingEachColumnsMinAndMax) {
  constexpr size_t kN = 1'000'000;
  constexpr int kColumns = 1000;
  SampleStore store(kN);
  store.AddSeries("noisy", "N");
  // a slow sine with a one-sample spike up at 400,000 and down at 700,001
  Fill(&store, 0, kN, 1e-4, [](size_t, size_t i) {
    if (i == 400'000) return 50.0;
    if (i == 700'001) return -60.0;
    return std::sin(1e-5 * static_cast<double>(i));
  });
  DrawPoints p;
  const double t0 = store.first_time(), t1 = store.last_time();
  Decimate(store, 0, t0, t1, kColumns, &p);
  EXPECT_EQ(p.samples, kN);
  EXPECT_LE(p.t.size(), 2u * kColumns);
  EXPECT_GE(p.t.size(), 2u * kColumns - 10) << "about two points per pixel column";
  EXPECT_DOUBLE_EQ(p.v_max, 50.0);
  EXPECT_DOUBLE_EQ(p.v_min, -60.0);
  // the spikes survive at their own times
  bool up = false, down = false;
  for (size_t k = 0; k < p.t.size(); ++k) {
    if (p.v[k] == 50.0) up = std::abs(p.t[k] - 40.0) < 1e-9;
    if (p.v[k] == -60.0) down = std::abs(p.t[k] - 70.0001) < 1e-9;
  }
  EXPECT_TRUE(up);
  EXPECT_TRUE(down);
  // every column's min and max (over all samples) are exactly the min and max of its points
  const double scale = kColumns / (t1 - t0);
  auto column = [&](double t) { return std::min<long>(kColumns - 1, long((t - t0) * scale)); };
  std::vector<double> lo(kColumns, 1e300), hi(kColumns, -1e300);
  store.ForEach(0, 0, store.size(), [&](double t, double v) {
    lo[column(t)] = std::min(lo[column(t)], v);
    hi[column(t)] = std::max(hi[column(t)], v);
  });
  std::vector<double> plo(kColumns, 1e300), phi(kColumns, -1e300);
  for (size_t k = 0; k < p.t.size(); ++k) {
    plo[column(p.t[k])] = std::min(plo[column(p.t[k])], p.v[k]);
    phi[column(p.t[k])] = std::max(phi[column(p.t[k])], p.v[k]);
  }
  for (int c = 0; c < kColumns; ++c) {
    ASSERT_EQ(plo[c], lo[c]) << "column " << c;
    ASSERT_EQ(phi[c], hi[c]) << "column " << c;
  }
  for (size_t k = 1; k < p.t.size(); ++k) ASSERT_LT(p.t[k - 1], p.t[k]) << k;
}

TEST(DecimateTest, AddsTheNeighboursOutsideTheWindowAndSkipsNaN) {
  SampleStore store(100);
  store.AddSeries("a", "");
  Fill(&store, 0, 100, 0.1, [](size_t, size_t i) { return i == 50 ? kNaN : double(i); });
  DrawPoints p;
  Decimate(store, 0, 4.0, 6.0, 1000, &p);
  ASSERT_FALSE(p.t.empty());
  EXPECT_DOUBLE_EQ(p.t.front(), 3.9);
  EXPECT_DOUBLE_EQ(p.t.back(), 6.1);
  EXPECT_EQ(p.t.size(), 2u + 21u - 1u) << "the NaN at t = 5 is not drawn";
  for (double v : p.v) EXPECT_FALSE(std::isnan(v));
  EXPECT_DOUBLE_EQ(p.v_min, 40.0);
  EXPECT_DOUBLE_EQ(p.v_max, 60.0);
}

// ------------------------------------------------------------------------ CSV

TEST(CsvExportTest, WritesTimeAndOneColumnPerCurveWithUnitsAndEverySample) {
  SampleStore store(5000);
  store.AddSeries("pendulum.angle", "rad");
  store.AddSeries("motor.current", "A");
  store.AddSeries("motor.gear_ratio", "");
  Fill(&store, 1, 4321, 0.001, [](size_t s, size_t i) { return (s + 1) * 0.5 * i; });
  std::ostringstream out;
  EXPECT_EQ(WriteCsv(store, {0, 1, 2}, out), 4321u);
  const auto lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 4322u);
  EXPECT_EQ(lines[0], "time [s],pendulum.angle [rad],motor.current [A],motor.gear_ratio [-]");
  for (size_t r = 1; r < lines.size(); ++r) {
    const auto f = Fields(lines[r]);
    ASSERT_EQ(f.size(), 4u) << lines[r];
    ASSERT_DOUBLE_EQ(std::stod(f[0]), r * 0.001) << "exact round trip of the time";
    ASSERT_DOUBLE_EQ(std::stod(f[2]), 1.0 * r);
  }
  // a subset, in the order asked; NaN where a series has no value
  SampleStore late(10);
  late.AddSeries("a", "m");
  Fill(&late, 1, 2, 1.0, [](size_t, size_t) { return 1.0; });
  late.AddSeries("b", "m");
  std::ostringstream two;
  WriteCsv(late, {1, 0}, two);
  EXPECT_EQ(two.str(), "time [s],b [m],a [m]\n1,nan,1\n2,nan,1\n");
  EXPECT_THROW(WriteCsv(late, {2}, two), std::out_of_range);
}

TEST(CsvExportTest, AFileIsWrittenWholeOrTheOldOneStays) {
  SampleStore store(5000);
  store.AddSeries("pendulum.angle", "rad");
  Fill(&store, 1, 3000, 0.001, [](size_t, size_t i) { return 0.25 * i; });
  const std::string path = ::testing::TempDir() + "/plotter_export_test.csv";
  EXPECT_EQ(ExportCsvFile(store, {0}, path), 3000u);
  std::ostringstream expected;
  WriteCsv(store, {0}, expected);
  EXPECT_EQ(ReadText(path), expected.str());
  // a write that fails half way (as on a full disk) leaves the file as it was and says why
  WriteText(path, "the user's old data\n");
  {
    const FileSizeLimit limit(1000);
    try {
      ExportCsvFile(store, {0}, path);
      ADD_FAILURE() << "a write past the file size limit succeeded";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("cannot write " + path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(ReadText(path), "the user's old data\n");
  try {
    ExportCsvFile(store, {0}, "/nonexistent/dir/data.csv");
    ADD_FAILURE() << "wrote into a directory that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cannot write /nonexistent/dir/data.csv", 0), 0u)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());
}

TEST(NumberFormatTest, WritesTheShortestTextThatReadsBackTheSameDouble) {
  EXPECT_EQ(FormatNumber(0.1), "0.1");
  EXPECT_EQ(FormatNumber(-0.125), "-0.125");
  EXPECT_EQ(FormatNumber(86400), "86400");
  EXPECT_EQ(FormatNumber(1.0 / 3), "0.3333333333333333");
  EXPECT_EQ(FormatNumber(-std::numeric_limits<double>::quiet_NaN()), "nan");
  std::string line = "t=";
  AppendNumber(&line, 0.001);
  EXPECT_EQ(line, "t=0.001");
}

// ------------------------------------------------------------------------ layouts

Layout Example() {
  Layout l;
  l.window_s = 2.5;
  l.buffer_samples = 250'000;
  l.every_n_steps = 4;
  PlotSpec a;
  a.curves = {{"pendulum_tendon.pivot.position", CurveStyle::kLine, ""},
              {"pendulum_tendon.motor.current", CurveStyle::kScatter, "#d62728"}};
  PlotSpec b;
  b.autoscale = false;
  b.y_min = -0.125;
  b.y_max = 3.3;
  b.curves = {{"pendulum_tendon.pendulum.position[2]", CurveStyle::kLine, "#1f77b4"}};
  l.plots = {a, b};
  return l;
}

TEST(LayoutTest, SavesAndLoadsTheSameLayout) {
  const Layout l = Example();
  const std::string path = ::testing::TempDir() + "/plotter_layout_test.layout";
  SaveLayout(l, path);
  const Layout back = LoadLayout(path);
  EXPECT_EQ(back, l) << FormatLayout(back);
  EXPECT_EQ(ParseLayout(FormatLayout(l)), l);
  EXPECT_EQ(back.Keys(), (std::vector<std::string>{"pendulum_tendon.pivot.position",
                                                   "pendulum_tendon.motor.current",
                                                   "pendulum_tendon.pendulum.position[2]"}));
  std::remove(path.c_str());
  // defaults: 10 s window, a million samples, every step
  const Layout empty = ParseLayout("");
  EXPECT_EQ(empty.window_s, 10.0);
  EXPECT_EQ(empty.buffer_samples, 1'000'000u);
  EXPECT_EQ(empty.every_n_steps, 1u);
}

TEST(LayoutTest, KeepsARangeSetUnderAutoscale) {
  // the range was dropped on saving when autoscale was on (found by fuzzing the layout parser)
  const Layout l = ParseLayout("[plot]\nautoscale = true\ny_range = -5 5\ncurve = a.b line\n");
  ASSERT_EQ(l.plots.size(), 1u);
  EXPECT_EQ(l.plots[0].y_min, -5);
  EXPECT_EQ(ParseLayout(FormatLayout(l)), l) << FormatLayout(l);
  // the default range under autoscale is not written
  EXPECT_EQ(FormatLayout(ParseLayout("[plot]\n")).find("y_range"), std::string::npos);
}

TEST(LayoutTest, RejectsMalformedLayoutsNamingTheLine) {
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases = {
      {"window_s = 10\nwindow = 3\n", "f:2: unknown key 'window'"},
      {"window_s = -1\n", "f:1: window_s = -1 s is out of range"},
      {"window_s = abc\n", "f:1: window_s wants a number, not 'abc'"},
      {"buffer_samples = 10\n", "f:1: buffer_samples = 10 is out of range [100, 50000000]"},
      {"buffer_samples = 200000000\n",
       "f:1: buffer_samples = 200000000 is out of range [100, 50000000]"},
      {"every_n_steps = 0\n", "f:1: every_n_steps = 0 is out of range"},
      {"version = 2\n", "f:1: unsupported layout version 2"},
      {"curve = a\n", "f:1: curve before the first [plot]"},
      {"[plot]\ncurve = a dotted\n", "f:2: curve style 'dotted' is neither line nor scatter"},
      {"[plot]\ncurve = a line red\n", "f:2: curve colour 'red' is not #rrggbb"},
      {"[plot]\nautoscale = maybe\n", "f:2: autoscale wants true or false"},
      {"[plot]\nautoscale = false\n", "f:3: the last plot has autoscale = false but no y_range"},
      {"[plot]\ny_range = 2 1\n", "f:2: y_range wants MIN < MAX"},
      {"[plots]\n", "f:1: unknown section [plots]"},
      {"[plot]\njust words\n", "f:2: expected key = value"},
  };
  for (const auto& c : cases) {
    try {
      ParseLayout(c.text, "f");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const LayoutError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(c.message, 0), 0u)
          << "got: " << e.what() << "\nwanted: " << c.message;
    }
  }
  EXPECT_THROW(LoadLayout("/nonexistent/x.layout"), LayoutError);
  EXPECT_THROW(SaveLayout(Example(), "/nonexistent/x.layout"), LayoutError);
}

TEST(LayoutTest, RejectsABufferThatItsCurvesWouldMakeLargerThanTheMemoryBudget) {
  // 8 bytes for the time and for each curve per sample, 1 GiB for all
  EXPECT_EQ(BufferBytes(1000, 3), 32'000u);
  EXPECT_EQ(MaxBufferSamples(0), kMaxBuffer);
  EXPECT_EQ(MaxBufferSamples(1), kMaxBuffer);
  EXPECT_EQ(MaxBufferSamples(3), kBufferBudgetBytes / 32);
  EXPECT_EQ(MaxBufferSamples(100'000'000), kMinBuffer);
  EXPECT_EQ(BufferBudgetProblem(33'554'432, 3), "");
  EXPECT_EQ(BufferBudgetProblem(40'000'000, 3),
            "3 curves of 40000000 samples would need 1221 MiB, more than the 1024 MiB all "
            "buffers may take (at most 33554432 samples for 3 curves)");
  // two curves fit 40 million samples, three do not: the buffer_samples line is named
  const std::string two = "buffer_samples = 40000000\n[plot]\ncurve = a\ncurve = b\n";
  EXPECT_EQ(ParseLayout(two, "f").buffer_samples, 40'000'000u);
  try {
    ParseLayout(two + "curve = c\n", "f");
    ADD_FAILURE() << "a 1.28 GB buffer was accepted";
  } catch (const LayoutError& e) {
    EXPECT_EQ(std::string(e.what()),
              "f:1: buffer_samples: 3 curves of 40000000 samples would need 1221 MiB, more than "
              "the 1024 MiB all buffers may take (at most 33554432 samples for 3 curves)");
  }
  // the default buffer with very many curves: the last line is named
  std::string many = "[plot]\n";
  for (int k = 0; k < 200; ++k) many += "curve = c" + std::to_string(k) + "\n";
  try {
    ParseLayout(many, "f");
    ADD_FAILURE() << "200 curves of a million samples were accepted";
  } catch (const LayoutError& e) {
    EXPECT_EQ(
        std::string(e.what()).rfind("f:201: buffer_samples: 200 curves of 1000000 samples", 0), 0u)
        << e.what();
  }
}

TEST(LayoutTest, ASaveThatFailsLeavesTheOldFileAndSaysWhy) {
  const std::string path = ::testing::TempDir() + "/plotter_layout_failing.layout";
  WriteText(path, "# the user's layout\n");
  Layout big = Example();
  AddPlot(&big, std::vector<std::string>(40, "pendulum_tendon.some.rather.long.channel.id"));
  {
    const FileSizeLimit limit(200);
    try {
      SaveLayout(big, path);
      ADD_FAILURE() << "a write past the file size limit succeeded";
    } catch (const LayoutError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cannot write " + path, 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(ReadText(path), "# the user's layout\n");
  SaveLayout(big, path);
  EXPECT_EQ(LoadLayout(path), big);
  std::remove(path.c_str());
}

TEST(LayoutTest, IdsFromTheCommandLineMakeAPlot) {
  EXPECT_EQ(SplitIds(" a.b, c ,,d[1]"), (std::vector<std::string>{"a.b", "c", "d[1]"}));
  Layout l;
  AddPlot(&l, SplitIds("a,b"));
  AddPlot(&l, {});
  ASSERT_EQ(l.plots.size(), 1u);
  EXPECT_EQ(l.plots[0].curves.size(), 2u);
  EXPECT_EQ(l.plots[0].curves[1].key, "b");
}

// ------------------------------------------------------------------------ subscription layouts

std::vector<ChannelEntry> PendulumChannels() {
  return {{"p.pivot.position", "rad", 1, 1, false, ""},
          {"p.motor.current", "A", 1, 1, false, ""},
          {"p.pendulum.position", "m", 3, 1, false, ""},
          {"p.frame.rotation", "", 3, 3, false, ""}};
}

TEST(ChannelLayoutTest, LaysTheIdsOutOneAfterTheOtherWithTheirShapes) {
  const auto layout =
      LayoutOf({"p.pendulum.position", "p.motor.current", "p.frame.rotation"}, PendulumChannels());
  ASSERT_EQ(layout.size(), 3u);
  EXPECT_EQ(layout[0].offset, 0u);
  EXPECT_EQ(layout[1].offset, 3u);
  EXPECT_EQ(layout[1].unit, "A");
  EXPECT_EQ(layout[2].offset, 4u);
  EXPECT_EQ(layout[2].rows, 3u);
  EXPECT_EQ(Width(layout), 13u);
  EXPECT_THROW(LayoutOf({"p.nothing"}, PendulumChannels()), std::invalid_argument);
}

TEST(ChannelLayoutTest, AReloadThatGivesAnIdAnotherShapeOrUnitIsAChange) {
  const auto layout =
      LayoutOf({"p.pivot.position", "p.motor.current", "p.pendulum.position"}, PendulumChannels());
  EXPECT_EQ(LayoutChange(layout, PendulumChannels()), "");
  // the body and the hinge swap names: same width (5), the current moves from 1 to 3
  auto swapped = PendulumChannels();
  swapped[0] = {"p.pivot.position", "m", 3, 1, false, ""};
  swapped[2] = {"p.pendulum.position", "rad", 1, 1, false, ""};
  EXPECT_EQ(
      Width(LayoutOf({"p.pivot.position", "p.motor.current", "p.pendulum.position"}, swapped)),
      Width(layout));
  EXPECT_EQ(LayoutChange(layout, swapped),
            "p.pivot.position is 3x1 [m] now, was 1x1 [rad], "
            "p.pendulum.position is 1x1 [rad] now, was 3x1 [m]");
  // a unit alone
  auto milliamps = PendulumChannels();
  milliamps[1].unit = "mA";
  EXPECT_EQ(LayoutChange(layout, milliamps), "p.motor.current is 1x1 [mA] now, was 1x1 [A]");
  // an id the scene no longer has keeps its place (NaN): no change
  auto no_motor = PendulumChannels();
  no_motor.erase(no_motor.begin() + 1);
  EXPECT_EQ(LayoutChange(layout, no_motor), "");
}

TEST(ChannelLayoutTest, SaysWhyAMatrixOfMoreThan64ElementsGivesNoCurve) {
  EXPECT_EQ(WhyNotPlottable({"p.pivot.position", "rad", 1, 1, false, ""}), "");
  EXPECT_EQ(WhyNotPlottable({"p.frame.rotation", "", 3, 3, false, ""}), "");
  EXPECT_EQ(WhyNotPlottable({"p.wide", "", 1, 64, false, ""}), "");
  EXPECT_EQ(WhyNotPlottable({"p.contact.map", "N", 10, 10, false, ""}),
            "p.contact.map is 10x10: 100 values are too many to plot one curve each (at most 64)");
  EXPECT_EQ(WhyNotPlottable({"p.empty", "", 0, 3, false, ""}),
            "p.empty is 0x3: it has no values to plot");
}

// ------------------------------------------------------------------------ quiet streams

/// Wall times given in seconds from the test's start.
struct WallAt {
  using Clock = StreamWatch::Clock;
  Clock::time_point t0 = Clock::now();
  Clock::time_point operator()(double s) const {
    return t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
};

TEST(StreamWatchTest, WaitsLongerThanTheGapBetweenSparseSamples) {
  // every step: the configured silence; sparse samples: three intervals and a batch
  EXPECT_DOUBLE_EQ(QuietThreshold(2.0, 1, 0.001), 2.0);
  EXPECT_DOUBLE_EQ(QuietThreshold(2.0, 100, 0.001), 2.0);
  EXPECT_DOUBLE_EQ(QuietThreshold(2.0, 1000, 0.001), 4.0);
  EXPECT_DOUBLE_EQ(QuietThreshold(2.0, 5000, 0.001), 20.0);
  EXPECT_DOUBLE_EQ(QuietThreshold(0.5, 100, 0.002), 0.8);
}

TEST(StreamWatchTest, ASparseStreamThatDeliversIsNeverQuiet) {
  // one sample every 5 s of simulated time, the Model at real time
  const WallAt at;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  StreamWatch watch(2.0);
  watch.Start(0.0, 5000, at(0));
  // polls every 250 ms for 60 s; a sample at 5, 10, ... arrives 50 ms later
  double last_sample = nan;
  WallAt::Clock::time_point last_batch{};
  for (double t = 0.25; t <= 60; t += 0.25) {
    const double due = std::floor((t - 0.05) / 5) * 5;
    if (due >= 5 && (std::isnan(last_sample) || due > last_sample)) {
      last_sample = due;
      last_batch = at(due + 0.05);
    }
    ASSERT_FALSE(watch.Quiet(true, t, 0.001, last_sample, last_batch, at(t))) << "at " << t;
  }
  // the samples stop: quiet once 20 s of simulated and of wall time have passed without one
  EXPECT_FALSE(watch.Quiet(true, 74.0, 0.001, last_sample, last_batch, at(74.0)));
  EXPECT_TRUE(watch.Quiet(true, 80.5, 0.001, last_sample, last_batch, at(80.5)));
  EXPECT_NEAR(watch.quiet_for(), 25.5, 1e-9);
  // paused: never quiet
  EXPECT_FALSE(watch.Quiet(false, 90.0, 0.001, last_sample, last_batch, at(90.0)));
}

TEST(StreamWatchTest, ADenseStreamThatStopsIsQuietAfterTheSilenceAndAResetRestartsTheWatch) {
  const WallAt at;
  StreamWatch watch(2.0);
  watch.Start(1.0, 1, at(0));
  EXPECT_FALSE(watch.Quiet(true, 2.0, 0.001, 1.95, at(1.0), at(1.0)));
  EXPECT_FALSE(watch.Quiet(true, 3.9, 0.001, 1.95, at(1.0), at(2.9)));
  EXPECT_TRUE(watch.Quiet(true, 4.0, 0.001, 1.95, at(1.0), at(3.1)));
  // not while the wall clock says the last batch came a moment ago (a Model faster than real time)
  StreamWatch fast(2.0);
  fast.Start(0.0, 1, at(0));
  EXPECT_FALSE(fast.Quiet(true, 10.0, 0.001, 0.5, at(0.1), at(1.0)));
  // a reset: the simulated time went back, the watch starts from there
  EXPECT_FALSE(watch.Quiet(true, 0.5, 0.001, 1.95, at(1.0), at(3.2)));
  EXPECT_FALSE(watch.Quiet(true, 2.4, 0.001, 1.95, at(1.0), at(5.1)));
  EXPECT_TRUE(watch.Quiet(true, 2.6, 0.001, 1.95, at(1.0), at(5.3)));
}

TEST(StreamWatchTest, AProcessThatDidNotRunGivesItsStreamTheSilenceAgainBeforeItIsQuiet) {
  // the plotter stopped (SIGSTOP) for 5 s while the Model ran on: at its first poll after SIGCONT
  // the batches sent meanwhile are still unread in its sockets, so that poll must not count the
  // 5 s as silence (it would subscribe anew and the Model's retries of the old subscription, which
  // the batches answer, would be for nothing)
  const WallAt at;
  StreamWatch watch(2.0);
  watch.Start(0.0, 1, at(0));
  for (double t = 0.25; t <= 10; t += 0.25)
    ASSERT_FALSE(watch.Quiet(true, t, 0.001, t - 0.02, at(t - 0.01), at(t))) << "at " << t;
  // stopped from 10 to 15 s: the first poll after it sees no newer batch yet
  EXPECT_FALSE(watch.Quiet(true, 15.0, 0.001, 9.98, at(9.99), at(15.0)));
  EXPECT_DOUBLE_EQ(watch.quiet_for(), 0.0);
  // the batches come: never quiet
  EXPECT_FALSE(watch.Quiet(true, 15.25, 0.001, 15.2, at(15.1), at(15.25)));
  // they do not come: quiet once the silence passed again, counted from the poll after SIGCONT
  StreamWatch silent(2.0);
  silent.Start(0.0, 1, at(0));
  EXPECT_FALSE(silent.Quiet(true, 10.0, 0.001, 9.98, at(9.99), at(10.0)));  // a starved poll
  for (double t = 10.25; t < 12.0; t += 0.25)
    ASSERT_FALSE(silent.Quiet(true, t, 0.001, 9.98, at(9.99), at(t))) << "at " << t;
  EXPECT_TRUE(silent.Quiet(true, 12.25, 0.001, 9.98, at(9.99), at(12.25)));
  EXPECT_NEAR(silent.quiet_for(), 2.25, 1e-9);
  // the next cases: a stream whose last batch (t = 0.45 s) came at 0.46 s, polled at t; a poll
  // that started at `started` when given
  auto poll = [&](StreamWatch& w, double t, double started = -1) {
    if (started >= 0) w.PollStarts(at(started));
    return w.Quiet(true, t, 0.001, 0.45, at(0.46), at(t));
  };
  StreamWatch slow(2.0), calls(2.0), stopped(2.0);
  for (StreamWatch* w : {&slow, &calls, &stopped}) {
    w->Start(0.0, 1, at(0));
    EXPECT_FALSE(poll(*w, 0.5));
  }
  // a poll late by less than the silence (a slow status call) counts the time as silence
  EXPECT_FALSE(poll(slow, 2.3));
  EXPECT_TRUE(poll(slow, 4.0));
  // the gap runs to the start of a poll: two slow calls of a poll (2.2 s after a start 0.25 s
  // after the previous poll) are not time the process did not run, and the silence is seen
  EXPECT_TRUE(poll(calls, 2.95, 0.75));
  // and a poll that starts 5 s late still restarts the count
  EXPECT_FALSE(poll(stopped, 5.6, 5.5));
}

TEST(BatchSequenceTest, LeavesOutABatchThatComesAfterALaterOneAndCountsTheGaps) {
  BatchSequence seq;
  EXPECT_TRUE(seq.Take(1));
  EXPECT_TRUE(seq.Take(2));
  // pushes 3-5 timed out while the plotter was stopped; at SIGCONT the Model's next push (6) is
  // read before them
  EXPECT_TRUE(seq.Take(6));
  EXPECT_EQ(seq.missing(), 3u);
  EXPECT_FALSE(seq.Take(4));
  EXPECT_FALSE(seq.Take(3));
  EXPECT_FALSE(seq.Take(6));  // the same number again
  EXPECT_TRUE(seq.Take(7));
  EXPECT_EQ(seq.missing(), 3u);  // the late ones were counted missing when 6 came
  EXPECT_EQ(seq.late(), 3u);
  // a new subscription starts at 1 again; the counts go on
  seq.Restart();
  EXPECT_TRUE(seq.Take(1));
  EXPECT_TRUE(seq.Take(3));
  EXPECT_EQ(seq.missing(), 4u);
  EXPECT_EQ(seq.late(), 3u);
}

TEST(BatchSequenceTest, TakesANumberFarBelowAsNumberingAnewAndDoesNotWrap) {
  BatchSequence seq;
  const uint64_t far = BatchSequence::kLateBatches + 10;
  EXPECT_TRUE(seq.Take(far));  // the next is far + 1
  EXPECT_FALSE(seq.Take(11));  // kLateBatches below it: late
  EXPECT_TRUE(seq.Take(10));   // further: numbered anew from 10, nothing counted missing
  EXPECT_EQ(seq.late(), 1u);
  EXPECT_EQ(seq.missing(), far - 1);
  EXPECT_TRUE(seq.Take(11));
  // the last number there is: the next is not 0
  EXPECT_TRUE(seq.Take(UINT64_MAX));
  EXPECT_FALSE(seq.Take(UINT64_MAX - 1));
  EXPECT_TRUE(seq.Take(1));  // far below: numbered anew
  EXPECT_TRUE(seq.Take(2));
  EXPECT_FALSE(seq.Take(1));
}

}  // namespace
}  // namespace caliper::plotter
