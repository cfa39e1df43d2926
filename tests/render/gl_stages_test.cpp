// Tests of the render and composite stages through the public entry point (make_gl_stages):
// known geometry checked pixel by pixel against ray casting through the camera model, the
// compositing formula, exact pass-through of the camera background, and every skip and error path.
#include "render/gl_stages.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/image/pixel_convert.h"
#include "render/lens/lens_undistortion.h"
#include "render/lens/lens_warp_map.h"
#include "render/gl/render_errors.h"
#include "tests/scene/gltf_test_files.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 320, kHeight = 240;
const Vec3 kColor{0.8, 0.3, 0.1};
// builtin:cube at scale 2: 12 cm, standing on the anchor at its origin.
const Box kCube{{-0.06, -0.06, 0.0}, {0.06, 0.06, 0.12}};

Config cube_config(int msaa_samples) {
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";
  config.render.objects[0].scale = 2.0;
  config.render.objects[0].color = kColor;
  // Unlit: every covered pixel is exactly the base colour.
  config.render.ambient = {1, 1, 1};
  config.render.light_color = {0, 0, 0};
  config.render.msaa_samples = msaa_samples;
  return config;
}

std::shared_ptr<const CameraModel> pinhole_camera() {
  return std::make_shared<const CameraModel>(CameraModel::pinhole(300.0, 305.0, 161.3, 118.7, kWidth, kHeight));
}

std::shared_ptr<const CameraModel> opencv8_camera() {
  return std::make_shared<const CameraModel>(CameraModel(
      "LENSMODEL_OPENCV8", {300.0, 302.0, 158.9, 121.4, 0.35, -0.12, 0.0011, -0.0009, 0.02, 0.62, -0.05, 0.03}, kWidth,
      kHeight));
}

// Looking down at the cube from the front left, so three faces show.
SE3 oblique_pose() { return look_at({0.22, -0.33, 0.30}, {0.01, 0.0, 0.05}); }

// One harness (one GL context) for the whole suite: contexts and shader compiles cost time.
StageHarness& harness() {
  static StageHarness instance;
  return instance;
}

const uint8_t* pixel_at(const Frame& frame, int x, int y) {
  return frame.data.data() + size_t(y) * frame.bytes_per_line + size_t(x) * 3;
}

struct CoverageCounts {
  int inside = 0;
  int outside = 0;
  int wrong = 0;
};

// Inside pixels have the expected colour within 1 LSB (8-bit rounding of the sRGB encode after
// a half-float layer); outside pixels are the camera's bytes exactly.
CoverageCounts check_coverage(const FrameContext& ctx, const Frame& background, const SE3& pose, double band,
                              const std::array<int, 3>& expected) {
  CoverageCounts counts;
  const std::vector<PixelTruth> truth = classify_image(*ctx.camera_model, pose, kCube, band);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const uint8_t* out = pixel_at(ctx.output, x, y);
      const uint8_t* in = pixel_at(background, x, y);
      const PixelClass cls = truth[size_t(y) * kWidth + x].cls;
      bool right = true;
      if (cls == PixelClass::Inside) {
        ++counts.inside;
        for (size_t c = 0; c < 3; ++c) right = right && std::abs(out[c] - expected[c]) <= 1;
      } else if (cls == PixelClass::Outside) {
        ++counts.outside;
        for (size_t c = 0; c < 3; ++c) right = right && out[c] == in[c];
      }
      if (!right && ++counts.wrong <= 5)
        ADD_FAILURE() << (cls == PixelClass::Inside ? "inside" : "outside") << " pixel (" << x << ", " << y
                      << ") is (" << int(out[0]) << ", " << int(out[1]) << ", " << int(out[2]) << "), camera ("
                      << int(in[0]) << ", " << int(in[1]) << ", " << int(in[2]) << ")";
    }
  return counts;
}

