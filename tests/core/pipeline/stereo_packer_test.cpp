// The stereo packer against the pictures it is given: the left eye's on top (or on the left), a
// time step's eyes paired only with each other, strays dropped and counted.
#include "core/pipeline/stereo_packer.h"

#include <gtest/gtest.h>

namespace arpipe {
namespace {

// A 4 x 2 RGB24 frame of one value, for eye `eye` at time t_ns.
FrameContext eye_frame(Eye eye, int64_t t_ns, uint8_t value) {
  FrameContext ctx;
  ctx.camera = Frame::allocate(PixelFormat::RGB24, 4, 2);
  std::fill(ctx.camera.data.begin(), ctx.camera.data.end(), value);
  ctx.camera.meta.eye = eye;
  ctx.camera.meta.exposure_start_ns = t_ns;
  ctx.output = ctx.camera;
  ctx.camera_model = std::make_shared<const CameraModel>(CameraModel::pinhole(4, 4, 1.5, 0.5, 4, 2));
  ctx.timings.push_back({"render", 1.0, ""});
  return ctx;
}

TEST(StereoPacker, PairsEachLeftEyeWithItsRightEye) {
  for (const StereoOutput packing : {StereoOutput::TopBottom, StereoOutput::LeftRight}) {
    StereoPacker packer(packing);
    EXPECT_FALSE(packer.add(eye_frame(Eye::Left, 100, 10)));
    std::optional<FrameContext> pair = packer.add(eye_frame(Eye::Right, 100, 200));
    ASSERT_TRUE(pair);
    const Frame& out = pair->output;
    EXPECT_EQ(out.meta.eye, Eye::Pair);
    EXPECT_EQ(pair->camera.meta.eye, Eye::Pair);
    const bool tb = packing == StereoOutput::TopBottom;
    ASSERT_EQ(out.width, tb ? 4 : 8);
    ASSERT_EQ(out.height, tb ? 4 : 2);
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x) {
        const bool right = tb ? y >= 2 : x >= 4;
        EXPECT_EQ(out.data[size_t(y) * out.bytes_per_line + size_t(x) * 3], right ? 200 : 10) << x << ", " << y;
      }
    // The lens over the pair's size (the left eye's), and the right eye's timings named so.
    ASSERT_TRUE(pair->output_camera_model);
    EXPECT_EQ(pair->output_camera_model->width(), out.width);
    EXPECT_EQ(pair->output_camera_model->height(), out.height);
    ASSERT_EQ(pair->timings.size(), 2u);
    EXPECT_EQ(pair->timings[1].stage, "render (right eye)");
    EXPECT_EQ(packer.unpaired(), 0u);
  }
}

TEST(StereoPacker, MonoFramesPassAndStrayEyesAreDroppedAndCounted) {
  StereoPacker packer(StereoOutput::TopBottom);
  EXPECT_TRUE(packer.add(eye_frame(Eye::Mono, 0, 1)));
  EXPECT_FALSE(packer.add(eye_frame(Eye::Right, 0, 1)));   // no left eye before it
  EXPECT_FALSE(packer.add(eye_frame(Eye::Left, 10, 1)));
  EXPECT_FALSE(packer.add(eye_frame(Eye::Left, 20, 1)));   // the one before lost its right eye
  EXPECT_FALSE(packer.add(eye_frame(Eye::Right, 30, 1)));  // another time step's: both lost
  EXPECT_EQ(packer.unpaired(), 4u);
  EXPECT_FALSE(packer.add(eye_frame(Eye::Left, 40, 1)));
  EXPECT_TRUE(packer.add(eye_frame(Eye::Right, 40, 1)));
  EXPECT_EQ(packer.unpaired(), 4u);
}

}  // namespace
}  // namespace arpipe
