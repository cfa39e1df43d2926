// Scene files for raw cameras: [camera] pixel_format takes the Bayer formats and
// [camera.sensor] black_level their black level, refused where it cannot apply.
#include <gtest/gtest.h>

#include <string>

#include "capture/sim/sim_scene_loader.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

TEST(SimSceneBayer, BayerFormatAndBlackLevelLoad) {
  const SimScene scene = parse_sim_scene("[camera]\npixel_format = \"SBGGR12P\"\n[camera.sensor]\nblack_level = 256\n",
                                         "scene.toml", {});
  EXPECT_EQ(scene.camera.pixel_format, PixelFormat::SBGGR12P);
  EXPECT_EQ(scene.camera.sensor.black_level, 256);
  // Existing scenes: no black level.
  EXPECT_EQ(parse_sim_scene("[camera]\npixel_format = \"RGB24\"\n", "scene.toml", {}).camera.sensor.black_level, 0);
}

TEST(SimSceneBayer, BlackLevelIsRefusedWhereItCannotApply) {
  const std::string not_raw = error_of("[camera]\npixel_format = \"YUYV\"\n[camera.sensor]\nblack_level = 16\n");
  EXPECT_EQ(not_raw.rfind("scene.toml:4:", 0), 0u) << not_raw;
  EXPECT_NE(not_raw.find("camera.sensor.black_level"), std::string::npos) << not_raw;
  EXPECT_NE(not_raw.find("YUYV"), std::string::npos) << not_raw;
  // At 10 bits the top code is 1023: a black level there would leave no range for light.
  const std::string too_high = error_of("[camera]\npixel_format = \"SRGGB10\"\n[camera.sensor]\nblack_level = 1023\n");
  EXPECT_NE(too_high.find("camera.sensor.black_level"), std::string::npos) << too_high;
  EXPECT_NE(too_high.find("1022"), std::string::npos) << too_high;
}

TEST(SimSceneBayer, PackedWidthsAreChecked) {
  // 10P packs 4 pixels in 5 bytes: a width of 642 is not whole groups.
  const std::string message = error_of("[camera]\npixel_format = \"SRGGB10P\"\nwidth = 642\nheight = 480\n");
  EXPECT_NE(message.find("multiple of 4"), std::string::npos) << message;
  EXPECT_NE(error_of("[camera]\npixel_format = \"SRGGB11\"\n").find("Bayer"), std::string::npos);
}

}  // namespace
}  // namespace arpipe::sim
