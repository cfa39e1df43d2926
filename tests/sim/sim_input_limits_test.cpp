// Simulator inputs of issue 18: image sizes are read from the PNG/JPEG header and capped before
// decoding, the simulated frame and the scene's counts are capped with the limit in the message,
// a huge HDR header is refused by the project's reader (no OpenCV assertion), and asset files must
// be regular files.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/sim_textures.h"
#include "capture/sim/simulator.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"
#include "tests/support/png_declaring.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("arpipe_sim_limits_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

using arpipe::test::png_declaring;

std::string scene_error(const std::string& text, const fs::path& base) {
  try {
    parse_sim_scene(text, "scene.toml", base);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ImageHeader, ReadsPngAndJpegSizesWithoutDecoding) {
  const fs::path dir = scratch("header");
  const cv::Mat image(37, 53, CV_8UC3, cv::Scalar(1, 2, 3));
  ASSERT_TRUE(cv::imwrite((dir / "a.png").string(), image));
  ASSERT_TRUE(cv::imwrite((dir / "a.jpg").string(), image));
  const ImageHeader png = read_image_header(dir / "a.png");
  EXPECT_EQ(png.format, "PNG");
  EXPECT_EQ(png.width, 53);
  EXPECT_EQ(png.height, 37);
  const ImageHeader jpeg = read_image_header(dir / "a.jpg");
  EXPECT_EQ(jpeg.format, "JPEG");
  EXPECT_EQ(jpeg.width, 53);
  EXPECT_EQ(jpeg.height, 37);
  std::ofstream(dir / "text.png") << "hello";
  try {
    read_image_header(dir / "text.png");
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "text.png").string() +
                                         ": expected a PNG or JPEG image (signature 89 50 4e 47 or ff d8), found bytes "
                                         "68 65");
  }
  std::ofstream(dir / "cut.jpg", std::ios::binary) << std::string("\xff\xd8\xff\xe0\x00\x10JFIF", 10);
  try {
    read_image_header(dir / "cut.jpg");
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    EXPECT_TRUE(contains(e.what(), "cut.jpg: byte 20: the file ends inside a JPEG marker")) << e.what();
  }
}

TEST(SimInputLimits, AHugePngTextureIsRefusedBeforeDecoding) {
  // Before: OpenCV decoded the declared 30000 x 30000 pixels (13 GB with the float copy).
  const fs::path dir = scratch("texture");
  SimMaterial material;
  material.texture.kind = SimTexture::Kind::Image;
  material.texture.image_path = png_declaring(dir, 30000, 30000);
  EXPECT_LT(fs::file_size(material.texture.image_path), 200u);
  try {
    PlaneTexture texture(material, "poster");
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    EXPECT_EQ(std::string(e.what()), "object \"poster\": image texture \"" + material.texture.image_path.string() +
                                         "\": a 30000 x 30000 PNG image exceeds the limit of 16384 pixels a side and "
                                         "33554432 pixels in all");
  }
  // Within each side's limit but over the pixel count.
  material.texture.image_path = png_declaring(dir, 16000, 16000);
  try {
    PlaneTexture texture(material, "poster");
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    EXPECT_TRUE(contains(e.what(), "a 16000 x 16000 PNG image exceeds the limit")) << e.what();
  }
  // The scene loader says it with the key.
  const std::string message = scene_error("[[object]]\n[object.texture]\nkind = \"image\"\nimage = \"huge.png\"\n", dir);
  EXPECT_TRUE(contains(message, "scene.toml:4:9: object[0].texture.image: expected an image of at most 16384 pixels a "
                                "side and 33554432 pixels in all"))
      << message;
}

TEST(SimInputLimits, TheSimulatedFrameSizeIsCapped) {
  // Before: 16384 x 16384 was accepted and the simulator grew past 21 GB.
  const std::string message = scene_error("[camera]\nwidth = 16384\nheight = 16384\n", {});
  EXPECT_EQ(message, "scene.toml:2:9: camera.width: expected a simulated frame of at most 8192 pixels a side and "
                     "16777216 pixels in all (rendering holds about 80 bytes a pixel), found 16384x16384");
  EXPECT_TRUE(contains(scene_error("[camera]\nwidth = 8000\nheight = 8000\n", {}), "16777216 pixels in all"));
  EXPECT_EQ(scene_error("[camera]\nwidth = 64\nheight = 32\n", {}), "");

  // simulate() checks it too, for scenes built in code.
  SimScene scene = parse_sim_scene("", "scene.toml", {});
  scene.camera.model = CameraModel::pinhole(100, 100, 5000, 5000, 10000, 10000);
  SimulateOptions options;
  options.out_dir = scratch("frame") / "out";
  try {
    simulate(scene, options);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "simulate: a 10000x10000 frame exceeds the limit of 8192 pixels a side and "
                                     "16777216 pixels in all (rendering holds about 80 bytes a pixel)");
  }
  EXPECT_FALSE(fs::exists(options.out_dir));
}

TEST(SimInputLimits, SceneCountsAreCapped) {
  std::string objects;
  for (int i = 0; i < 1001; ++i) objects += "[[object]]\n";
  EXPECT_EQ(scene_error(objects, {}), "scene.toml:1:1: object: expected at most 1000 [[object]] tables, found 1001");
  std::string lights;
  for (int i = 0; i < 101; ++i) lights += "[[light]]\n";
  EXPECT_TRUE(contains(scene_error(lights, {}), "light: expected at most 100 [[light]] tables, found 101"));
  std::string exposures = "[camera]\nexposure_ms = [";
  for (int i = 0; i < 10001; ++i) exposures += "1,";
  exposures += "]\n";
  EXPECT_TRUE(contains(scene_error(exposures, {}),
                       "camera.exposure_ms: expected an array of at most 10000 numbers (a number > 0 each), found "
                       "10001 numbers"));
}

TEST(SimInputLimits, AHugeHdrHeaderIsTheReadersErrorNotAnOpenCvAssertion) {
  const fs::path dir = scratch("sky");
  std::ofstream(dir / "huge.hdr") << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n";
  SimEnvironment environment;
  environment.hdr_path = dir / "huge.hdr";
  try {
    EnvironmentMap map(environment);
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, "HDR environment: " + (dir / "huge.hdr").string() + ": resolution line")) << message;
    EXPECT_TRUE(contains(message, "32768")) << message;
    EXPECT_FALSE(contains(message, "OpenCV")) << message;
  }
}

TEST(SimInputLimits, AssetFilesMustBeRegularFiles) {
  const fs::path dir = scratch("fifo");
  ASSERT_EQ(::mkfifo((dir / "sky.hdr").c_str(), 0600), 0);
  // Before: the loader's std::ifstream blocked in open() on the FIFO.
  const std::string message = scene_error("[environment]\nhdr = \"sky.hdr\"\n", dir);
  EXPECT_TRUE(contains(message, "environment.hdr: expected a Radiance .hdr image, found \"sky.hdr\" (" +
                                    (dir / "sky.hdr").string() + "): it is a FIFO (named pipe), expected a regular file"))
      << message;
}

}  // namespace
}  // namespace arpipe::sim
