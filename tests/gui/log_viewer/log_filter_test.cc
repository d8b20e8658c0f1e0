// The viewer's filters on the known session: each alone and combined gives exactly the expected
// rows; highlighting keeps every row and marks exactly the matches; a bad or too long regular
// expression is reported with RE2's reason; appended records are classified like the others; a
// regular expression (RE2 syntax) searches a message of megabytes whole, without recursing, and
// hostile patterns answer at once.
#include "log_filter.h"

#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "known_session.h"
#include "session_file.h"

namespace caliper::log_viewer {
namespace {

namespace k = testing;

class LogFilterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    store_.Append(ReadSessionFile(k::KnownSessionPath()).records);
    view_.Apply(FilterSettings{}, store_);
  }

  // Rows shown under `s`.
  size_t Shown(const FilterSettings& s) {
    view_.Apply(s, store_);
    return view_.rows().size();
  }

  // The messages of the highlighted rows.
  std::vector<std::string> Highlighted() const {
    std::vector<std::string> out;
    for (size_t row = 0; row < view_.rows().size(); ++row)
      if (view_.highlighted(row)) out.push_back(store_.record(view_.rows()[row]).message);
    return out;
  }

  RecordStore store_;
  LogView view_;
};

TEST_F(LogFilterTest, NoFilterShowsEverythingAndHighlightsNothing) {
  EXPECT_EQ(view_.rows().size(), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.highlighted_count(), 0u);
  for (int kind = 0; kind < kFilterKinds; ++kind) EXPECT_FALSE(view_.active(FilterKind(kind)));
}

TEST_F(LogFilterTest, PriorityAlone) {
  FilterSettings s;
  s.max_priority = logging::kWarn;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kWarnOrWorse));
  s.max_priority = logging::kError;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kErrorOrWorse));
  s.max_priority = logging::kFatal;
  EXPECT_EQ(Shown(s), 1u);
  s.max_priority = logging::kInfo;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords - k::kDebugOnly));
  s.max_priority = logging::kDebug;  // everything: the filter is off
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_FALSE(view_.active(kPriority));
}

TEST_F(LogFilterTest, CategoryAloneExcludesWholeSubtreesOnly) {
  FilterSettings s;
  s.excluded_categories = {"caliper.model"};
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords - k::kModel0));
  s.excluded_categories = {"caliper.model.physics"};
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords - k::kModelPhysics));
  s.excluded_categories = {"caliper.model.physics", "caliper.model.daq"};
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords - k::kModelPhysics - k::kModelDaq));
  s.excluded_categories = {"caliper.mod"};  // not a whole segment: excludes nothing
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  s.excluded_categories = {"caliper"};
  EXPECT_EQ(Shown(s), 0u);
}

TEST_F(LogFilterTest, UnderCategoryFollowsDottedSegments) {
  EXPECT_TRUE(UnderCategory("caliper.model.rtc", "caliper.model"));
  EXPECT_TRUE(UnderCategory("caliper.model", "caliper.model"));
  EXPECT_FALSE(UnderCategory("caliper.modeller", "caliper.model"));
  EXPECT_FALSE(UnderCategory("caliper", "caliper.model"));
}

TEST_F(LogFilterTest, ComponentAlone) {
  FilterSettings s;
  s.excluded_components = {"model0"};
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords - k::kModel0));
  s.excluded_components = {"renderer0", "logger0"};
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kModel0 + k::kPd0));
}

TEST_F(LogFilterTest, TextAloneAsSubstringAndAsRegularExpression) {
  FilterSettings s;
  s.text = "tendon";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kTendonAnyCase));
  s.case_sensitive = true;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kTendonExactCase));
  s.case_sensitive = false;
  s.text = "TENDON";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kTendonAnyCase));
  s.text = "^step \\d+";
  EXPECT_EQ(Shown(s), 0u) << "as plain text it matches nothing";
  s.regex = true;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kStepRegex));
  s.text = "lost|disk full";
  EXPECT_EQ(Shown(s), 2u);
  // a tab inside a message is matched too
  s.text = "length\\tbiceps";
  EXPECT_EQ(Shown(s), 1u);
}

TEST_F(LogFilterTest, BadRegularExpressionIsReportedAndTurnsTheTextFilterOff) {
  FilterSettings s;
  s.regex = true;
  s.text = "(tendon";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_FALSE(view_.active(kText));
  EXPECT_EQ(view_.error(), "bad regular expression '(tendon': missing ): (tendon");
  s.text = "[a";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.error().rfind("bad regular expression '[a': ", 0), 0u) << view_.error();
  s.text = "tendon";  // fixed: the error goes away
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kTendonAnyCase));
  EXPECT_EQ(view_.error(), "");
  s.regex = false;  // the same text is fine as plain text
  s.text = "(tendon";
  EXPECT_EQ(Shown(s), 0u);
  EXPECT_EQ(view_.error(), "");
}