std::array<int, 3> expected_unlit_color() {
  return {encode_srgb_8bit(kColor[0]), encode_srgb_8bit(kColor[1]), encode_srgb_8bit(kColor[2])};
}

TEST(RenderStages, PinholeCoverageIsExactAtPixelCentresWithoutMsaa) {
  harness().configure(cube_config(1));
  // Without multisampling a pixel is covered exactly when its centre is inside, up to the
  // rasteriser snapping vertices to its sub-pixel grid (2^-GL_SUBPIXEL_BITS px).
  GLint subpixel_bits = 4;
  glGetIntegerv(GL_SUBPIXEL_BITS, &subpixel_bits);
  const double band = std::ldexp(1.0, -subpixel_bits) + 0.005;
  const Frame background = varied_background(kWidth, kHeight);
  const SE3 pose = oblique_pose();
  FrameContext ctx = make_context(background, pinhole_camera(), pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);
  ASSERT_EQ(ctx.output.format, PixelFormat::RGB24);
  ASSERT_EQ(ctx.output.width, kWidth);
  ASSERT_EQ(ctx.output.height, kHeight);
  const CoverageCounts counts = check_coverage(ctx, background, pose, band, expected_unlit_color());
  EXPECT_EQ(counts.wrong, 0);
  std::cout << "band " << band << " px: " << counts.inside << " inside, " << counts.outside << " outside\n";
  EXPECT_GT(counts.inside, 2000);
  EXPECT_GT(counts.outside, 40000);
  ASSERT_NE(find_timing(ctx, "render"), nullptr);
  EXPECT_EQ(find_timing(ctx, "render")->skipped, "");
  ASSERT_NE(find_timing(ctx, "composite"), nullptr);
  EXPECT_EQ(find_timing(ctx, "composite")->skipped, "");
}

TEST(RenderStages, PinholeCoverageWithMsaa) {
  harness().configure(cube_config(4));
  const Frame background = varied_background(kWidth, kHeight);
  const SE3 pose = oblique_pose();
  FrameContext ctx = make_context(background, pinhole_camera(), pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);
  // 1 px: a multisampled edge pixel blends, and only pixels that far from the edge are pure.
  const CoverageCounts counts = check_coverage(ctx, background, pose, 1.0, expected_unlit_color());
  EXPECT_EQ(counts.wrong, 0);
  EXPECT_GT(counts.inside, 2000);
  EXPECT_GT(counts.outside, 40000);
}

CoverageCounts opencv8_coverage(const std::string& lens, double band) {
  Config config = cube_config(4);
  config.render.lens = *choice_value(kLensModeNames, lens);
  harness().configure(config);
  const Frame background = varied_background(kWidth, kHeight);
  // Off to the side of the image, where the lens bends the cube's edges most.
  const SE3 pose = look_at({0.12, -0.30, 0.26}, {-0.09, 0.02, 0.04});
  FrameContext ctx = make_context(background, opencv8_camera(), pose);
  harness().process(ctx);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
  if (!ctx.virtual_layer_drawn) return {};
  EXPECT_EQ(ctx.output_camera_model, ctx.camera_model);
  return check_coverage(ctx, background, pose, band, expected_unlit_color());
}

TEST(RenderStages, OpenCv8CoverageFollowsTheLensPerVertex) {
  // 1 px covers multisampled edges and the chords between the mesh's vertices (the lens is
  // applied per vertex; the cube's 8x8 grid per face keeps chord sag well under a pixel).
  const CoverageCounts counts = opencv8_coverage("vertex", 1.0);
  EXPECT_EQ(counts.wrong, 0);
  EXPECT_GT(counts.inside, 1500);
  EXPECT_GT(counts.outside, 40000);
}

