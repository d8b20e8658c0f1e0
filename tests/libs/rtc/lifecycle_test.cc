#include "caliper/rtc/lifecycle.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_component.h"

namespace caliper::rtc {
namespace {

using testing::Hook;
using testing::TestComponent;
using Strings = std::vector<std::string>;

class LifecycleTest : public ::testing::Test {
 protected:
  void ToInactive() {
    ASSERT_EQ(lifecycle_.Initialize(), ReturnCode::kOk);
    ASSERT_EQ(lifecycle_.state(), State::kInactive);
  }
  void ToActive() {
    ToInactive();
    ASSERT_EQ(lifecycle_.Activate(), ReturnCode::kOk);
    ASSERT_EQ(lifecycle_.state(), State::kActive);
  }
  void ToError() {
    ToActive();
    component_.Fail(testing::kExecute);
    lifecycle_.Execute();
    component_.Succeed(testing::kExecute);
    ASSERT_EQ(lifecycle_.state(), State::kError);
    ASSERT_EQ(component_.count(testing::kAborting), 1);
  }
  /// The number of hook calls so far.
  size_t Calls() const { return component_.calls().size(); }

  TestComponent component_;
  Lifecycle lifecycle_{&component_, "test"};
};

TEST(ReturnCodeTest, NamesCodesAsInTheIdl) {
  EXPECT_STREQ(ToString(ReturnCode::kOk), "RTC_OK");
  EXPECT_STREQ(ToString(ReturnCode::kError), "RTC_ERROR");
  EXPECT_STREQ(ToString(ReturnCode::kBadParameter), "BAD_PARAMETER");
  EXPECT_STREQ(ToString(ReturnCode::kUnsupported), "UNSUPPORTED");
  EXPECT_STREQ(ToString(ReturnCode::kOutOfResources), "OUT_OF_RESOURCES");
  EXPECT_STREQ(ToString(ReturnCode::kPreconditionNotMet), "PRECONDITION_NOT_MET");
}

TEST(StateTest, NamesStates) {
  EXPECT_STREQ(ToString(State::kCreated), "CREATED");
  EXPECT_STREQ(ToString(State::kInactive), "INACTIVE");
  EXPECT_STREQ(ToString(State::kActive), "ACTIVE");
  EXPECT_STREQ(ToString(State::kError), "ERROR");
}

// --- normal transitions

TEST_F(LifecycleTest, StartsCreatedWithoutCallingHooks) {
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  EXPECT_FALSE(lifecycle_.finalized());
  EXPECT_EQ(lifecycle_.last_error(), "");
  EXPECT_EQ(Calls(), 0u);
}

TEST_F(LifecycleTest, InitializeMovesToInactive) {
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  EXPECT_EQ(component_.calls(), Strings{"on_initialize"});
}

TEST_F(LifecycleTest, ActivateAndDeactivateMoveBetweenInactiveAndActive) {
  ToInactive();
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.calls(),
            (Strings{"on_initialize", "on_activated", "on_deactivated", "on_activated"}));
  EXPECT_EQ(lifecycle_.last_error(), "");
}

TEST_F(LifecycleTest, ExecuteWhileActiveRunsExecuteThenStateUpdate) {
  ToActive();
  lifecycle_.Execute();
  lifecycle_.Execute();
  EXPECT_EQ(component_.calls(), (Strings{"on_initialize", "on_activated", "on_execute",
                                         "on_state_update", "on_execute", "on_state_update"}));
  EXPECT_EQ(lifecycle_.state(), State::kActive);
}

TEST_F(LifecycleTest, ExecuteOutsideActiveRunsNothing) {
  lifecycle_.Execute();  // CREATED
  ToInactive();
  lifecycle_.Execute();  // INACTIVE
  EXPECT_EQ(component_.count(testing::kExecute), 0);
  EXPECT_EQ(component_.count(testing::kStateUpdate), 0);
  EXPECT_EQ(component_.count(testing::kOnError), 0);
}

TEST_F(LifecycleTest, ResetFromErrorMovesToInactive) {
  ToError();
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  EXPECT_EQ(component_.count(testing::kReset), 1);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kOk);  // usable again
  lifecycle_.Execute();
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.count(testing::kStateUpdate), 1);
}

TEST_F(LifecycleTest, FinalizeFromInactiveEndsTheComponent) {
  ToInactive();
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kOk);
  EXPECT_TRUE(lifecycle_.finalized());
  EXPECT_EQ(component_.count(testing::kFinalize), 1);
}

TEST_F(LifecycleTest, FinalizeFromErrorIsAllowed) {
  ToError();
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kOk);
  EXPECT_TRUE(lifecycle_.finalized());
  EXPECT_EQ(component_.count(testing::kFinalize), 1);
}

