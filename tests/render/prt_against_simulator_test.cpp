// Environment light against the simulator: virtual objects lit by a known HDR environment, drawn by
// the render stages (SH irradiance, unshadowed and shadowed PRT) and ray traced by the simulator
// (capture/sim: cosine-weighted sky samples with shadow rays, independent of render/), compared
// pixel by pixel in linear radiance.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <filesystem>
#include <numbers>

#include "capture/sim/embree_scene.h"
#include "capture/sim/sample_rng.h"
#include "capture/sim/scene_shader.h"
#include "core/image/radiance_hdr.h"
#include "core/environment/environment_light.h"
#include "core/environment/hdr_environment.h"
#include "core/environment/environment_layout.h"
#include "core/scene/builtin_meshes.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;
namespace fs = std::filesystem;

constexpr int kWidth = 320, kHeight = 240;
constexpr int kStep = 3;             // every third pixel each way: the simulator's cost
constexpr int kTruthSamples = 1024;  // sky samples per pixel: ~1 % noise per pixel
const Vec3 kAlbedo{0.8, 0.8, 0.8};

// A smooth sky all round (no ground: the objects float, so nothing but themselves occludes):
// a vertical gradient, a warm broad window lobe and a cool one, radiance below 1.
Vec3 environment_radiance(const Vec3& d) {
  const Vec3 warm_dir = normalized(Vec3{0.6, -0.5, 0.62});
  const Vec3 cool_dir = normalized(Vec3{-0.7, 0.4, 0.2});
  const double warm = std::pow(std::max(0.0, dot(d, warm_dir)), 3);
  const double cool = std::pow(std::max(0.0, dot(d, cool_dir)), 2);
  const double base = 0.18 + 0.08 * d[2];
  return {base + 0.55 * warm + 0.05 * cool, base + 0.42 * warm + 0.12 * cool, base + 0.25 * warm + 0.3 * cool};
}

// The same sky twice: in the simulator's equirectangular convention (sim_textures.h) and in
// arpipe's (probe_layout.h, probe up = world +z, forward = world +y).
struct SkyFiles {
  fs::path simulator, pipeline;
};

const SkyFiles& sky_files() {
  static const SkyFiles files = [] {
    const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test-prt-sky";
    fs::create_directories(dir);
    constexpr int H = 128, W = 256;
    HdrImage sim, ours;
    sim.width = ours.width = W;
    sim.height = ours.height = H;
    sim.rgb.resize(size_t(W) * H * 3);
    ours.rgb.resize(size_t(W) * H * 3);
    const Mat3 R_world_probe = default_world_from_probe(0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const double phi = 2 * std::numbers::pi * (x + 0.5) / W, theta = std::numbers::pi * (y + 0.5) / H;
        const Vec3 sim_dir{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
        const Vec3 our_dir = mat_mul(R_world_probe, *environment_pixel_direction(EnvironmentLayout::Equirectangular, W, H, x, y));
        const Vec3 a = environment_radiance(sim_dir), b = environment_radiance(our_dir);
        for (size_t c = 0; c < 3; ++c) {
          sim.rgb[(size_t(y) * W + x) * 3 + c] = float(a[c]);
          ours.rgb[(size_t(y) * W + x) * 3 + c] = float(b[c]);
        }
      }
    SkyFiles out{dir / "sky-simulator.hdr", dir / "sky-arpipe.hdr"};
    write_radiance_hdr(out.simulator, sim);
    write_radiance_hdr(out.pipeline, ours);
    return out;
  }();
  return files;
}

StageHarness& harness() {
  static StageHarness instance;
  return instance;
}

std::shared_ptr<const CameraModel> camera() {
  return std::make_shared<const CameraModel>(CameraModel::pinhole(300.0, 300.0, 159.5, 119.5, kWidth, kHeight));
}

Config object_config(const std::string& mesh, ObjectPrt prt) {
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = mesh;
  config.render.objects[0].color = kAlbedo;
  config.render.objects[0].prt = prt;
  config.render.prt.samples = 24;
  config.render.prt.cache_dir = fs::path(ARPIPE_BINARY_DIR) / "test-cache" / "prt-simulator-test";
  config.render.msaa_samples = 0;
  config.render.shadows.method = ShadowMethod::Off;
  config.light.source = LightSource::Environment;
  config.light.environment.file = sky_files().pipeline;
  config.light.environment.layout = EnvironmentLayout::Equirectangular;
  return config;
}

// Linear radiance per sampled pixel (row-major over the kStep grid), from the render stages with
// exposure 1 s and gain 1 (so linear pixel = scene-linear radiance) over a black frame.
std::vector<Vec3> render(const Config& config, const SE3& T_cam_world) {
  harness().configure(config);
  Frame black = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(black.data.begin(), black.data.end(), uint8_t{0});
  FrameContext ctx = make_context(black, camera(), T_cam_world);
  ctx.camera.meta.exposure_ns = 1'000'000'000;
  ctx.light = load_environment_lighting(config).estimate;
  harness().process(ctx);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
  std::vector<Vec3> out;
  for (int y = 0; y < kHeight; y += kStep)
    for (int x = 0; x < kWidth; x += kStep) {
      const uint8_t* p = ctx.output.data.data() + size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3;
      out.push_back({decode_srgb(p[0] / 255.0), decode_srgb(p[1] / 255.0), decode_srgb(p[2] / 255.0)});
    }
  return out;
}

struct Truth {
  std::vector<Vec3> radiance;   // per sampled pixel
  std::vector<bool> interior;   // the pixel and its 8 neighbours (kStep apart... 1 px apart) see the object
  std::vector<Vec3> hit_point;  // world, where the pixel's ray meets the object
};

Truth ray_trace(const sim::SimObject& object, const SE3& T_cam_world) {
  sim::SimScene scene;
  scene.environment.hdr_path = sky_files().simulator;
  scene.environment.radiance = {1, 1, 1};
  scene.objects = {object};
  const sim::SceneShader shader(scene, true);
  const std::shared_ptr<const CameraModel> model = camera();
  const SE3 T_world_cam = T_cam_world.inverse();
  const Vec3 eye = T_world_cam.translation();
  const auto ray = [&](double x, double y) {
    return normalized(mat_mul(T_world_cam.rotation(), *model->unproject({x, y})));
  };
  Truth truth;
  uint64_t stream = 0;
  for (int y = 0; y < kHeight; y += kStep)
    for (int x = 0; x < kWidth; x += kStep) {
      bool interior = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) interior = interior && shader.sees_virtual_object(eye, ray(x + dx, y + dy));
      truth.interior.push_back(interior);
      Vec3 sum{0, 0, 0};
      if (interior) {
        sim::SampleRng rng(7, ++stream);
        for (int s = 0; s < kTruthSamples; ++s) {
          const sim::Rgb r = shader.radiance(eye, ray(x, y), rng);
          sum = sum + Vec3{r[0], r[1], r[2]};
        }
      }
      truth.radiance.push_back((1.0 / kTruthSamples) * sum);
    }
  return truth;
}