TEST(RenderStages, OpenCv8CoverageFollowsTheLensThroughTheWarpMap) {
  // The warp samples the multisampled canvas bilinearly: what reaches a pixel comes from canvas
  // points within 1 texel (the taps) plus half a texel (the samples inside a texel) along each
  // axis, so within 1.5 sqrt(2) texels; in image pixels that is 1.5 sqrt(2) over the smallest
  // number of canvas texels per image pixel.
  const LensWarpMap map(*opencv8_camera(), cube_config(4).render.lens_canvas_scale);
  double texels_per_pixel = INFINITY;
  for (int y = 0; y + 1 < kHeight; ++y)
    for (int x = 0; x + 1 < kWidth; ++x) {
      const Vec2 c = map.at(x, y), right = map.at(x + 1, y), below = map.at(x, y + 1);
      texels_per_pixel = std::min({texels_per_pixel, std::hypot(right[0] - c[0], right[1] - c[1]),
                                   std::hypot(below[0] - c[0], below[1] - c[1])});
    }
  const double band = 1.5 * std::sqrt(2.0) / texels_per_pixel;
  std::cout << "smallest canvas texels per image pixel " << texels_per_pixel << ": band " << band << " px\n";
  const CoverageCounts counts = opencv8_coverage("map", band);
  EXPECT_EQ(counts.wrong, 0);
  EXPECT_GT(counts.inside, 1500);
  EXPECT_GT(counts.outside, 40000);
}

TEST(RenderStages, PinholeLensDrawsTheSameInMapAndVertexModes) {
  // A pinhole lens needs no warp: "map" draws straight into the image, byte for byte as "vertex".
  const Frame background = varied_background(kWidth, kHeight);
  std::vector<uint8_t> outputs[2];
  for (int i = 0; i < 2; ++i) {
    Config config = cube_config(4);
    config.render.lens = i == 0 ? LensMode::Map : LensMode::Vertex;
    harness().configure(config);
    FrameContext ctx = make_context(background, pinhole_camera(), oblique_pose());
    harness().process(ctx);
    ASSERT_TRUE(ctx.virtual_layer_drawn);
    outputs[i] = ctx.output.data;
  }
  EXPECT_TRUE(outputs[0] == outputs[1]);
}

TEST(RenderStages, LambertShadingPerFace) {
  Config config = cube_config(4);
  config.render.ambient = {0.1, 0.15, 0.2};
  config.render.light_color = {0.9, 0.8, 0.7};
  config.render.light_direction = normalized(Vec3{-0.5, -0.8, 0.6});  // lights -y and +z; +x faces away
  harness().configure(config);
  const Frame background = varied_background(kWidth, kHeight);
  const SE3 pose = oblique_pose();
  FrameContext ctx = make_context(background, pinhole_camera(), pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);
  const Vec3 normals[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  std::set<int> faces_seen;
  const std::vector<PixelTruth> truth = classify_image(*ctx.camera_model, pose, kCube, 1.0);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const PixelTruth& pixel = truth[size_t(y) * kWidth + x];
      if (pixel.cls != PixelClass::Inside) continue;
      const int face = pixel.face;
      faces_seen.insert(face);
      const double lambert = std::max(dot(normals[face], config.render.light_direction), 0.0);
      const uint8_t* out = pixel_at(ctx.output, x, y);
      for (size_t c = 0; c < 3; ++c) {
        const double linear = kColor[c] * (config.render.ambient[c] + config.render.light_color[c] * lambert);
        // 1 LSB: 8-bit rounding after a half-float layer; a wrong normal or light is far off.
        ASSERT_NEAR(out[c], encode_srgb_8bit(linear), 1) << "face " << face << " pixel (" << x << ", " << y << ")";
      }
    }
  EXPECT_EQ(faces_seen, (std::set<int>{1, 2, 5})) << "the view should show the +x, -y and +z faces";
}

