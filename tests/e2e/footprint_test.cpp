// The footprint: every render pass works only inside the rectangle the objects, their blur paths
// and their shadows can reach (render_stage.cpp). Checked here the only way that proves it: the
// same captures through the whole pipeline with render.full_canvas = true (every pass over the
// whole image) give the same composited frames within 1/255 on every pixel, including objects at
// the image border, blur paths that leave the picture, and shadows reaching far outside the
// objects' own boxes. Also: a layer handed on again (render.reuse_layer) is the layer drawing would
// give, within the same 1/255.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "child_process.h"
#include "kept_frames.h"

namespace fs = std::filesystem;
namespace arpipe {
namespace {

using namespace kept_frames;

// The largest difference of any byte between two runs' frames, which must show the same frames.
int largest_difference(const std::vector<Shown>& a, const std::vector<Shown>& b) {
  EXPECT_EQ(a.size(), b.size());
  int most = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    EXPECT_EQ(a[i].index, b[i].index);
    EXPECT_EQ(a[i].drawn, b[i].drawn) << "frame " << a[i].index;
    const Frame& x = a[i].output;
    const Frame& y = b[i].output;
    EXPECT_EQ(x.data.size(), y.data.size());
    if (x.data.size() != y.data.size()) continue;
    for (size_t k = 0; k < x.data.size(); ++k) most = std::max(most, std::abs(int(x.data[k]) - int(y.data[k])));
  }
  return most;
}

int drawn_frames(const std::vector<Shown>& frames) {
  return int(std::count_if(frames.begin(), frames.end(), [](const Shown& s) { return s.drawn; }));
}

// Frames whose drawn rectangle reaches an edge of the picture.
int frames_at_border(const std::vector<Shown>& frames) {
  return int(std::count_if(frames.begin(), frames.end(), [](const Shown& s) {
    const VirtualLayerTexture& l = s.layer;
    return s.drawn && (l.x == 0 || l.y == 0 || l.x + l.rect_width == l.width || l.y + l.rect_height == l.height);
  }));
}

// Both runs with layer reuse off, so that every frame is drawn by the path under test.
const std::vector<std::string> kDrawEveryFrame{"render.reuse_layer=false"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST(Footprint, TheEmbeddedDefaultIsTheFullCanvasPicture) {
  const auto footprint = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 40, kDrawEveryFrame);
  const auto full = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 40,
                        with(kDrawEveryFrame, {"render.full_canvas=true"}));
  ASSERT_GT(drawn_frames(footprint), 30);
  EXPECT_LE(largest_difference(footprint, full), 1);
}

TEST(Footprint, TheLightCapturesAreTheFullCanvasPicture) {
  for (const char* scene : {"sun-outdoor", "probe-indoor"}) {
    const fs::path config = kConfigs / (std::string(scene) + ".toml");
    const fs::path capture = kBuild / (std::string(scene) + "-capture");
    const auto footprint = run(config, capture, 12, kDrawEveryFrame);
    const auto full = run(config, capture, 12, with(kDrawEveryFrame, {"render.full_canvas=true"}));
    ASSERT_GT(drawn_frames(footprint), 6) << scene;
    EXPECT_LE(largest_difference(footprint, full), 1) << scene;
  }
}

// A cube beside the tag, where the moving camera carries it across the edge of the picture, with
// the blur path forced on and long: the footprint is cut by the border while the smear reaches
// beyond it.
TEST(Footprint, ObjectsAndBlurPathsAtTheBorderAreTheFullCanvasPicture) {
  const std::vector<std::string> at_border{"render.objects.0.position_m=[0.21, 0.0, 0.0]",
                                           "render.objects.0.scale=2.0", "render.blur.min_motion_px=0.0"};
  for (const char* method : {"accumulate", "intraframe-warp", "velocity"}) {
    const std::vector<std::string> settings =
        with(with(kDrawEveryFrame, at_border), {std::string("render.blur.method=\"") + method + "\""});
    const auto footprint = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30, settings);
    const auto full = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30,
                          with(settings, {"render.full_canvas=true"}));
    ASSERT_GT(frames_at_border(footprint), 3) << method << ": the cube must reach the border";
    const int blurred = int(std::count_if(footprint.begin(), footprint.end(),
                                          [](const Shown& s) { return s.drawn && s.blur_samples > 0; }));
    EXPECT_GT(blurred, 3) << method;
    EXPECT_LE(largest_difference(footprint, full), 1) << method;
  }
}

// A low light throws the cube's shadow far past its box: the footprint must take the shadow in.
TEST(Footprint, ShadowsFarOutsideTheObjectsAreTheFullCanvasPicture) {
  const std::vector<std::string> low_light = with(kDrawEveryFrame, {"render.light_direction=[1.0, 0.3, 0.35]"});
  const auto footprint = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30, low_light);
  const auto full = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30,
                        with(low_light, {"render.full_canvas=true"}));
  // The shadow makes the drawn rectangle wider than the cube's with the light overhead.
  const auto overhead = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30,
                            with(kDrawEveryFrame, {"render.light_direction=[0.0, 0.0, 1.0]"}));
  ASSERT_EQ(footprint.size(), overhead.size());
  int wider = 0;
  for (size_t i = 0; i < footprint.size(); ++i)
    if (footprint[i].drawn && overhead[i].drawn && footprint[i].layer.rect_width > overhead[i].layer.rect_width + 20)
      ++wider;
  EXPECT_GT(wider, 10);
  EXPECT_LE(largest_difference(footprint, full), 1);
}

