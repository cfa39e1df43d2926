// Objects that move (SimObject::keyframes) through simulate(): a 360-degree video whose frames show
// each object where object_pose_at puts it at the frame's exposure start (the real one in the
// camera frames, the virtual one in the ground-truth coverage), and a static scene whose frames
// stay bit for bit what they were when its world is rebuilt for every frame.
#include "capture/sim/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "capture/recording/recording_reader.h"
#include "capture/sim/ground_truth_coverage.h"
#include "core/image/pixel_convert.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

constexpr double kPi = std::numbers::pi;

struct Centroid {
  double x = 0, y = 0, weight = 0;
};

// The weighted centroid of an image whose weight at (x, y) is weight(x, y) in [0, 1].
template <typename Weight>
Centroid centroid(int width, int height, Weight weight) {
  Centroid c;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double w = weight(x, y);
      c.x += w * x;
      c.y += w * y;
      c.weight += w;
    }
  if (c.weight > 0) {
    c.x /= c.weight;
    c.y /= c.weight;
  }
  return c;
}

SimObject ball(const std::string& name, double radius_m, const Rgb& albedo, const Vec3& from, const Vec3& to,
               double duration_s) {
  SimObject object;
  object.name = name;
  object.shape = SimObject::Shape::Sphere;
  object.radius_m = radius_m;
  object.material.albedo = albedo;
  object.keyframes = {{0.0, SE3(identity3(), from)}, {duration_s, SE3(identity3(), to)}};
  object.T_world_object = object.keyframes.front().T_world_object;
  return object;
}

// A 512 x 256 equirectangular camera at the origin looking along +y under a grey sky of radiance 1:
// every unshadowed Lambertian surface has radiance = its albedo, the sky 1 (0.5 of full scale).
SimScene lonlat_sky_scene() {
  SimScene scene;
  const int width = 512, height = 256;
  scene.camera = exact_camera(width, height, 100);
  scene.camera.model = CameraModel("LENSMODEL_LONLAT", {width / (2 * kPi), height / kPi, (width - 1) / 2.0, (height - 1) / 2.0},
                                   width, height);
  scene.camera.fps = 30;
  // A long exposure: were objects placed at its middle rather than its start, they would be 10 cm
  // (about 8 px) off.
  scene.camera.exposure_ns = {20'000'000};
  scene.camera.sensor.sensitivity = 25;  // 1 W/(m^2 sr) x 20 ms x 25 = 0.5
  scene.environment.radiance = {1, 1, 1};
  scene.trajectory = still({0, 0, 0}, {0, 1, 0}, {0, 0, 1});
  scene.render.samples_per_pixel = 16;
  return scene;
}