TEST(RenderStages, EdgePixelsFollowThePremultipliedFormula) {
  harness().configure(cube_config(4));
  const Frame background = varied_background(kWidth, kHeight);
  const SE3 pose = oblique_pose();
  FrameContext ctx = make_context(background, pinhole_camera(), pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);
  // With 4 samples per pixel an edge pixel's coverage a is k/4, and the virtual layer holds
  // (a * colour, a). The output must be encode(a * colour + (1 - a) * decode(camera)) for one
  // such a in all three channels (1 LSB). Compositing in sRGB space, or multiplying by alpha
  // twice, misses that by several LSB at half coverage for these colours.
  int fractional = 0, edge_pixels = 0;
  const std::vector<PixelTruth> truth = classify_image(*ctx.camera_model, pose, kCube, 1.0);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      if (truth[size_t(y) * kWidth + x].cls != PixelClass::Edge) continue;
      ++edge_pixels;
      const uint8_t* out = pixel_at(ctx.output, x, y);
      const uint8_t* in = pixel_at(background, x, y);
      std::vector<int> matches;
      for (int k = 0; k <= 4; ++k) {
        const double a = k / 4.0;
        bool all = true;
        for (size_t c = 0; c < 3; ++c) {
          const double linear = a * kColor[c] + (1 - a) * decode_srgb(in[c] / 255.0);
          all = all && std::abs(out[c] - encode_srgb_8bit(linear)) <= 1;
        }
        if (all) matches.push_back(k);
      }
      ASSERT_FALSE(matches.empty()) << "edge pixel (" << x << ", " << y << ") = (" << int(out[0]) << ", "
                                    << int(out[1]) << ", " << int(out[2]) << ") over (" << int(in[0]) << ", "
                                    << int(in[1]) << ", " << int(in[2]) << ") fits no coverage k/4";
      if (matches.size() == 1 && matches[0] != 0 && matches[0] != 4) ++fractional;
    }
  std::cout << edge_pixels << " edge pixels, " << fractional << " with an unambiguous partial coverage\n";
  EXPECT_GT(fractional, 50);
}

TEST(RenderStages, CameraBytesRoundTripExactlyInsideTheDrawnRectangle) {
  harness().configure(cube_config(4));
  const Frame background = varied_background(kWidth, kHeight);
  const SE3 pose = oblique_pose();
  FrameContext ctx = make_context(background, pinhole_camera(), pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);
  // Pixels near the cube but not covered lie inside the GL rectangle (the cube's box projection
  // plus its margin), where they went through decode, composite with alpha 0 and encode. They
  // must come out as they went in, for every byte value.
  const std::vector<PixelTruth> truth = classify_image(*ctx.camera_model, pose, kCube, 1.0);
  int min_x = kWidth, max_x = 0, min_y = kHeight, max_y = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (truth[size_t(y) * kWidth + x].cls != PixelClass::Outside) {
        min_x = std::min(min_x, x), max_x = std::max(max_x, x), min_y = std::min(min_y, y), max_y = std::max(max_y, y);
      }
  std::array<std::set<int>, 3> values_seen;
  for (int y = min_y; y <= max_y; ++y)
    for (int x = min_x; x <= max_x; ++x) {
      if (truth[size_t(y) * kWidth + x].cls != PixelClass::Outside) continue;
      const uint8_t* out = pixel_at(ctx.output, x, y);
      const uint8_t* in = pixel_at(background, x, y);
      for (size_t c = 0; c < 3; ++c) {
        ASSERT_EQ(out[c], in[c]) << "pixel (" << x << ", " << y << ") channel " << c;
        values_seen[c].insert(in[c]);
      }
    }
  for (size_t c = 0; c < 3; ++c) EXPECT_EQ(values_seen[c].size(), 256u) << "channel " << c;
}