TEST_F(LifecycleTest, StartupShutdownAndRateChangedRunTheirHooks) {
  ToActive();
  EXPECT_EQ(lifecycle_.Startup(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.RateChanged(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.Shutdown(), ReturnCode::kOk);
  EXPECT_EQ(component_.count(testing::kStartup), 1);
  EXPECT_EQ(component_.count(testing::kRateChanged), 1);
  EXPECT_EQ(component_.count(testing::kShutdown), 1);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
}

// --- preconditions: kPreconditionNotMet, no hook called, state unchanged

TEST_F(LifecycleTest, RejectsInitializeTwice) {
  ToInactive();
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  EXPECT_EQ(component_.count(testing::kInitialize), 1);
}

TEST_F(LifecycleTest, RejectsInitializeWhileActive) {
  ToActive();
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.count(testing::kInitialize), 1);
}

TEST_F(LifecycleTest, RejectsActivateFromCreated) {
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  EXPECT_EQ(Calls(), 0u);
}

TEST_F(LifecycleTest, RejectsActivateWhileActive) {
  ToActive();
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.count(testing::kActivated), 1);
}

TEST_F(LifecycleTest, RejectsActivateFromError) {
  ToError();
  const size_t calls = Calls();
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(Calls(), calls);
}

TEST_F(LifecycleTest, RejectsDeactivateOutsideActive) {
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kPreconditionNotMet);  // CREATED
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  ToInactive();
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  EXPECT_EQ(component_.count(testing::kDeactivated), 0);
}

TEST_F(LifecycleTest, RejectsDeactivateFromError) {
  ToError();
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kDeactivated), 0);
}

TEST_F(LifecycleTest, RejectsResetOutsideError) {
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  ToInactive();
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  ASSERT_EQ(lifecycle_.Activate(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.count(testing::kReset), 0);
}

TEST_F(LifecycleTest, RejectsFinalizeBeforeInitialize) {
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kPreconditionNotMet);
  EXPECT_FALSE(lifecycle_.finalized());
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  EXPECT_EQ(component_.count(testing::kFinalize), 0);
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kOk);  // still possible
}

TEST_F(LifecycleTest, RejectsFinalizeWhileActive) {
  ToActive();
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kPreconditionNotMet);
  EXPECT_FALSE(lifecycle_.finalized());
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.count(testing::kFinalize), 0);
}

TEST_F(LifecycleTest, RejectsExecutionContextEventsBeforeInitialize) {
  EXPECT_EQ(lifecycle_.Startup(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Shutdown(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.RateChanged(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(Calls(), 0u);
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
}

TEST_F(LifecycleTest, RejectsEverythingAfterFinalize) {
  ToInactive();
  ASSERT_EQ(lifecycle_.Finalize(), ReturnCode::kOk);
  const State after = lifecycle_.state();
  const size_t calls = Calls();

  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Startup(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Shutdown(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.RateChanged(), ReturnCode::kPreconditionNotMet);
  lifecycle_.Execute();

  EXPECT_EQ(lifecycle_.state(), after);
  EXPECT_TRUE(lifecycle_.finalized());
  EXPECT_EQ(Calls(), calls);  // no hook ran
}

TEST_F(LifecycleTest, RejectsEverythingAfterFinalizeFromError) {
  ToError();
  ASSERT_EQ(lifecycle_.Finalize(), ReturnCode::kOk);
  const State after = lifecycle_.state();
  const size_t calls = Calls();
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kPreconditionNotMet);
  lifecycle_.Execute();  // would run on_error in ERROR
  EXPECT_EQ(lifecycle_.state(), after);
  EXPECT_EQ(Calls(), calls);
}

// --- failing hooks

TEST_F(LifecycleTest, FailingInitializeStaysCreated) {
  component_.Fail(testing::kInitialize);
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  EXPECT_EQ(lifecycle_.last_error(), "on_initialize returned RTC_ERROR");
  EXPECT_EQ(component_.count(testing::kAborting), 0);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kPreconditionNotMet);

  component_.Succeed(testing::kInitialize);  // a later attempt may succeed
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
}

TEST_F(LifecycleTest, ThrowingInitializeStaysCreated) {
  component_.Throw(testing::kInitialize);
  EXPECT_EQ(lifecycle_.Initialize(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kCreated);
  EXPECT_EQ(lifecycle_.last_error(), "on_initialize threw: on_initialize exploded");
}

TEST_F(LifecycleTest, FailingActivateEntersErrorAndAbortsOnce) {
  ToInactive();
  component_.Fail(testing::kActivated);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_activated returned RTC_ERROR");
  EXPECT_EQ(component_.calls(), (Strings{"on_initialize", "on_activated", "on_aborting"}));
}

TEST_F(LifecycleTest, FailingActivatePassesOnItsReturnCode) {
  ToInactive();
  component_.Fail(testing::kActivated, ReturnCode::kOutOfResources);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kOutOfResources);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(lifecycle_.last_error(), "on_activated returned OUT_OF_RESOURCES");
}

TEST_F(LifecycleTest, ThrowingActivateEntersErrorNamingHookAndException) {
  ToInactive();
  component_.Throw(testing::kActivated);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_activated threw: on_activated exploded");
}

TEST_F(LifecycleTest, ThrowingSomethingElseEntersErrorToo) {
  ToInactive();
  component_.ThrowUnknown(testing::kActivated);
  EXPECT_EQ(lifecycle_.Activate(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(lifecycle_.last_error(), "on_activated threw an unknown exception");
}

TEST_F(LifecycleTest, FailingDeactivateEntersError) {
  ToActive();
  component_.Fail(testing::kDeactivated);
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_deactivated returned RTC_ERROR");
}

TEST_F(LifecycleTest, ThrowingDeactivateEntersError) {
  ToActive();
  component_.Throw(testing::kDeactivated);
  EXPECT_EQ(lifecycle_.Deactivate(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_deactivated threw: on_deactivated exploded");
}

TEST_F(LifecycleTest, FailingExecuteEntersErrorAndSkipsStateUpdate) {
  ToActive();
  component_.Fail(testing::kExecute);
  lifecycle_.Execute();
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kStateUpdate), 0);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_execute returned RTC_ERROR");
}

TEST_F(LifecycleTest, ThrowingExecuteEntersErrorAndSkipsStateUpdate) {
  ToActive();
  component_.Throw(testing::kExecute);
  lifecycle_.Execute();
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kStateUpdate), 0);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_execute threw: on_execute exploded");
}

TEST_F(LifecycleTest, FailingStateUpdateEntersError) {
  ToActive();
  component_.Throw(testing::kStateUpdate);
  lifecycle_.Execute();
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kExecute), 1);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_state_update threw: on_state_update exploded");
}

TEST_F(LifecycleTest, ErrorRunsOnErrorOnEachTickAndNothingElse) {
  ToError();
  lifecycle_.Execute();
  lifecycle_.Execute();
  lifecycle_.Execute();
  EXPECT_EQ(component_.count(testing::kOnError), 3);
  EXPECT_EQ(component_.count(testing::kExecute), 1);  // only the failing one
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.state(), State::kError);
}

