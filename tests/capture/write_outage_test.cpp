// WriteOutage: one message when writing stops, one when it resumes, and a disk that keeps filling
// and emptying costs two lines a minute, not two a frame.
#include <gtest/gtest.h>

#include "capture/sinks/write_outage.h"
#include "sink_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

TEST(WriteOutage, LogsTheStartAndTheEndOfAnOutageOnceAndCountsEveryFailure) {
  int64_t now = 0;
  WriteOutage outage("out/x.jsonl", "the file ends at its last complete line", [&] { return now; });
  testing::internal::CaptureStderr();
  outage.succeeded(0);
  for (uint64_t i = 1; i < 5; ++i) outage.failed(i, "No space left on device");
  EXPECT_TRUE(outage.active());
  outage.succeeded(5);
  outage.succeeded(6);
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_FALSE(outage.active());
  EXPECT_EQ(outage.failures(), 4u);
  EXPECT_EQ(occurrences(log, "\n"), 2u) << log;
  EXPECT_NE(log.find("out/x.jsonl: cannot write frame 1: No space left on device; the file ends at its last complete "
                     "line. Later frames are retried"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("out/x.jsonl: writing resumed at frame 5; 4 frames were lost (from frame 1)"), std::string::npos)
      << log;
}

TEST(WriteOutage, OutagesWithinAMinuteOfTheLastMessageAreOnlyCountedAndReportedLater) {
  int64_t now = 0;
  WriteOutage outage("v.y4m", "the video ends at its last complete frame", [&] { return now; });
  testing::internal::CaptureStderr();
  outage.failed(10, "No space left on device");  // logged
  outage.succeeded(11);                          // logged
  for (uint64_t i = 12; i < 40; i += 2) {        // flapping: only counted
    now += 1'000'000'000;
    outage.failed(i, "No space left on device");
    outage.succeeded(i + 1);
  }
  const std::string quiet = testing::internal::GetCapturedStderr();
  EXPECT_EQ(occurrences(quiet, "\n"), 2u) << quiet;
  EXPECT_EQ(outage.failures(), 15u);

  testing::internal::CaptureStderr();
  now += WriteOutage::kQuietNs;
  outage.failed(50, "No space left on device");
  outage.report_at_end();
  const std::string later = testing::internal::GetCapturedStderr();
  EXPECT_NE(later.find("v.y4m: cannot write frame 50: No space left on device; the video ends at its last complete "
                       "frame. Later frames are retried, and failures are only counted until writing resumes (14 "
                       "shorter outages since the last message lost 14 frames and were only counted)"),
            std::string::npos)
      << later;
  EXPECT_NE(later.find("v.y4m: the run ends with writing still failing; 1 frames were lost (from frame 50)"),
            std::string::npos)
      << later;
}

TEST(WriteOutage, AnUnloggedOutageAtTheEndIsReported) {
  int64_t now = 0;
  WriteOutage outage("p", "kept", [&] { return now; });
  testing::internal::CaptureStderr();
  outage.failed(1, "e");
  outage.succeeded(2);
  outage.failed(3, "e");
  outage.failed(4, "e");
  outage.report_at_end();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("p: 1 more outages since the last message lost 2 frames in all"), std::string::npos) << log;
  EXPECT_EQ(occurrences(log, "\n"), 3u) << log;
}

}  // namespace
}  // namespace arpipe