// Pass-through: a frame in the camera's own format (YUYV here), converted exactly as to_rgb24 does.
void expect_pass_through(const FrameContext& ctx, const Frame& camera_frame, const std::string& render_skip) {
  EXPECT_FALSE(ctx.virtual_layer_drawn);
  std::vector<uint8_t> expected;
  to_rgb24(camera_frame, expected);
  ASSERT_EQ(ctx.output.format, PixelFormat::RGB24);
  ASSERT_EQ(ctx.output.width, camera_frame.width);
  ASSERT_EQ(ctx.output.height, camera_frame.height);
  EXPECT_TRUE(ctx.output.data == expected) << "output differs from to_rgb24(camera)";
  EXPECT_EQ(ctx.output.meta.sequence, camera_frame.meta.sequence);
  const StageTiming* render = find_timing(ctx, "render");
  ASSERT_NE(render, nullptr);
  EXPECT_EQ(render->skipped.substr(0, render_skip.size()), render_skip) << render->skipped;
  const StageTiming* composite = find_timing(ctx, "composite");
  ASSERT_NE(composite, nullptr);
  EXPECT_FALSE(composite->skipped.empty());
}

Frame yuyv_camera_frame() {
  const Frame rgb = varied_background(kWidth, kHeight);
  Frame frame = from_rgb24(rgb.data.data(), kWidth, kHeight, PixelFormat::YUYV);
  frame.meta.sequence = 42;
  return frame;
}

TEST(RenderStages, LostPoseIsAPassThrough) {
  harness().configure(cube_config(4));
  const Frame camera_frame = yuyv_camera_frame();
  FrameContext ctx = make_context(camera_frame, pinhole_camera(), oblique_pose(), TrackState::Lost);
  harness().process(ctx);
  expect_pass_through(ctx, camera_frame, "pose lost");
}

TEST(RenderStages, ObjectsOutOfViewIsAPassThrough) {
  harness().configure(cube_config(4));
  const Frame camera_frame = yuyv_camera_frame();
  // Looking away from the anchor.
  FrameContext ctx = make_context(camera_frame, pinhole_camera(), look_at({0.2, -0.3, 0.3}, {1.0, -1.5, 0.3}));
  harness().process(ctx);
  expect_pass_through(ctx, camera_frame, "objects out of view");
}

TEST(RenderStages, DisabledRenderingIsAPassThrough) {
  Config config = cube_config(4);
  config.render.enabled = false;
  harness().configure(config);
  const Frame camera_frame = yuyv_camera_frame();
  FrameContext ctx = make_context(camera_frame, pinhole_camera(), oblique_pose());
  harness().process(ctx);
  expect_pass_through(ctx, camera_frame, "render disabled");
}

TEST(RenderStages, UnsupportedLensModelIsRecordedAndPassesThrough) {
  Config config = cube_config(4);
  config.render.lens = LensMode::Vertex;  // the vertex shader knows PINHOLE and OPENCVn only
  harness().configure(config);
  const Frame camera_frame = yuyv_camera_frame();
  auto stereographic =
      std::make_shared<const CameraModel>("LENSMODEL_STEREOGRAPHIC", std::vector<double>{300, 300, 159.5, 119.5}, kWidth, kHeight);
  FrameContext ctx = make_context(camera_frame, stereographic, oblique_pose());
  harness().process(ctx);
  expect_pass_through(ctx, camera_frame,
                      "error: lens model LENSMODEL_STEREOGRAPHIC is not supported by render.lens = \"vertex\"");
  EXPECT_EQ(ctx.output_camera_model, stereographic);
}

TEST(RenderStages, LensTooWideForTheCanvasIsRecordedAndPassesThrough) {
  harness().configure(cube_config(4));  // render.lens = "map"
  const Frame camera_frame = yuyv_camera_frame();
  // Stereographic with f = 80 px: the corners of 320x240 are 2 atan(200 / 160) = 103 degrees off axis.
  auto fisheye =
      std::make_shared<const CameraModel>("LENSMODEL_STEREOGRAPHIC", std::vector<double>{80, 80, 159.5, 119.5}, kWidth, kHeight);
  FrameContext ctx = make_context(camera_frame, fisheye, oblique_pose());
  harness().process(ctx);
  expect_pass_through(ctx, camera_frame, "error: lens model LENSMODEL_STEREOGRAPHIC sees rays 10");
}

