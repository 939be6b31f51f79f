#include "pdvo/common/logging.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

int Touch(int* counter) { return ++*counter; }

TEST(Logging, ParsesLevelsByNameOrNumber) {
  EXPECT_EQ(ParseLogLevel("warning"), LogLevel::kWarning);
  EXPECT_EQ(ParseLogLevel("3"), LogLevel::kDebug);
  EXPECT_THROW(ParseLogLevel("loud"), InvalidArgument);
}

TEST(Logging, MessagesAboveTheLevelAreNotEvenBuilt) {
  const LogLevel before = GetLogLevel();
  int built = 0;
  SetLogLevel(LogLevel::kWarning);
  PDVO_LOG(Debug) << Touch(&built);
  PDVO_LOG(Info) << Touch(&built);
  EXPECT_EQ(built, 0);
  testing::internal::CaptureStderr();
  PDVO_LOG(Warning) << "value " << Touch(&built);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "warning: value 1\n");
  // Safe in a braceless if/else.
  if (built == 1)
    PDVO_LOG(Error) << "x";
  else
    ADD_FAILURE();
  SetLogLevel(before);
}

TEST(Progress, CountsStepsAndPrintsPlainLinesWhenNotOnATerminal) {
  const LogLevel before = GetLogLevel();
  SetLogLevel(LogLevel::kInfo);
  testing::internal::CaptureStderr();
  {
    Progress progress("work", 4, 1e9);
    for (int i = 0; i < 4; ++i) {
      progress.SetNote("state " + std::to_string(10 * i));
      progress.Step();
    }
    EXPECT_EQ(progress.done(), 4u);
    EXPECT_GT(progress.Rate(), 0.0);
  }
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("work: 4/4"), std::string::npos) << err;    // the final line, printed once
  EXPECT_NE(err.find(", state 30,"), std::string::npos) << err;  // with the latest note
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1);
  SetLogLevel(before);
}

TEST(Progress, PrintsNoFinalLineWhenItsLoopFails) {
  const LogLevel before = GetLogLevel();
  SetLogLevel(LogLevel::kInfo);
  testing::internal::CaptureStderr();
  try {
    Progress progress("work", 4, 1e9);
    progress.Step();
    throw std::runtime_error("fails");
  } catch (const std::runtime_error&) {
  }
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "");  // the error's own line then stands alone
  SetLogLevel(before);
}

}  // namespace
}  // namespace pdvo