TEST_F(LogFilterTest, TimeAlone) {
  FilterSettings s;
  s.from_time_us = k::kKnownStartUs + 10000000;
  s.to_time_us = k::kKnownStartUs + 19999999;
  EXPECT_EQ(Shown(s), 10u);
  s.to_time_us = 0;
  EXPECT_EQ(Shown(s), 20u);
  s.from_time_us = 0;
  s.to_time_us = k::kKnownStartUs + 1007;  // exactly the first record: bounds are inclusive
  EXPECT_EQ(Shown(s), 1u);
}

TEST_F(LogFilterTest, FiltersCombine) {
  FilterSettings s;
  s.max_priority = logging::kWarn;
  s.excluded_components = {"renderer0", "logger0"};
  s.excluded_categories = {"caliper.model.daq"};
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kWarnModelPdNoDaq));
  s.from_time_us = k::kKnownStartUs + 10000000;
  s.to_time_us = k::kKnownStartUs + 19999999;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kWarnModelPdNoDaqInTime));
  s.text = "diverged";
  EXPECT_EQ(Shown(s), 1u);
  EXPECT_EQ(store_.record(view_.rows()[0]).message, "simulation diverged at t=1.234 s");
}

TEST_F(LogFilterTest, HighlightKeepsEveryRowAndMarksExactlyTheMatches) {
  FilterSettings s;
  s.text = "tendon";
  s.mode[kText] = FilterMode::kHighlight;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.highlighted_count(), static_cast<size_t>(k::kTendonAnyCase));
  EXPECT_EQ(Highlighted(),
            (std::vector<std::string>{
                "loaded scene arm26.dae: 12 bodies, 6 tendons", "tendon biceps slack for 20 steps",
                "Tendon triceps exceeded max force 900 N",
                "tendon length\tbiceps 0.31 m\nsecond line \\ with a backslash"}));
  // a hiding priority filter with it: the rows shrink, the highlights among them stay
  s.max_priority = logging::kWarn;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kWarnOrWorse));
  EXPECT_EQ(Highlighted(), (std::vector<std::string>{"tendon biceps slack for 20 steps",
                                                     "Tendon triceps exceeded max force 900 N"}));
  // two highlighting filters: rows matching both
  s.mode[kPriority] = FilterMode::kHighlight;
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.highlighted_count(), 2u);
  // highlighting by component: the checked components' rows
  FilterSettings c;
  c.excluded_components = {"model0", "renderer0", "logger0"};
  c.mode[kComponent] = FilterMode::kHighlight;
  EXPECT_EQ(Shown(c), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.highlighted_count(), static_cast<size_t>(k::kPd0));
}

TEST_F(LogFilterTest, AppendedRecordsAreClassifiedLikeTheOthers) {
  FilterSettings s;
  s.max_priority = logging::kWarn;
  s.text = "tendon";
  s.mode[kText] = FilterMode::kHighlight;
  s.excluded_categories = {"caliper.model.daq"};
  view_.Apply(s, store_);
  ASSERT_EQ(view_.rows().size(), 8u);  // 9 warn or worse, one of them in caliper.model.daq
  auto make = [](uint64_t seq, int priority, const std::string& category, const std::string& msg) {
    logging::Record r;
    r.source = "live:1:1";
    r.seq = seq;
    r.priority = priority;
    r.category = category;
    r.component = "model1";  // a component not seen before
    r.message = msg;
    return r;
  };
  store_.Append({make(1, logging::kError, "caliper.model.physics", "tendon snapped"),
                 make(2, logging::kInfo, "caliper.model.physics", "tendon ok"),
                 make(3, logging::kError, "caliper.model.daq", "tendon channel lost"),
                 make(4, logging::kError, "caliper.sample.new", "a new category")});
  EXPECT_EQ(view_.Update(store_), 2u);
  EXPECT_EQ(view_.rows().size(), 10u);
  EXPECT_EQ(view_.highlighted_count(), 3u);
  EXPECT_EQ(view_.Update(store_), 0u) << "nothing new";
  // the same result as classifying everything at once
  LogView fresh;
  fresh.Apply(s, store_);
  EXPECT_EQ(fresh.rows(), view_.rows());
  EXPECT_EQ(fresh.highlighted_count(), view_.highlighted_count());
}

TEST_F(LogFilterTest, ChangingOneFilterKeepsTheOthers) {
  FilterSettings s;
  s.text = "model0";
  s.regex = true;
  EXPECT_EQ(Shown(s), 5u);
  s.max_priority = logging::kError;  // only the priority bit is recomputed
  EXPECT_EQ(Shown(s), 1u);           // "lost model0: TRANSIENT (connect failed)"
  s.max_priority = logging::kDebug;
  EXPECT_EQ(Shown(s), 5u);
  view_.Reset();
  EXPECT_TRUE(view_.rows().empty());
  EXPECT_EQ(view_.Update(store_), 5u);
}

