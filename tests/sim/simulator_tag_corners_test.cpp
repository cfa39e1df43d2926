// The simulator's AprilTags against mrcal: in a noise-free, blur-free frame through a distorted
// lens, each tag's outer corners (found by libapriltag, then located to sub-pixel precision by
// fitting its four border edges) lie where mrcal projects the true corners.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "capture/recording/recording_reader.h"
#include "capture/sim/simulator.h"
#include "core/config/config.h"
#include "core/image/pixel_convert.h"
#include "core/track/tag_corner_refiner.h"
#include "core/track/tag_detector.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

TEST(SimulatorTags, OuterCornersLandWhereMrcalProjectsThem) {
  const int width = 480, height = 360;
  SimScene scene;
  scene.camera = exact_camera(width, height, 430);
  scene.camera.model =
      CameraModel("LENSMODEL_OPENCV4", {430, 430, 238.0, 181.5, -0.05, 0.012, 0.0004, -0.0003}, width, height);
  scene.camera.pixel_format = PixelFormat::GREY;
  scene.camera.sensor.response = CameraResponse::srgb();  // what the corner refiner decodes
  scene.camera.sensor.sensitivity = 1000;
  scene.camera.exposure_ns = {1'000'000};
  // Two tags of 6 cm (black-border edge) at known places on a grey table.
  const double size = 0.06;
  const std::vector<std::pair<int, Vec3>> tags{{0, {-0.045, 0.0, 0.0}}, {7, {0.045, 0.01, 0.0}}};
  for (const auto& [id, centre] : tags) {
    SimTexture texture;
    texture.kind = SimTexture::Kind::AprilTag;
    texture.family = "tag36h11";
    texture.tag_id = id;
    const double printed = size * 10.0 / 8.0;  // tag36h11: 10 cells printed, 8 to the black border's edge
    SimObject tag = ground_plane(fmt::format("tag{}", id), printed, printed, texture);
    tag.T_world_object = SE3::from_rt({0, 0, 0.3 * id}, centre);  // turned, to test the texture's orientation
    scene.objects.push_back(tag);
  }
  SimObject table = ground_plane("table", 2, 2);
  table.material.albedo = {0.4, 0.4, 0.4};
  table.T_world_object = SE3(identity3(), {0, 0, -0.0005});
  scene.objects.push_back(table);
  scene.lights.push_back(overhead_sun(3.14159265358979));
  scene.trajectory = still({0.03, -0.16, 0.24}, {0.0, 0.0, 0.0});
  scene.render.samples_per_pixel = 64;

  const fs::path dir = scratch_dir("tag-corners");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  simulate(scene, options);
  const RecordingReader reader(dir);
  Frame frame;
  reader.read(0, frame);

  Config config;
  config.track.family = "tag36h11";
  TagDetector detector(config);
  std::vector<TagObservation> observations;
  detector.detect(frame.data.data(), frame.width, frame.height, frame.bytes_per_line, observations);
  ASSERT_EQ(observations.size(), tags.size());
  const TagCornerRefiner refiner(PixelFormat::GREY);
  const SE3& T_cam_world = reader.ground_truth()[0].T_cam_world_mid;
  double worst = 0;
  for (TagObservation& observation : observations) {
    ASSERT_TRUE(refiner.refine(frame.data.data(), frame.width, frame.height, frame.bytes_per_line,
                               reader.camera_model(), detector.border_cells(), observation.corners));
    const auto tag = std::find_if(tags.begin(), tags.end(), [&](const auto& t) { return t.first == observation.id; });
    ASSERT_NE(tag, tags.end()) << "unexpected id " << observation.id;
    const SE3 T_world_tag = SE3::from_rt({0, 0, 0.3 * tag->first}, tag->second);
    // AprilTag order: bottom-left, bottom-right, top-right, top-left of the printed tag.
    const std::array<Vec3, 4> corners{Vec3{-size / 2, -size / 2, 0}, Vec3{size / 2, -size / 2, 0},
                                      Vec3{size / 2, size / 2, 0}, Vec3{-size / 2, size / 2, 0}};
    for (size_t i = 0; i < 4; ++i) {
      const auto expected = reader.camera_model().project(T_cam_world * (T_world_tag * corners[i]));
      ASSERT_TRUE(expected.has_value());
      const double error = std::hypot(observation.corners[i][0] - (*expected)[0], observation.corners[i][1] - (*expected)[1]);
      worst = std::max(worst, error);
      EXPECT_LT(error, 0.1) << "tag " << observation.id << " corner " << i;
    }
  }
  RecordProperty("worst_corner_error_px", fmt::format("{:.3f}", worst));
}

}  // namespace
}  // namespace arpipe::sim