TEST(RenderStages, CameraModelOfAnotherSizeIsRecordedAndPassesThrough) {
  harness().configure(cube_config(4));
  const Frame camera_frame = yuyv_camera_frame();
  auto other_size = std::make_shared<const CameraModel>(CameraModel::pinhole(300, 300, 319.5, 239.5, 640, 480));
  FrameContext ctx = make_context(camera_frame, other_size, oblique_pose());
  harness().process(ctx);
  expect_pass_through(ctx, camera_frame, "error: the camera frame is 320x240 but the camera model is for 640x480");
}

// Signed distance (pixels, positive inside) of a point to a triangle given counter-clockwise or
// clockwise: the smallest distance to its three edge lines, negated when outside any.
double signed_distance_to_triangle(const Vec2& p, const std::array<Vec2, 3>& t) {
  const double area = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
  double distance = INFINITY;
  for (size_t i = 0; i < 3; ++i) {
    const Vec2& a = t[i];
    const Vec2& b = t[(i + 1) % 3];
    const double edge = std::hypot(b[0] - a[0], b[1] - a[1]);
    const double cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    distance = std::min(distance, (area > 0 ? cross : -cross) / edge);
  }
  return distance;
}

TEST(RenderStages, GltfObjectRendersWithItsMaterialColourWhereTheConfigPlacesIt) {
  const std::filesystem::path dir = std::filesystem::path(ARPIPE_BINARY_DIR) / "test_tmp" / "render_stages";
  std::filesystem::create_directories(dir / "meshes");
  render_test::TriangleOptions options;
  options.node_transform = R"("scale": [0.1, 0.1, 0.1])";
  std::ofstream(dir / "meshes" / "triangle.gltf") << render_test::triangle_gltf(options);

  Config config = cube_config(4);
  config.file = dir / "scene.toml";
  config.render.objects[0].mesh = (dir / "meshes" / "triangle.gltf").string();
  config.render.objects[0].scale = 1.5;
  config.render.objects[0].yaw_rad = 0.3;
  config.render.objects[0].position_m = {0.02, 0.01, 0.0};
  harness().configure(config);

  const Frame background = varied_background(kWidth, kHeight);
  const SE3 pose = look_at({0.12, -0.35, 0.12}, {0.04, 0.0, 0.05});
  FrameContext ctx = make_context(background, pinhole_camera(), pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);

  // The glTF triangle (0,0,0), (1,0,0), (0,1,0) scaled by 0.1 is, in the z-up object frame,
  // (0,0,0), (0.1,0,0), (0,0,0.1); the config scales, turns and moves it onto the anchor.
  const SE3 T_world_object = SE3::from_rt({0, 0, 0.3}, {0.02, 0.01, 0.0});
  std::array<Vec2, 3> corners;
  const Vec3 object_corners[3] = {{0, 0, 0}, {0.1, 0, 0}, {0, 0, 0.1}};
  for (size_t i = 0; i < 3; ++i) corners[i] = *ctx.camera_model->project(pose * (T_world_object * (1.5 * object_corners[i])));
  // The file's baseColorFactor (0.2, 0.4, 0.6), unlit.
  const std::array<int, 3> expected{encode_srgb_8bit(0.2), encode_srgb_8bit(0.4), encode_srgb_8bit(0.6)};
  int inside = 0, wrong = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double distance = signed_distance_to_triangle({double(x), double(y)}, corners);
      const uint8_t* out = pixel_at(ctx.output, x, y);
      const uint8_t* in = pixel_at(background, x, y);
      bool right = true;
      if (distance > 1.0) {  // 1 px: multisampled edges
        ++inside;
        for (size_t c = 0; c < 3; ++c) right = right && std::abs(out[c] - expected[c]) <= 1;
      } else if (distance < -1.0) {
        for (size_t c = 0; c < 3; ++c) right = right && out[c] == in[c];
      }
      if (!right && ++wrong <= 5) ADD_FAILURE() << "pixel (" << x << ", " << y << ") distance " << distance;
    }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(inside, 1000);
}

