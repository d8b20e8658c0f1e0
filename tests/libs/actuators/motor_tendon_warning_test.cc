// A dc_motor_tendon whose relaxed elastic element is longer than its path at load: the load logs
// a warning naming the actuator, the lengths in millimetres and what the negative line means, and
// the model behaves as the warning says (just taut, pulls as soon as the spool winds in).
#include <gtest/gtest.h>

#include <log4cpp/Category.hh>
#include <log4cpp/LoggingEvent.hh>
#include <log4cpp/Priority.hh>
#include <log4cpp/StringQueueAppender.hh>
#include <memory>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "caliper/logging/log.h"
#include "caliper/sgal/scene.h"

namespace caliper::actuators {
namespace {

// the events of one category at WARN and above, as "PRIORITY message"
class WarningCapture {
 public:
  WarningCapture() : category_(logging::Get("actuators")) {
    appender_ = new log4cpp::StringQueueAppender("capture");  // the category owns it
    category_.addAppender(appender_);
    category_.setPriority(log4cpp::Priority::WARN);
  }
  ~WarningCapture() { category_.removeAppender(appender_); }

  std::vector<std::string> Take() {
    std::vector<std::string> out;
    auto& queue = appender_->getQueue();
    for (; !queue.empty(); queue.pop()) out.push_back(queue.front());
    return out;
  }

 private:
  log4cpp::Category& category_;
  log4cpp::StringQueueAppender* appender_;
};

sgal::Actuator Motor(double rest_length_m, double pretension_n = 0) {
  sgal::Actuator a;
  a.name = "kite_motor";
  a.kind = "dc_motor_tendon";
  a.tendon = "kite";
  a.parameters["rest_length"] = rest_length_m;
  a.parameters["pretension"] = pretension_n;
  return a;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(DcMotorTendonWarning, RestLengthLongerThanThePathIsLoggedInMillimetres) {
  WarningCapture capture;
  auto motor = Make(Motor(0.1));
  EXPECT_TRUE(capture.Take().empty()) << "making the actuator is not a load";
  motor->Reset(0.075);
  const std::vector<std::string> warnings = capture.Take();
  ASSERT_EQ(warnings.size(), 1u);
  const std::string& w = warnings[0];
  EXPECT_TRUE(Contains(w, "WARN")) << w;
  EXPECT_TRUE(Contains(w, "caliper.process.actuators")) << w;
  EXPECT_TRUE(Contains(w, "actuator 'kite_motor' (dc_motor_tendon)")) << w;
  EXPECT_TRUE(Contains(w, "rest_length 100 mm")) << w;
  EXPECT_TRUE(Contains(w, "tendon path at load (75 mm)")) << w;
  EXPECT_TRUE(Contains(w, "the kite line starts at -25 mm")) << w;
  EXPECT_TRUE(Contains(w, "25 mm of the element counts as already wound on the spool")) << w;
  EXPECT_TRUE(Contains(w, "pulls as soon as the spool winds in")) << w;
  EXPECT_NEAR(motor->Get("line_length"), -0.025, 1e-12);
}

TEST(DcMotorTendonWarning, PretensionCountsInTheRelaxedLength) {
  WarningCapture capture;
  // 1000 N/m at 10 N: relaxed 60 mm, longer than the 55 mm path though the rest length is not
  auto motor = Make(Motor(0.05, 10));
  motor->Reset(0.055);
  const std::vector<std::string> warnings = capture.Take();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(Contains(warnings[0], "rest_length 50 mm, relaxed length 60 mm at pretension 10 N"))
      << warnings[0];
  EXPECT_TRUE(Contains(warnings[0], "starts at -5 mm")) << warnings[0];
}

TEST(DcMotorTendonWarning, APathLongerThanTheElementGivesNoWarning) {
  WarningCapture capture;
  auto motor = Make(Motor(0.1));
  motor->Reset(0.3);
  EXPECT_TRUE(capture.Take().empty());
  EXPECT_NEAR(motor->Get("line_length"), 0.2, 1e-12);
}

TEST(DcMotorTendonWarning, TheElementIsJustTautAndPullsOnceTheSpoolWindsIn) {
  auto motor = Make(Motor(0.1));
  motor->Reset(0.075);
  motor->SetTimeStep(1e-3);
  EXPECT_EQ(motor->Step(0.075, 0, 1e-3), 0.0) << "no command: no tension";
  motor->SetCommand(3);  // [V]
  double tension = 0;
  for (int i = 0; i < 5 && tension <= 0; ++i) tension = motor->Step(0.075, 0, 1e-3);
  EXPECT_GT(tension, 0) << "no slack to take up first";
  EXPECT_LT(motor->Get("line_length"), -0.025);
}

}  // namespace
}  // namespace caliper::actuators