TEST_F(LifecycleTest, FailingOnErrorStaysInErrorWithoutAbortingAgain) {
  ToError();
  component_.Throw(testing::kOnError);
  lifecycle_.Execute();
  lifecycle_.Execute();
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kOnError), 2);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_execute returned RTC_ERROR");  // why it entered ERROR
}

TEST_F(LifecycleTest, ThrowingOnAbortingStillEntersError) {
  ToActive();
  component_.Throw(testing::kAborting);
  component_.Throw(testing::kExecute);
  lifecycle_.Execute();
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_execute threw: on_execute exploded");
}

TEST_F(LifecycleTest, FailingResetStaysInError) {
  ToError();
  component_.Fail(testing::kReset);
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(lifecycle_.last_error(), "on_reset returned RTC_ERROR");
  EXPECT_EQ(component_.count(testing::kAborting), 1);  // not entered again

  component_.Throw(testing::kReset);
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(lifecycle_.last_error(), "on_reset threw: on_reset exploded");

  component_.Succeed(testing::kReset);
  EXPECT_EQ(lifecycle_.Reset(), ReturnCode::kOk);
  EXPECT_EQ(lifecycle_.state(), State::kInactive);
  EXPECT_EQ(component_.count(testing::kReset), 3);
}

TEST_F(LifecycleTest, FailingRateChangedEntersError) {
  ToActive();
  component_.Fail(testing::kRateChanged);
  EXPECT_EQ(lifecycle_.RateChanged(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_rate_changed returned RTC_ERROR");
}

TEST_F(LifecycleTest, ThrowingRateChangedWhileInactiveEntersError) {
  ToInactive();
  component_.Throw(testing::kRateChanged);
  EXPECT_EQ(lifecycle_.RateChanged(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(lifecycle_.last_error(), "on_rate_changed threw: on_rate_changed exploded");
}

TEST_F(LifecycleTest, FailingRateChangedInErrorDoesNotAbortAgain) {
  ToError();
  component_.Fail(testing::kRateChanged);
  EXPECT_EQ(lifecycle_.RateChanged(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kError);
  EXPECT_EQ(component_.count(testing::kAborting), 1);
  EXPECT_EQ(lifecycle_.last_error(), "on_execute returned RTC_ERROR");
}

TEST_F(LifecycleTest, FailingStartupOrShutdownIsReportedButChangesNoState) {
  ToActive();
  component_.Fail(testing::kStartup);
  component_.Throw(testing::kShutdown);
  EXPECT_EQ(lifecycle_.Startup(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.Shutdown(), ReturnCode::kError);
  EXPECT_EQ(lifecycle_.state(), State::kActive);
  EXPECT_EQ(component_.count(testing::kAborting), 0);
}

TEST_F(LifecycleTest, FailingFinalizeStillFinalizes) {
  ToInactive();
  component_.Throw(testing::kFinalize);
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kError);
  EXPECT_TRUE(lifecycle_.finalized());
  EXPECT_EQ(lifecycle_.Finalize(), ReturnCode::kPreconditionNotMet);
  EXPECT_EQ(component_.count(testing::kFinalize), 1);
}

}  // namespace
}  // namespace caliper::rtc
