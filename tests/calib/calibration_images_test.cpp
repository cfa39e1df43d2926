// Calibration image sets: a glob of image files in name order, decoded to grey, with errors that
// name the pattern or the file; and a recording's frames as full-range luma.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "tests/calib/calib_test_support.h"
#include "tests/support/png_declaring.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

// A grey test card whose every pixel is known: value = (3x + 5y + seed) mod 256.
cv::Mat card(int width, int height, int seed) {
  cv::Mat image(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.at<unsigned char>(y, x) = static_cast<unsigned char>((3 * x + 5 * y + seed) % 256);
  return image;
}

void expect_card(const GreyImage& image, int width, int height, int seed) {
  ASSERT_EQ(image.width, width);
  ASSERT_EQ(image.height, height);
  ASSERT_EQ(image.pixels.size(), static_cast<size_t>(width * height));
  const cv::Mat expected = card(width, height, seed);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      ASSERT_EQ(image.pixels[static_cast<size_t>(y * width + x)], expected.at<unsigned char>(y, x)) << x << "," << y;
}

// The caught error's message, or "" when nothing was thrown.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const CalibrationInputError& e) {
    return e.what();
  }
  return "";
}

TEST(CalibrationImages, GlobIsSortedAndDecodedToGrey) {
  const fs::path dir = scratch_dir("glob");
  ASSERT_TRUE(cv::imwrite((dir / "view-10.png").string(), card(40, 30, 1)));
  ASSERT_TRUE(cv::imwrite((dir / "view-02.png").string(), card(32, 24, 2)));
  // A colour file whose channels are equal decodes to the same grey values.
  cv::Mat colour;
  cv::merge(std::vector<cv::Mat>{card(20, 10, 3), card(20, 10, 3), card(20, 10, 3)}, colour);
  ASSERT_TRUE(cv::imwrite((dir / "view-05.png").string(), colour));
  fs::create_directory(dir / "view-99.png.d");  // a directory the pattern also matches: skipped
  std::ofstream(dir / "notes.txt") << "not an image\n";

  const auto images = images_from_glob((dir / "view-*").string());
  ASSERT_EQ(images->count(), 3u);
  EXPECT_EQ(images->name(0), (dir / "view-02.png").string());
  EXPECT_EQ(images->name(1), (dir / "view-05.png").string());
  EXPECT_EQ(images->name(2), (dir / "view-10.png").string());
  const GreyImage first = images->load(0);
  EXPECT_EQ(first.name, images->name(0));
  expect_card(first, 32, 24, 2);
  expect_card(images->load(1), 20, 10, 3);
  expect_card(images->load(2), 40, 30, 1);
  remove_scratch(dir);
}

TEST(CalibrationImages, GlobErrorsNameThePatternOrTheFile) {
  const fs::path dir = scratch_dir("glob-errors");
  const std::string nothing = (dir / "*.png").string();
  EXPECT_EQ(error_of([&] { images_from_glob(nothing); }), "'" + nothing + "': no file matches this pattern");
  const std::string absent_dir = (dir / "absent" / "*.png").string();
  EXPECT_EQ(error_of([&] { images_from_glob(absent_dir); }),
            "'" + absent_dir + "': cannot list a directory of this pattern: No such file or directory");

  std::ofstream(dir / "broken.png") << "these bytes are not a PNG";
  ASSERT_TRUE(cv::imwrite((dir / "good.png").string(), card(8, 8, 0)));
  const auto images = images_from_glob((dir / "*.png").string());
  ASSERT_EQ(images->count(), 2u);
  EXPECT_EQ(error_of([&] { images->load(0); }),
            (dir / "broken.png").string() + ": cannot read image: not a readable image file (OpenCV could not decode it)");
  expect_card(images->load(1), 8, 8, 0);
  // A file that went away after the glob.
  fs::remove(dir / "good.png");
  EXPECT_EQ(error_of([&] { images->load(1); }), (dir / "good.png").string() + ": cannot read image: it no longer exists");
  EXPECT_EQ(error_of([&] { images->load(2); }), "'" + (dir / "*.png").string() + "': no image 2 (the pattern matched 2)");
  remove_scratch(dir);
}

