#include "caliper/logging/record.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <vector>
#include <string>

namespace caliper::logging {
namespace {

Record Sample() {
  Record r;
  r.time_us = 1700000000123456;  // 2023-11-14T22:13:20.123456Z
  r.priority = kWarn;
  r.category = "caliper.model.physics";
  r.component = "model0";
  r.host = "node7";
  r.pid = 4242;
  r.source = "node7:4242:1700000000000000";
  r.seq = 17;
  r.message = "joint 3 above limit";
  return r;
}


TEST(RecordTest, FormatsOneTabSeparatedLineInUtc) {
  EXPECT_EQ(FormatLine(Sample()),
            "2023-11-14T22:13:20.123456Z\tWARN\tcaliper.model.physics\tmodel0\tnode7\t4242\t"
            "node7:4242:1700000000000000\t17\tjoint 3 above limit");
}

TEST(RecordTest, PadsMicroseconds) {
  Record r = Sample();
  r.time_us = 1700000000000007;
  EXPECT_EQ(FormatLine(r).substr(0, 28), "2023-11-14T22:13:20.000007Z\t");
}

TEST(RecordTest, EqualityComparesEveryField) {
  const Record a = Sample();
  EXPECT_EQ(a, Sample());
  const std::vector<std::function<void(Record*)>> changes = {
      [](Record* r) { r->time_us += 1; },      [](Record* r) { r->priority = kError; },
      [](Record* r) { r->category += "x"; },   [](Record* r) { r->component += "x"; },
      [](Record* r) { r->host += "x"; },       [](Record* r) { r->pid += 1; },
      [](Record* r) { r->source += "x"; },     [](Record* r) { r->seq += 1; },
      [](Record* r) { r->message += "x"; }};
  for (size_t i = 0; i < changes.size(); ++i) {
    Record b = Sample();
    changes[i](&b);
    EXPECT_NE(a, b) << "field " << i;
  }
}

TEST(RecordTest, RoundTripsAPlainRecord) {
  Record parsed;
  ASSERT_TRUE(ParseLine(FormatLine(Sample()), &parsed));
  EXPECT_EQ(parsed, Sample());
}

TEST(RecordTest, TimeStampsRoundTripOverCenturiesAndLeapDays) {
  // the parser computes the calendar itself: it must agree with the C library's formatter
  Record r = Sample();
  for (int64_t t = 0; t < int64_t{4102444800} * 1000000; t += int64_t{133337} * 1000000 + 654321) {
    r.time_us = t;
    Record parsed;
    ASSERT_TRUE(ParseLine(FormatLine(r), &parsed)) << FormatLine(r);
    ASSERT_EQ(parsed.time_us, t) << FormatLine(r);
  }
  r.time_us = -1500000;  // before 1970: the second below and positive microseconds
  EXPECT_EQ(FormatLine(r).substr(0, 27), "1969-12-31T23:59:58.500000Z");
  Record before;
  ASSERT_TRUE(ParseLine(FormatLine(r), &before));
  EXPECT_EQ(before.time_us, -1500000);
  for (const char* stamp : {"2000-02-29T23:59:59.999999Z", "2100-03-01T00:00:00.000000Z",
                            "1970-01-01T00:00:00.000000Z", "2024-12-31T12:00:00.500000Z"}) {
    Record parsed;
    const std::string line = std::string(stamp) + "\tINFO\tc\tm\th\t1\ts\t1\tx";
    ASSERT_TRUE(ParseLine(line, &parsed)) << stamp;
    EXPECT_EQ(FormatLine(parsed).substr(0, 27), stamp);
  }
}

TEST(RecordTest, WritesFourDigitsOfYearBeforeTheYear1000) {
  // strftime's %Y wrote the year 433 as "433", which ParseLine refuses (found by fuzzing the
  // session file reader: a record it read did not read back once exported)
  Record r;
  ASSERT_TRUE(ParseLine("0433-03-05T10:00:12.013007Z\tDEBUG\tc\tx\th\t1\th:1:1\t4\tm", &r));
  EXPECT_EQ(FormatLine(r).substr(0, 28), "0433-03-05T10:00:12.013007Z\t");
  Record back;
  ASSERT_TRUE(ParseLine(FormatLine(r), &back));
  EXPECT_EQ(back, r);
}

TEST(RecordTest, RoundTripsTabsNewlinesAndBackslashes) {
  Record r = Sample();
  r.message = "a\tb\nc\\d\\\\e\r\nf\\t literal \\n end\\";
  r.category = "cat\twith\ttabs";
  r.component = "comp\nnewline";
  r.host = "back\\slash";
  r.source = "src\t\n\\";
  const std::string line = FormatLine(r);
  // the line stays one line of exactly nine fields
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_EQ(line.find('\r'), std::string::npos);
  EXPECT_EQ(std::count(line.begin(), line.end(), '\t'), 8);
  EXPECT_NE(line.find("a\\tb\\nc\\\\d"), std::string::npos) << line;
  Record parsed;
  ASSERT_TRUE(ParseLine(line, &parsed));
  EXPECT_EQ(parsed, r);
}

TEST(RecordTest, RoundTripsEmptyFields) {
  Record r;
  r.time_us = 0;
  r.seq = 1;
  Record parsed;
  ASSERT_TRUE(ParseLine(FormatLine(r), &parsed));
  EXPECT_EQ(parsed, r);
}

TEST(RecordTest, RoundTripsEveryNamedPriority) {
  for (int p : {kFatal, kAlert, kCrit, kError, kWarn, kNotice, kInfo, kDebug}) {
    Record r = Sample();
    r.priority = p;
    Record parsed;
    ASSERT_TRUE(ParseLine(FormatLine(r), &parsed));
    EXPECT_EQ(parsed.priority, p);
  }
}

TEST(RecordTest, RejectsCommentAndEmptyLines) {
  Record r;
  EXPECT_FALSE(ParseLine("", &r));
  EXPECT_FALSE(ParseLine("# caliper session log", &r));
  EXPECT_FALSE(ParseLine("#" + FormatLine(Sample()), &r));
}

TEST(RecordTest, RejectsLineTornBeforeTheMessage) {
  const std::string line = FormatLine(Sample());
  const size_t message_start = line.rfind('\t') + 1;
  for (size_t n = 0; n < message_start; ++n) {
    Record r;
    EXPECT_FALSE(ParseLine(line.substr(0, n), &r)) << "cut at " << n << ": " << line.substr(0, n);
  }
}

TEST(RecordTest, RejectsMalformedFields) {
  const std::string good = FormatLine(Sample());
  auto with_field = [&](int index, const std::string& value) {
    std::string line = good;
    size_t start = 0;
    for (int i = 0; i < index; ++i) start = line.find('\t', start) + 1;
    const size_t end = line.find('\t', start);
    return line.replace(start, end - start, value);
  };
  Record r;
  ASSERT_TRUE(ParseLine(with_field(1, "error"), &r));  // priority names in any case
  EXPECT_EQ(r.priority, kError);
  ASSERT_TRUE(ParseLine(with_field(1, "350"), &r));  // or a number
  EXPECT_EQ(r.priority, 350);
  EXPECT_FALSE(ParseLine(with_field(0, "yesterday"), &r));
  EXPECT_FALSE(ParseLine(with_field(5, ""), &r)) << "an empty pid";
  EXPECT_FALSE(ParseLine(with_field(5, "-3"), &r)) << "a signed pid";
  EXPECT_FALSE(ParseLine(with_field(5, " 42"), &r)) << "a padded pid";
  EXPECT_FALSE(ParseLine(with_field(7, "-1"), &r)) << "a negative seq would wrap";
  EXPECT_FALSE(ParseLine(with_field(7, "18446744073709551616"), &r)) << "seq past 2^64";
  for (const char* stamp : {"2023-02-29T10:00:00.000000Z", "2023-04-31T10:00:00.000000Z",
                            "2100-02-29T10:00:00.000000Z", "2023-13-14T22:13:20.123456Z",
                            "2023-11-14T24:13:20.123456Z",
                            "2023-11-14 22:13:20.123456Z", "2023-11-14T22:13:20.12345Z",
                            "2023-11-14T22:13:20.1234567Z", "2023-11-1xT22:13:20.123456Z",
                            "2023-11-14T22:13:20.123456"})
    EXPECT_FALSE(ParseLine(with_field(0, stamp), &r)) << stamp;
  EXPECT_FALSE(ParseLine(with_field(1, "LOUD"), &r));
  EXPECT_FALSE(ParseLine(with_field(5, "12x"), &r));
  EXPECT_FALSE(ParseLine(with_field(7, ""), &r));
  EXPECT_FALSE(ParseLine(with_field(7, "3a"), &r));
}

TEST(PriorityTest, NamesEachLevel) {
  EXPECT_EQ(PriorityName(kFatal), "FATAL");
  EXPECT_EQ(PriorityName(kAlert), "ALERT");
  EXPECT_EQ(PriorityName(kCrit), "CRIT");
  EXPECT_EQ(PriorityName(kError), "ERROR");
  EXPECT_EQ(PriorityName(kWarn), "WARN");
  EXPECT_EQ(PriorityName(kNotice), "NOTICE");
  EXPECT_EQ(PriorityName(kInfo), "INFO");
  EXPECT_EQ(PriorityName(kDebug), "DEBUG");
}

TEST(PriorityTest, NamesInBetweenPrioritiesByTheNextLessSevereLevel) {
  EXPECT_EQ(PriorityName(350), "WARN");
  EXPECT_EQ(PriorityName(601), "DEBUG");
  EXPECT_EQ(PriorityName(800), "DEBUG");
}

TEST(PriorityTest, ParsesNamesInAnyCaseAndNumbers) {
  int p = -1;
  ASSERT_TRUE(ParsePriority("fatal", &p));
  EXPECT_EQ(p, kFatal);
  ASSERT_TRUE(ParsePriority("Notice", &p));
  EXPECT_EQ(p, kNotice);
  ASSERT_TRUE(ParsePriority("DEBUG", &p));
  EXPECT_EQ(p, kDebug);
  ASSERT_TRUE(ParsePriority("warning", &p));
  EXPECT_EQ(p, kWarn);
  ASSERT_TRUE(ParsePriority("450", &p));
  EXPECT_EQ(p, 450);
}

TEST(PriorityTest, RejectsUnknownText) {
  int p = 123;
  EXPECT_FALSE(ParsePriority("", &p));
  EXPECT_FALSE(ParsePriority("verbose", &p));
  EXPECT_FALSE(ParsePriority("4x", &p));
  EXPECT_EQ(p, 123);  // untouched on failure
}

}  // namespace
}  // namespace caliper::logging