struct Errors {
  double mean_relative = 0;  // mean |render - truth| / mean truth, luminance, over the pixels
  int pixels = 0;
};

// The sampled pixels as a small linear image, so that a person can look at what was compared
// (build/test-prt-sky/cup-*.hdr, in any HDR viewer).
void write_sampled(const std::string& name, const std::vector<Vec3>& pixels) {
  HdrImage image;
  image.width = (kWidth + kStep - 1) / kStep;
  image.height = (kHeight + kStep - 1) / kStep;
  for (const Vec3& p : pixels)
    for (double c : p) image.rgb.push_back(static_cast<float>(std::max(0.0, c)));
  write_radiance_hdr(fs::path(ARPIPE_BINARY_DIR) / "test-prt-sky" / (name + ".hdr"), image);
}

double luminance(const Vec3& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

Errors compare(const std::vector<Vec3>& rendered, const Truth& truth, const std::vector<bool>& selected) {
  double error = 0, level = 0;
  Errors out;
  for (size_t i = 0; i < rendered.size(); ++i) {
    if (!truth.interior[i] || !selected[i]) continue;
    error += std::abs(luminance(rendered[i]) - luminance(truth.radiance[i]));
    level += luminance(truth.radiance[i]);
    ++out.pixels;
  }
  out.mean_relative = level > 0 ? error / level : 0;
  return out;
}

TEST(PrtAgainstSimulator, DiffuseSphereInAKnownEnvironmentMatchesRayTracing) {
  const SE3 pose = look_at({0.16, -0.20, 0.12}, {0, 0, 0.03});
  sim::SimObject sphere;
  sphere.name = "sphere";
  sphere.shape = sim::SimObject::Shape::Sphere;
  sphere.T_world_object = SE3(identity3(), {0, 0, 0.03});
  sphere.radius_m = 0.03;
  sphere.material.albedo = {kAlbedo[0], kAlbedo[1], kAlbedo[2]};
  sphere.is_virtual = true;
  const Truth truth = ray_trace(sphere, pose);
  const std::vector<bool> all(truth.interior.size(), true);
  for (const ObjectPrt prt : {ObjectPrt::Off, ObjectPrt::Shadowed}) {
    const Errors errors = compare(render(object_config("builtin:sphere", prt), pose), truth, all);
    ASSERT_GT(errors.pixels, 300) << object_prt_name(prt);
    // 3 %: 9 coefficients of a smooth sky give ~1 % irradiance error (bench sh), the 1024-sample
    // truth ~1 % noise per pixel, 8-bit output ~0.3 %, the 24-ring mesh's facets well under 1 %.
    EXPECT_LT(errors.mean_relative, 0.03) << "prt = " << object_prt_name(prt) << " over " << errors.pixels << " pixels";
    RecordProperty("sphere_error_" + std::string(object_prt_name(prt)), std::to_string(errors.mean_relative));
    std::cout << "sphere, prt = " << object_prt_name(prt) << ": mean error " << errors.mean_relative << " over " << errors.pixels
              << " pixels\n";
  }
}

TEST(PrtAgainstSimulator, ShadowedTransferIsCloserThanUnshadowedInsideAConcaveModel) {
  // Looking down into the cup's pit, whose walls hide much of the sky from its floor.
  const SE3 pose = look_at({0.09, -0.13, 0.21}, {0, 0, 0.02});
  sim::SimObject cup;
  cup.name = "cup";
  cup.shape = sim::SimObject::Shape::Mesh;
  cup.mesh_builtin = "builtin:cup";
  cup.material.albedo = {kAlbedo[0], kAlbedo[1], kAlbedo[2]};
  cup.is_virtual = true;
  const Truth truth = ray_trace(cup, pose);
  // The pixels that see into the pit (below its rim), by casting the same rays at the same mesh.
  sim::EmbreeScene geometry;
  const Mesh mesh = make_cup_mesh();
  geometry.add_triangles(mesh.positions, mesh.indices, {});
  geometry.commit();
  const SE3 T_world_cam = pose.inverse();
  const std::shared_ptr<const CameraModel> model = camera();
  std::vector<bool> in_pit, all;
  for (int y = 0; y < kHeight; y += kStep)
    for (int x = 0; x < kWidth; x += kStep) {
      const Vec3 dir = normalized(mat_mul(T_world_cam.rotation(), *model->unproject({double(x), double(y)})));
      const sim::ShapeHit hit = geometry.intersect(T_world_cam.translation(), dir);
      const Vec3 p = T_world_cam.translation() + hit.t * dir;
      in_pit.push_back(hit.hit() && p[2] < 0.06 - 1e-3 && std::abs(p[0]) < 0.02 && std::abs(p[1]) < 0.02);
      all.push_back(true);
    }
  const std::vector<Vec3> unshadowed = render(object_config("builtin:cup", ObjectPrt::Unshadowed), pose);
  const std::vector<Vec3> shadowed = render(object_config("builtin:cup", ObjectPrt::Shadowed), pose);
  write_sampled("cup-ray-traced", truth.radiance);
  write_sampled("cup-prt-unshadowed", unshadowed);
  write_sampled("cup-prt-shadowed", shadowed);
  const Errors pit_unshadowed = compare(unshadowed, truth, in_pit), pit_shadowed = compare(shadowed, truth, in_pit);
  const Errors all_unshadowed = compare(unshadowed, truth, all), all_shadowed = compare(shadowed, truth, all);
  ASSERT_GT(pit_shadowed.pixels, 100) << "the view should look into the pit";
  RecordProperty("pit_error_unshadowed", std::to_string(pit_unshadowed.mean_relative));
  RecordProperty("pit_error_shadowed", std::to_string(pit_shadowed.mean_relative));
  // Unshadowed transfer lights the pit's floor and walls with the whole sky; the walls hide most
  // of it, so it is far off. Shadowed transfer keeps the 3-band part of visibility x cosine.
  EXPECT_LT(pit_shadowed.mean_relative, 0.5 * pit_unshadowed.mean_relative)
      << "pit: shadowed " << pit_shadowed.mean_relative << " unshadowed " << pit_unshadowed.mean_relative;
  // 12 %: 3 bands hold only the smooth part of the pit's visibility (bench prt: the 3-band
  // product's error at the pit floor), plus Gouraud interpolation over 5.6 mm of wall per vertex.
  EXPECT_LT(pit_shadowed.mean_relative, 0.12);
  EXPECT_LT(all_shadowed.mean_relative, all_unshadowed.mean_relative);
  std::cout << "pit error: shadowed " << pit_shadowed.mean_relative << ", unshadowed " << pit_unshadowed.mean_relative
            << " (" << pit_shadowed.pixels << " pixels); whole cup: shadowed " << all_shadowed.mean_relative
            << ", unshadowed " << all_unshadowed.mean_relative << "\n";
}

}  // namespace
}  // namespace arpipe
