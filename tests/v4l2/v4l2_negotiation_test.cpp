// Choosing a V4L2 format from a camera's offers (pure: no device). The offers are a typical UVC
// webcam's: YUYV up to 640x480 at 30 fps, MJPEG up to 1920x1080 at 30 fps.
#include <gtest/gtest.h>
#include <linux/videodev2.h>

#include "capture/live/camera_stream.h"
#include "capture/v4l2/v4l2_negotiation.h"

namespace arpipe {
namespace {

std::vector<V4L2FormatOffer> webcam() {
  V4L2FormatOffer yuyv{V4L2_PIX_FMT_YUYV, false, {}, {}};
  yuyv.sizes = {{640, 480, {{1, 30}, {1, 15}}, {}}, {320, 240, {{1, 30}}, {}}, {1920, 1080, {{1, 5}}, {}}};
  V4L2FormatOffer mjpg{V4L2_PIX_FMT_MJPEG, true, {}, {}};
  // Some drivers give 30 fps as 333333/10000000 (100 ns units).
  mjpg.sizes = {{1920, 1080, {{333333, 10000000}}, {}}, {640, 480, {{1, 30}}, {}}};
  V4L2FormatOffer h264{v4l2_fourcc('H', '2', '6', '4'), true, {}, {}};
  h264.sizes = {{1920, 1080, {{1, 30}}, {}}};
  return {h264, yuyv, mjpg};
}

TEST(V4L2Negotiation, AutoPrefersAFormatPassedOnAsItIs) {
  const auto choice = choose_v4l2_format(webcam(), {640, 480, 30, CaptureFormat::Auto}, "/dev/video0");
  EXPECT_EQ(choice.fourcc, V4L2_PIX_FMT_YUYV);
  ASSERT_TRUE(choice.interval);
  EXPECT_EQ(choice.interval->numerator, 1u);
  EXPECT_EQ(choice.interval->denominator, 30u);
}

TEST(V4L2Negotiation, AutoFallsBackToMjpegWhenOnlyItCanDoTheRate) {
  const auto choice = choose_v4l2_format(webcam(), {1920, 1080, 30, CaptureFormat::Auto}, "/dev/video0");
  EXPECT_EQ(choice.fourcc, V4L2_PIX_FMT_MJPEG);
  ASSERT_TRUE(choice.interval);
  EXPECT_EQ(choice.interval->numerator, 333333u);  // within 0.5 % of 30 fps: the driver's own fraction
}

TEST(V4L2Negotiation, ZeroMeansTheFirstSizeAndRateListed) {
  const auto choice = choose_v4l2_format(webcam(), {0, 0, 0, CaptureFormat::YUYV}, "/dev/video0");
  EXPECT_EQ(choice.width, 640u);
  EXPECT_EQ(choice.height, 480u);
  EXPECT_EQ(choice.interval->denominator, 30u);
}

TEST(V4L2Negotiation, RefusalListsEveryOfferAndNamesTheDevice) {
  try {
    choose_v4l2_format(webcam(), {1280, 720, 30, CaptureFormat::Auto}, "/dev/video7");
    FAIL() << "1280x720 is not offered";
  } catch (const CameraError& e) {
    EXPECT_EQ(e.kind(), CameraError::Kind::Refused);
    const std::string what = e.what();
    for (const char* line : {"/dev/video7", "auto 1280x720 at 30 fps", "YUYV 640x480 @ 30, 15 fps",
                             "MJPG 1920x1080 @ 30 fps", "H264 1920x1080 @ 30 fps (not usable by arpipe)"})
      EXPECT_NE(what.find(line), std::string::npos) << "missing '" << line << "' in:\n" << what;
  }
}

TEST(V4L2Negotiation, StepwiseSizesAcceptAnySizeInRange) {
  V4L2FormatOffer grey{V4L2_PIX_FMT_GREY, false, {}, "stepwise 64x64 to 1280x960 step 16x16"};
  grey.sizes = {{1280, 960, {}, {}}, {64, 64, {}, {}}};
  const auto choice = choose_v4l2_format({grey}, {800, 600, 20, CaptureFormat::GREY}, "/dev/video0");
  EXPECT_EQ(choice.width, 800u);
  ASSERT_TRUE(choice.interval);
  EXPECT_NEAR(choice.interval->fps(), 20.0, 1e-9);
  EXPECT_THROW(choose_v4l2_format({grey}, {2000, 600, 0, CaptureFormat::GREY}, "/dev/video0"), CameraError);
}

}  // namespace
}  // namespace arpipe