TEST(CalibrationImages, RecordingFramesAreFullRangeLuma) {
  const RecordingReader reader(calib_capture());
  ASSERT_EQ(reader.info().pixel_format, PixelFormat::YUYV);
  const auto images = images_from_recording(calib_capture());
  ASSERT_EQ(images->count(), reader.frame_count());
  const size_t last = images->count() - 1;
  EXPECT_EQ(images->name(last), fmt::format("{} frame {}", calib_capture().string(), last));
  const GreyImage image = images->load(last);
  EXPECT_EQ(image.name, images->name(last));
  ASSERT_EQ(image.width, 640);
  ASSERT_EQ(image.height, 480);
  ASSERT_EQ(image.pixels.size(), 640u * 480u);
  // YUYV stores Y0 U Y1 V; its luma is BT.601 limited range (16 black, 235 white), which the image
  // set stretches to 0..255 as image files have it.
  Frame frame;
  reader.read(last, frame);
  int dark = 255, light = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      const int luma = frame.data[static_cast<size_t>(y) * frame.bytes_per_line + 2 * static_cast<size_t>(x)];
      const int expected = std::clamp(static_cast<int>(std::lround((luma - 16) * 255.0 / 219.0)), 0, 255);
      ASSERT_EQ(image.pixels[static_cast<size_t>(y * 640 + x)], expected) << x << "," << y;
      dark = std::min(dark, expected);
      light = std::max(light, expected);
    }
  // The board's ink and paper (reflectance 0.03 and 0.8) span most of the range.
  EXPECT_LT(dark, 60);
  EXPECT_GT(light, 180);
}

TEST(CalibrationImages, RecordingLoadsFromSeveralThreads) {
  const auto images = images_from_recording(calib_capture());
  const GreyImage alone = images->load(1);
  GreyImage a, b;
  std::thread other([&] { a = images->load(1); });
  b = images->load(1);
  other.join();
  EXPECT_EQ(a.pixels, alone.pixels);
  EXPECT_EQ(b.pixels, alone.pixels);
}

TEST(CalibrationImages, RecordingErrorsNameTheDirectory) {
  const fs::path dir = scratch_dir("recording-errors");
  const std::string message = error_of([&] { images_from_recording(dir / "absent"); });
  EXPECT_EQ(message.rfind((dir / "absent").string() + ": cannot open the recording: ", 0), 0u) << message;
  const auto images = images_from_recording(calib_capture());
  const size_t count = images->count();
  EXPECT_EQ(error_of([&] { images->load(count); }),
            fmt::format("{}: no frame {} (the recording has {})", calib_capture().string(), count, count));
  remove_scratch(dir);
}

// Issue 18: photographs are hostile input. Before: a 30000 x 30000 PNG header in a small file was
// decoded (2.7 GB of grey pixels); a FIFO the glob matched blocked imread forever.
TEST(CalibrationImages, AHugeDeclaredPngIsRefusedBeforeDecoding) {
  const fs::path dir = scratch_dir("huge");
  const fs::path png = arpipe::test::png_declaring(dir, 30000, 30000, "view-01.png");
  const auto images = images_from_glob((dir / "view-*").string());
  ASSERT_EQ(images->count(), 1u);
  EXPECT_EQ(error_of([&] { images->load(0); }),
            "calibration image \"" + png.string() +
                "\": a 30000 x 30000 PNG image exceeds the limit of 16384 pixels a side and 134217728 pixels in all");
}

TEST(CalibrationImages, AFifoMatchedByTheGlobIsRefusedWithoutBlocking) {
  const fs::path dir = scratch_dir("fifo");
  ASSERT_EQ(::mkfifo((dir / "view-01.png").c_str(), 0600), 0);
  const auto images = images_from_glob((dir / "view-*").string());
  ASSERT_EQ(images->count(), 1u);
  EXPECT_EQ(error_of([&] { images->load(0); }),
            (dir / "view-01.png").string() + ": cannot read image: it is a FIFO (named pipe), expected a regular file");
}

}  // namespace
}  // namespace arpipe::calib