TEST(AnimatedSimulation, EachFrameShowsTheObjectsWhereTheirKeysPutThemAtItsExposureStart) {
  SimScene scene = lonlat_sky_scene();
  // A red ball crossing the view left to right below the horizon at 10 m/s, and a virtual one
  // right to left above it: 0.33 m, some 25 px, a frame.
  scene.objects.push_back(ball("real", 0.1, {0.9, 0.05, 0.05}, {-0.5, 1, -0.25}, {0.5, 1, -0.25}, 0.1));
  scene.objects.push_back(ball("virtual", 0.1, {0.05, 0.9, 0.05}, {0.5, 1, 0.25}, {-0.5, 1, 0.25}, 0.1));
  scene.objects.back().is_virtual = true;
  const fs::path dir = scratch_dir("animated-lonlat");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 3;
  simulate(scene, options);

  const RecordingReader reader(dir);
  const CameraModel& model = reader.camera_model();
  ASSERT_EQ(reader.frame_count(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    const double t = double(k) / scene.camera.fps;  // what a video player shows frame k at
    const SE3& T_cam_world = reader.ground_truth()[k].T_cam_world_start;
    Frame frame;
    reader.read(k, frame);
    std::vector<uint8_t> rgb;
    to_rgb24(frame, rgb);
    // The real ball in the camera frame: the share of the pixel it covers, from how far its green
    // falls from the sky's (0.5 full scale) towards the ball's (0.025).
    const double sky = 0.5 * 255, red_ball = 0.025 * 255;
    const Centroid real = centroid(model.width(), model.height(), [&](int x, int y) {
      const double g = rgb[(size_t(y) * size_t(model.width()) + size_t(x)) * 3 + 1];
      return std::clamp((sky - g) / (sky - red_ball), 0.0, 1.0);
    });
    const auto real_at = model.project(T_cam_world * object_pose_at(scene.objects[0], t).translation());
    ASSERT_TRUE(real_at.has_value());
    // The ball is about 140 px; a wrong time by a frame would be 25 px off, by half the exposure 4 px.
    EXPECT_GT(real.weight, 100);
    EXPECT_NEAR(real.x, (*real_at)[0], 0.25);
    EXPECT_NEAR(real.y, (*real_at)[1], 0.25);

    // The virtual ball, in the ground-truth coverage.
    const CoverageImage coverage = read_coverage_frame(dir, k);
    const Centroid virt = centroid(coverage.width, coverage.height, [&](int x, int y) { return double(coverage.at(x, y)); });
    const auto virtual_at = model.project(T_cam_world * object_pose_at(scene.objects[1], t).translation());
    ASSERT_TRUE(virtual_at.has_value());
    EXPECT_GT(virt.weight, 100);
    EXPECT_NEAR(virt.x, (*virtual_at)[0], 0.25);
    EXPECT_NEAR(virt.y, (*virtual_at)[1], 0.25);
  }
  fs::remove_all(dir);
}

// A small scene of every kind of object (a textured plane, a sphere, a mesh, a virtual mesh) with
// the sensor's noise on and a composite.
SimScene mixed_scene() {
  SimScene scene;
  scene.camera = exact_camera(96, 72, 90);
  scene.camera.pixel_format = PixelFormat::YUYV;
  scene.camera.sensor.noise = true;
  scene.camera.sensor.sensitivity = 150;
  SimTexture tag;
  tag.kind = SimTexture::Kind::AprilTag;
  tag.family = "tag36h11";
  SimObject anchor = ground_plane("anchor", 0.125, 0.125, tag);
  scene.objects.push_back(anchor);
  SimObject sphere;
  sphere.name = "sphere";
  sphere.shape = SimObject::Shape::Sphere;
  sphere.radius_m = 0.03;
  sphere.T_world_object = SE3(identity3(), {0.08, 0.02, 0.03});
  scene.objects.push_back(sphere);
  SimObject cube;
  cube.name = "cube";
  cube.shape = SimObject::Shape::Mesh;
  cube.mesh_builtin = "builtin:cube";
  cube.T_world_object = SE3::from_rt({0, 0, 0.3}, {-0.08, 0.03, 0});
  cube.is_virtual = true;
  scene.objects.push_back(cube);
  scene.lights.push_back(overhead_sun(3));
  scene.environment.radiance = {0.2, 0.2, 0.2};
  scene.trajectory = still({0.02, -0.25, 0.3}, {0, 0, 0}, {0, 0, 1});
  scene.render.samples_per_pixel = 4;
  return scene;
}

TEST(AnimatedSimulation, AStaticWorldRebuiltEveryFrameGivesTheSameBytes) {
  const SimScene still_scene = mixed_scene();
  // The same world with a pose track that never moves: simulate() then places it anew each frame.
  SimScene rebuilt = still_scene;
  for (SimObject& object : rebuilt.objects)
    if (object.name != "anchor") object.keyframes = {{0.0, object.T_world_object}, {1.0, object.T_world_object}};
  ASSERT_TRUE(rebuilt.has_animated_objects());
  ASSERT_FALSE(still_scene.has_animated_objects());

  const fs::path a = scratch_dir("static-once"), b = scratch_dir("static-rebuilt");
  SimulateOptions options;
  options.frames = 3;
  options.out_dir = a;
  simulate(still_scene, options);
  options.out_dir = b;
  simulate(rebuilt, options);
  for (const fs::path& sub : {fs::path{}, fs::path(kGroundTruthCompositeDir), fs::path(kGroundTruthCoverageDir)}) {
    SCOPED_TRACE(sub.string());
    const std::vector<uint8_t> once = file_bytes(a / sub / "frames.bin");
    ASSERT_FALSE(once.empty());
    EXPECT_TRUE(once == file_bytes(b / sub / "frames.bin"));
    EXPECT_TRUE(file_bytes(a / sub / "ground_truth.jsonl") == file_bytes(b / sub / "ground_truth.jsonl"));
  }
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(AnimatedSimulation, AMovingObjectChangesOnlyTheFramesAfterItStarts) {
  // The sphere stands still until t = 1/30 s, then moves away: frame 0 (t = 0) and frame 1 (t = 1/30,
  // its key) match the static scene's, frame 2 does not.
  const SimScene still_scene = mixed_scene();
  SimScene moving = still_scene;
  SimObject& sphere = moving.objects[1];
  const double t1 = 1.0 / 30;
  sphere.keyframes = {{t1, sphere.T_world_object}, {2 * t1, SE3(identity3(), {0.02, -0.05, 0.03})}};
  const fs::path a = scratch_dir("moving-still"), b = scratch_dir("moving");
  SimulateOptions options;
  options.frames = 3;
  options.out_dir = a;
  simulate(still_scene, options);
  options.out_dir = b;
  simulate(moving, options);
  const RecordingReader still_reader(a), moving_reader(b);
  for (size_t k = 0; k < 3; ++k) {
    Frame x, y;
    still_reader.read(k, x);
    moving_reader.read(k, y);
    EXPECT_EQ(x.data == y.data, k < 2) << "frame " << k;
  }
  fs::remove_all(a);
  fs::remove_all(b);
}

}  // namespace
}  // namespace arpipe::sim
