// The 360° video writer read back by the panorama source's own reader: every frame, in order, at
// its index, its pixels within x264's loss at crf 18, and the spherical metadata of its layout.
#include "capture/panorama/panorama_video_writer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "capture/panorama/panorama_video.h"
#include "core/scene/asset_error.h"
#include "tests/capture/capture_test_support.h"

namespace arpipe {
namespace {

TEST(PanoramaVideoWriter, FramesComeBackInOrderAtTheirIndexWithTheirPixels) {
  const auto dir = test::scratch_dir("panorama-video-writer");
  const std::filesystem::path file = dir / "mono.mp4";
  constexpr int kWidth = 128, kHeight = 64, kFrames = 12;
  {
    PanoramaVideoWriter writer(file, kWidth, kHeight, 30, PanoramaLayout::Equirect);
    std::vector<uint8_t> rgb(size_t(kWidth) * kHeight * 3);
    for (int k = 0; k < kFrames; ++k) {
      // A horizontal ramp shifted by k, so each frame differs from the next.
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x)
          for (int c = 0; c < 3; ++c) rgb[(size_t(y) * kWidth + x) * 3 + c] = uint8_t((x * 2 + k * 16 + c * 40) % 256);
      writer.write(rgb.data(), size_t(kWidth) * 3);
    }
    writer.finish();
  }
  PanoramaVideo video(file);  // "auto": the metadata says mono
  EXPECT_EQ(video.layout(), PanoramaLayout::Equirect);
  EXPECT_EQ(video.rate_num() * 1, 30 * video.rate_den());
  PanoramaVideoFrame frame;
  for (int k = 0; k < kFrames; ++k) {
    ASSERT_TRUE(video.next(frame)) << k;
    EXPECT_EQ(frame.index, k);
    // Away from the ramp's wrap (a hard edge x264 rings at), the mean error is small.
    double error = 0;
    int count = 0;
    for (int y = 8; y < kHeight - 8; ++y)
      for (int x = 8; x < kWidth - 8; ++x) {
        const int expected = (x * 2 + k * 16) % 256;
        if (expected < 16 || expected > 240) continue;
        error += std::abs(int(frame.rgb[(size_t(y) * kWidth + x) * 3]) - expected);
        ++count;
      }
    EXPECT_LT(error / count, 3.0) << "frame " << k;
  }
  EXPECT_FALSE(video.next(frame));
  std::filesystem::remove_all(dir);
}

TEST(PanoramaVideoWriter, AStereoVideoSaysItsLayout) {
  const auto dir = test::scratch_dir("panorama-video-writer-stereo");
  const std::filesystem::path file = dir / "tb.mp4";
  {
    PanoramaVideoWriter writer(file, 64, 64, 25, PanoramaLayout::EquirectTopBottom);
    const std::vector<uint8_t> grey(64 * 64 * 3, 128);
    writer.write(grey.data(), 64 * 3);
    writer.write(grey.data(), 64 * 3);
  }  // finished by the destructor
  EXPECT_EQ(PanoramaVideo(file).layout(), PanoramaLayout::EquirectTopBottom);
  // Read as mono, its metadata refuses.
  EXPECT_THROW(PanoramaVideo(file, PanoramaLayout::Equirect), AssetError);
  EXPECT_THROW(PanoramaVideoWriter(dir / "odd.mp4", 63, 32, 30, PanoramaLayout::Equirect), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace arpipe