// Seed 003's hybrid on the courtyard of `arpipe bench hybrid`: four cubes stand all around the
// panorama's viewer, so that in most views one is ahead and others beside or behind the camera,
// their boxes and shadows cut by the near plane; the courtyard but its paving is one proxy that
// catches the shadows and casts its own, the paving the ground catcher. The footprint holds what is drawn (the same picture as the full
// canvas), and it is not the whole picture: neither the ground catcher's patch around all four
// cubes nor the courtyard proxy's box spreads it over the frame.
TEST(Footprint, ObjectsAllAroundAPanoramaViewerAreTheFullCanvasPicture) {
  const fs::path out = kBuild / "e2e-out" / "footprint-courtyard";
  fs::remove_all(out);
  fs::create_directories(out);
  std::string err;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpipe"),
                              {"simulate", "--scene", (kConfigs / "sim" / "courtyard.toml").string(), "--out",
                               (out / "still").string(), "--png", "--samples", "1", "--export-glb",
                               (out / "world.glb").string(), "--export-leave-out", "paving"},
                              out / "logs-simulate", &err),
            0)
      << err;
  // 30 degrees a frame from -10: every cube passes ahead, beside and behind.
  const std::vector<std::string> sweep = with(
      kDrawEveryFrame, {"source.panorama.file=\"" + (out / "still" / "frame_000000.png").string() + "\"",
                        "render.proxies.0.mesh=\"" + (out / "world.glb").string() + "\"",
                        "source.panorama.view.yaw_deg_per_s=900.0", "source.panorama.view.frames=12"});
  const auto footprint = run(kConfigs / "courtyard.toml", out, 12, sweep);
  const auto full = run(kConfigs / "courtyard.toml", out, 12, with(sweep, {"render.full_canvas=true"}));
  ASSERT_EQ(footprint.size(), 12u);
  int small = 0;
  for (const Shown& shown : footprint)
    if (shown.drawn && shown.layer.rect_width * shown.layer.rect_height < shown.layer.width * shown.layer.height / 4)
      ++small;
  EXPECT_GE(small, 6) << "frames drawn in less than a quarter of the picture";
  EXPECT_LE(largest_difference(footprint, full), 1);
}

// The tag-static capture: a still camera, its frames differing by sensor noise only. The
// tracker's frame-to-frame noise there (0.09 to 0.15 px at the cube's corners) stays under
// LayerReuse::kMaxMotionPx, so the layer is drawn once and handed on.
TEST(LayerReuse, AStillCameraReusesTheLayer) {
  const auto frames = run(kConfigs / "arpipe.toml", kBuild / "tag-static-capture", 10, {});
  ASSERT_EQ(drawn_frames(frames), 10);
  const int handed_on = int(std::count_if(frames.begin(), frames.end(), [](const Shown& s) {
    return s.render_skip.rfind("reused", 0) == 0;
  }));
  EXPECT_GE(handed_on, 8);
}

// The same first frame of tag-static ten times over: every pose is the same bit for bit, so the
// layer is handed on, and each frame must be the picture drawing it again gives.
TEST(LayerReuse, AFrozenFrameReusesTheLayerAndShowsTheSamePicture) {
  const fs::path frozen = kBuild / "e2e-out" / ("frozen-capture-" + std::to_string(getpid()));
  fs::remove_all(frozen);
  {
    const RecordingReader still(kBuild / "tag-static-capture");
    Frame first, frame;
    still.read(0, first);
    RecordingWriter writer(frozen, still.info(), still.camera_model());
    for (size_t k = 0; k < still.frame_count(); ++k) {
      still.read(k, frame);  // its own timestamps and exposure
      frame.data = first.data;
      writer.append(frame);
    }
  }
  const auto reused = run(kConfigs / "arpipe.toml", frozen, 10, {});
  const auto drawn = run(kConfigs / "arpipe.toml", frozen, 10, kDrawEveryFrame);
  fs::remove_all(frozen);
  ASSERT_EQ(drawn_frames(reused), 10);
  // Frame 0 draws (no layer yet) and so does frame 1 (the first motion estimate adds the
  // exposure's instants to what the layer depends on); every later one hands it on.
  for (const Shown& s : reused)
    EXPECT_EQ(s.render_skip.rfind("reused", 0) == 0, s.index >= 2) << "frame " << s.index << ": " << s.render_skip;
  EXPECT_LE(largest_difference(reused, drawn), 1);
}

// A moving camera never reuses: every frame's pose differs by pixels.
TEST(LayerReuse, AMovingCameraDrawsEveryFrame) {
  const auto frames = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30, {});
  for (const Shown& s : frames) EXPECT_NE(s.render_skip.rfind("reused", 0), 0u) << "frame " << s.index;
}

}  // namespace
}  // namespace arpipe