TEST(RenderStages, MissingMeshFileFailsConfigureNamingTheFile) {
  harness().configure(cube_config(4));  // the configuration that must survive the refused one
  Config config = cube_config(4);
  config.file = std::filesystem::path(ARPIPE_BINARY_DIR) / "test_tmp" / "configs" / "scene.toml";
  config.render.objects[0].mesh = (config.file.parent_path() / "meshes" / "missing.gltf").string();
  try {
    harness().configure(config);
    FAIL() << "expected AssetError";
  } catch (const AssetError& e) {
    const std::string expected_path = (config.file.parent_path() / "meshes" / "missing.gltf").string();
    EXPECT_NE(std::string(e.what()).find(expected_path), std::string::npos) << e.what();
  }
  // The stage kept its previous configuration and still renders.
  const Frame background = varied_background(kWidth, kHeight);
  FrameContext ctx = make_context(background, pinhole_camera(), oblique_pose());
  harness().process(ctx);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
}

TEST(RenderStages, UnknownBuiltinMeshFailsConfigureNamingTheKey) {
  Config config = cube_config(4);
  config.file = "scene.toml";
  config.render.objects[0].mesh = "builtin:teapot";
  try {
    harness().configure(config);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("render.objects[0].mesh"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("builtin:teapot"), std::string::npos) << e.what();
  }
}

TEST(RenderStages, UndistortModeUndistortsEveryFrameAndSaysSo) {
  Config config = cube_config(4);
  config.render.lens = LensMode::Undistort;
  harness().configure(config);
  const Frame camera_frame = yuyv_camera_frame();
  Frame rgb = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  to_rgb24(camera_frame, rgb.data);
  Frame undistorted;
  const LensUndistortion undistortion(*opencv8_camera());
  undistortion.apply(rgb, undistorted);
  const CameraModel& core = *undistortion.pinhole_core();
  // Nothing drawn (pose lost): the undistorted frame, made on the CPU, with the core as its model.
  FrameContext lost = make_context(camera_frame, opencv8_camera(), oblique_pose(), TrackState::Lost);
  harness().process(lost);
  EXPECT_FALSE(lost.virtual_layer_drawn);
  EXPECT_TRUE(lost.output.data == undistorted.data);
  ASSERT_NE(lost.output_camera_model, nullptr);
  EXPECT_EQ(lost.output_camera_model->lensmodel(), "LENSMODEL_PINHOLE");
  EXPECT_EQ(lost.output_camera_model->intrinsics(), core.intrinsics());
  // Drawn: the cube where the pinhole core sees it, over the undistorted frame.
  const SE3 pose = oblique_pose();
  FrameContext drawn = make_context(camera_frame, opencv8_camera(), pose);
  harness().process(drawn);
  ASSERT_TRUE(drawn.virtual_layer_drawn);
  EXPECT_EQ(drawn.output_camera_model->lensmodel(), "LENSMODEL_PINHOLE");
  const std::vector<PixelTruth> truth = classify_image(core, pose, kCube, 1.0);
  const std::array<int, 3> expected = expected_unlit_color();
  int inside = 0, wrong = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const PixelClass cls = truth[size_t(y) * kWidth + x].cls;
      const uint8_t* out = pixel_at(drawn.output, x, y);
      const uint8_t* in = pixel_at(undistorted, x, y);
      bool right = true;
      if (cls == PixelClass::Inside) {
        ++inside;
        for (size_t c = 0; c < 3; ++c) right = right && std::abs(out[c] - expected[c]) <= 1;
      } else if (cls == PixelClass::Outside) {
        for (size_t c = 0; c < 3; ++c) right = right && out[c] == in[c];
      }
      if (!right && ++wrong <= 5) ADD_FAILURE() << "pixel (" << x << ", " << y << ")";
    }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(inside, 2000);
}

}  // namespace
}  // namespace arpipe
