// Seed 003's animated proxies in sync with the video: a proxy on a glTF node whose animation moves
// it one metre a second along x stands, on every output frame, where the video frame the source
// shows puts it (its x times 30 frames/s is that frame's index), through B-frames, the MP4 edit
// list and 10 minutes of loops, in the real source and render stage.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "capture/panorama/panorama_source.h"
#include "core/config/config.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/glb_writer.h"
#include "render/gl_stages.h"
#include "tests/capture/capture_test_support.h"
#include "tests/support/barcode_video.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
constexpr int kVideoFrames = 64;
constexpr double kVideoFps = 30;

// A box on the node "marker", at x = t metres from 0 to the last video frame's time, LINEAR.
fs::path marker_glb(const fs::path& dir) {
  GlbAnimatedNode marker;
  marker.name = "marker";
  marker.mesh = *make_builtin_mesh("builtin:box", {0.1, 0.1, 0.1}, 1);
  const double last_s = (kVideoFrames - 1) / kVideoFps;
  marker.keys = {{0, SE3::from_rt({0, 0, 0}, {0, 0, 0})}, {last_s, SE3::from_rt({0, 0, 0}, {last_s, 0, 0})}};
  const std::vector<uint8_t> glb = encode_glb(Mesh{}, "panorama_animation_test", {}, {marker});
  const fs::path path = dir / "marker.glb";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(glb.data()), std::streamsize(glb.size()));
  return path;
}

TEST(PanoramaAnimation, AnAnimatedProxyStandsWhereTheShownVideoFramePutsItThroughTenMinutesOfLoops) {
  const fs::path dir = test::scratch_dir("panorama-animation");
  Config config;
  config.source.type = SourceType::Panorama;
  config.source.pacing = ReplayPacing::Fast;
  config.source.panorama.file =
      test::make_barcode_video(dir, "b-frames.mp4", kVideoFrames, test::kH264WithBFrames);
  config.source.panorama.view.width = 64;
  config.source.panorama.view.height = 32;
  config.source.panorama.view.fps = kVideoFps;
  constexpr int kFrames = 18000;  // 10 minutes at 30 frames/s: 281 passes of the video
  config.source.panorama.view.frames = kFrames;
  // The view's centre pixel looks at bit 0's block (column 8 of 256, the equator).
  config.source.panorama.view.yaw_rad = (8.5 / test::kBarcodeWidth - 0.5) * 2 * M_PI;
  SceneProxy proxy;
  proxy.name = "marker";
  proxy.mesh = marker_glb(dir).string();
  proxy.node = "marker";
  config.render.proxies = {proxy};
  PanoramaSource source(config.source);
  std::vector<std::unique_ptr<Stage>> stages = make_gl_stages();
  for (auto& stage : stages) stage->configure(config);
  int mismatches = 0;
  for (int k = 0; k < kFrames; ++k) {
    FrameContext ctx;
    ASSERT_EQ(source.next(ctx.camera), SourceStatus::Frame) << "output frame " << k;
    for (auto& stage : stages) stage->process(ctx);
    ASSERT_TRUE(ctx.camera.meta.source_frame_index);
    ASSERT_TRUE(ctx.animation) << "output frame " << k;
    ASSERT_EQ(ctx.animation->proxies.size(), 1u);
    const int64_t index = *ctx.camera.meta.source_frame_index;
    // The index is the barcode's (its bit 0 under the centre pixel) and the video's place in its loop.
    const bool bit0 = ctx.camera.data[16 * ctx.camera.bytes_per_line + 3 * 32] > 128;
    const double x = ctx.animation->proxies[0].position_m[0];
    // The animation's frame: the proxy's place over the speed (1 m/s) times the video's rate.
    const double animation_frame = x * kVideoFps;
    if (index != k % kVideoFrames || bit0 != bool(index & 1) || std::abs(animation_frame - double(index)) > 1e-4 ||
        std::abs(ctx.animation->time_s * kVideoFps - double(index)) > 1e-6) {
      if (++mismatches <= 5)
        ADD_FAILURE() << fmt::format("output frame {}: index {} (bit 0 {}), animation time {} s, proxy at x = {} m", k,
                                     index, bit0, ctx.animation->time_s, x);
    }
  }
  EXPECT_EQ(mismatches, 0);
  FrameContext end;
  EXPECT_EQ(source.next(end.camera), SourceStatus::EndOfStream);
}

}  // namespace
}  // namespace arpipe
