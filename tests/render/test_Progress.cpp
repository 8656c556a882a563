// The progress bar's log (stderr not a terminal: a line every 10%): adaptive sampling shrinks
// the work left, so the bar jumps forward and still ends at 100% with nothing left.
#include <gtest/gtest.h>

#include <string>

#include "render/Progress.h"

using namespace envgi;

TEST(Progress, ShrinkingTheTotalEndsAtAHundredPercent) {
  testing::internal::CaptureStderr();
  {
    Progress p(1000, true);
    p.add(300);          // 30%
    p.shrinkTotal(500);  // 300 of 500: 60%
    p.add(200);          // 100%
    p.finish();
  }
  std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find(" 30%"), std::string::npos) << log;
  EXPECT_NE(log.find(" 60%"), std::string::npos) << log;
  size_t last = log.rfind('[');
  ASSERT_NE(last, std::string::npos) << log;
  EXPECT_NE(log.find("100%", last), std::string::npos) << log;
  EXPECT_NE(log.find("0.0s left", last), std::string::npos) << log;
  EXPECT_EQ(log.find("100%"), log.rfind("100%")) << "the end drawn once:\n" << log;
}

// Shrinking past what is done ends the bar there: every pixel stopped early.
TEST(Progress, ShrinkingToWhatIsDoneDrawsTheEnd) {
  testing::internal::CaptureStderr();
  {
    Progress p(1000, true);
    p.add(250);
    p.shrinkTotal(5000);
    p.finish();
  }
  std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("100%"), std::string::npos) << log;
  // Nothing drawn when disabled.
  testing::internal::CaptureStderr();
  {
    Progress q(10, false);
    q.add(5);
    q.shrinkTotal(5);
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}
