// Image textures are decoded by the decoder of the format their header names (libpng,
// libjpeg-turbo), never by OpenCV's signature probing; the pixels are those cv::imread gives.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "capture/sim/sim_textures.h"
#include "core/image/srgb.h"
#include "core/scene/asset_error.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("arpipe_texture_decoding_" + name + "_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

SimMaterial image_material(const fs::path& path) {
  SimMaterial m;
  m.albedo = {1, 1, 1};
  m.texture.kind = SimTexture::Kind::Image;
  m.texture.image_path = path;
  return m;
}

TEST(SimTextureDecoding, AJpegWithDicmAtByte128IsAnAssetErrorNotAnAbort) {
  // fuzz_png_jpeg's reproducer: cv::imread took it for DICOM and GDCM aborted the process.
  const fs::path file = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "fuzz_png_jpeg" /
                        "jpeg-header-dicm-gdcm-assert.jpg";
  try {
    PlaneTexture texture(image_material(file), "poster");
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("object \"poster\": image texture \"" + file.string() + "\": cannot be decoded: JPEG: ", 0),
              0u)
        << message;
  }
}

// A test image with every channel different and gradients in both directions.
cv::Mat pattern(int rows, int cols, int type) {
  cv::Mat image(rows, cols, type);
  const int channels = image.channels();
  const double scale = image.depth() == CV_16U ? 257.0 * 255 / 256 : 1.0;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      for (int k = 0; k < channels; ++k) {
        const int v = (r * 37 + c * 11 + k * 80) % 256;
        if (image.depth() == CV_16U)
          image.ptr<uint16_t>(r)[c * channels + k] = static_cast<uint16_t>(v * scale + k);
        else
          image.ptr<uint8_t>(r)[c * channels + k] = static_cast<uint8_t>(v);
      }
  return image;
}

// The texture at each texel centre against cv::imread(IMREAD_COLOR) of the same file, to float storage.
void expect_same_pixels_as_opencv(const fs::path& path) {
  const cv::Mat reference = cv::imread(path.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(reference.empty()) << path;
  ASSERT_EQ(reference.type(), CV_8UC3);
  const PlaneTexture texture(image_material(path), "poster");
  int differing = 0;
  for (int r = 0; r < reference.rows; ++r)
    for (int c = 0; c < reference.cols; ++c) {
      const cv::Vec3b bgr = reference.at<cv::Vec3b>(r, c);
      const Rgb got = texture.reflectance((c + 0.5) / reference.cols, (r + 0.5) / reference.rows);
      for (int k = 0; k < 3; ++k)
        if (std::abs(got[size_t(k)] - srgb_decode(bgr[2 - k] / 255.0)) > 1e-7) ++differing;
    }
  EXPECT_EQ(differing, 0) << path;
}

TEST(SimTextureDecoding, PngAndJpegDecodeToTheSamePixelsAsOpenCv) {
  const fs::path dir = scratch("same");
  struct Case {
    std::string name;
    cv::Mat image;
    std::vector<int> params;
  };
  const std::vector<Case> cases = {
      {"rgb8.png", pattern(23, 31, CV_8UC3), {}},
      {"rgba8.png", pattern(17, 13, CV_8UC4), {}},
      {"grey8.png", pattern(9, 14, CV_8UC1), {}},
      {"rgb16.png", pattern(11, 7, CV_16UC3), {}},
      {"grey16.png", pattern(5, 6, CV_16UC1), {}},
      {"rgb.jpg", pattern(37, 45, CV_8UC3), {cv::IMWRITE_JPEG_QUALITY, 90}},
      {"quality100.jpg", pattern(16, 24, CV_8UC3), {cv::IMWRITE_JPEG_QUALITY, 100}},
      {"progressive.jpg", pattern(21, 19, CV_8UC3), {cv::IMWRITE_JPEG_PROGRESSIVE, 1}},
      {"grey.jpg", pattern(20, 30, CV_8UC1), {}},
  };
  for (const Case& c : cases) {
    const fs::path path = dir / c.name;
    ASSERT_TRUE(cv::imwrite(path.string(), c.image, c.params)) << c.name;
    expect_same_pixels_as_opencv(path);
  }
}

TEST(SimTextureDecoding, ACutOffPngIsAnAssetErrorNamingTheFile) {
  const fs::path dir = scratch("cut");
  const fs::path whole = dir / "whole.png", cut = dir / "cut.png";
  ASSERT_TRUE(cv::imwrite(whole.string(), pattern(40, 40, CV_8UC3)));
  fs::copy_file(whole, cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(whole) / 2);
  try {
    PlaneTexture texture(image_material(cut), "poster");
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("object \"poster\": image texture \"" + cut.string() + "\": cannot be decoded: PNG: ", 0), 0u)
        << message;
  }
}

}  // namespace
}  // namespace arpipe::sim