TEST_F(LogFilterTest, RegularExpressionsMatchLikeStdRegexOnEveryMessage) {
  // patterns of both syntaxes match what they matched as ECMAScript: saved filters keep their
  // meaning
  store_.Append({[] {
    logging::Record r;
    r.message = "ab cd TENDON Slack For 12 steps; step 9: ok";
    return r;
  }()});
  for (const char* pattern :
       {"tendon", "^step \\d+", "model0 (bound|reset)", "ste?p", "\\bfor\\b", "Tendon.*N$",
        "slack for [0-9]+ steps", "(lost|disk) [a-z]+", "x*", "s{2}", "max force [0-9]{3} N"}) {
    for (bool case_sensitive : {false, true}) {
      FilterSettings s;
      s.text = pattern;
      s.regex = true;
      s.case_sensitive = case_sensitive;
      auto flags = std::regex::ECMAScript;
      if (!case_sensitive) flags |= std::regex::icase;
      const std::regex re(pattern, flags);
      size_t expected = 0;
      for (size_t i = 0; i < store_.size(); ++i)
        expected += std::regex_search(store_.record(i).message, re) ? 1 : 0;
      EXPECT_EQ(Shown(s), expected) << pattern << (case_sensitive ? " (case)" : "");
    }
  }
}

TEST_F(LogFilterTest, RegularExpressionsSearchHugeMessagesWhole) {
  // std::regex's default matcher recursed once per character here and overflowed the stack
  logging::Record huge;
  huge.source = "huge";
  huge.seq = 1;
  for (int i = 0; i < (1 << 19); ++i) huge.message += "ab";  // 1 MiB
  logging::Record needle_far_in = huge;
  needle_far_in.seq = 2;
  needle_far_in.message = std::string(1 << 20, 'x') + " needle";
  store_.Append({huge, needle_far_in});
  FilterSettings s;
  s.regex = true;
  s.text = "^(a|b)*";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords + 2))
      << "every message matches, the huge one too";
  EXPECT_TRUE(view_.error().empty()) << view_.error();
  s.text = "^(a|b)*$";
  EXPECT_EQ(Shown(s), 1u) << "only the huge one is all a and b";
  s.text = "(a|b)*c";  // any message with a c (any case) in it, not the huge one
  size_t with_c = 0;
  for (size_t i = 0; i < store_.size(); ++i)
    with_c += store_.record(i).message.find_first_of("cC") != std::string::npos ? 1 : 0;
  EXPECT_EQ(Shown(s), with_c);
  // a match a megabyte into a message is found, as plain text is
  s.text = "x need+le$";
  EXPECT_EQ(Shown(s), 1u);
  s.regex = false;
  s.text = "needle";
  EXPECT_EQ(Shown(s), 1u);
}

TEST_F(LogFilterTest, NestedQuantifiersAnswerAtOnce) {
  // exponential backtracking with std::regex (more than 30 s for 20 letters)
  logging::Record aaa;
  aaa.source = "aaa";
  aaa.seq = 1;
  aaa.message = std::string(20, 'a');
  store_.Append({aaa});
  FilterSettings s;
  s.regex = true;
  s.case_sensitive = true;
  s.text = "^(a*)*b";
  EXPECT_EQ(Shown(s), 0u);
  s.text = "^(a*)*$";
  EXPECT_EQ(Shown(s), 1u);
}

TEST_F(LogFilterTest, Re2SyntaxAndItsBounds) {
  FilterSettings s;
  s.regex = true;
  s.case_sensitive = true;
  s.text = "(?i)TENDON";  // RE2's inline flag
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kTendonAnyCase));
  // backreferences and lookaround are not RE2: reported, the filter off
  s.text = "(tendon) \\1";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.error(), "bad regular expression '(tendon) \\1': invalid escape sequence: \\1");
  s.text = "tendon(?= biceps)";
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.error(),
            "bad regular expression 'tendon(?= biceps)': invalid perl operator: (?=");
  s.text = std::string(logging::kMaxPatternBytes + 1, 't');
  EXPECT_EQ(Shown(s), static_cast<size_t>(k::kKnownRecords));
  EXPECT_EQ(view_.error(),
            "regular expression too long: " + std::to_string(logging::kMaxPatternBytes + 1) +
                " bytes, at most " + std::to_string(logging::kMaxPatternBytes));
  EXPECT_FALSE(view_.active(kText));
}

TEST_F(LogFilterTest, ModeNamesRoundTrip) {
  FilterMode m = FilterMode::kHide;
  EXPECT_TRUE(ParseMode(ModeName(FilterMode::kHighlight), &m));
  EXPECT_EQ(m, FilterMode::kHighlight);
  EXPECT_TRUE(ParseMode("hide", &m));
  EXPECT_EQ(m, FilterMode::kHide);
  EXPECT_FALSE(ParseMode("show", &m));
}

}  // namespace
}  // namespace caliper::log_viewer
