// The simulator against geometry and physics, end to end through simulate() and the recording it
// writes: corners where mrcal projects them, intensity linear in exposure and gain, motion-blur
// ramps v*e wide, rolling-shutter skew from the readout time, determinism, virtual objects.
#include "capture/sim/simulator.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/recording/recording_reader.h"
#include "capture/sim/camera_trajectory.h"
#include "core/image/pixel_convert.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

constexpr double kPi = 3.14159265358979323846;

cv::Mat grey_frame(const RecordingReader& reader, size_t index) {
  Frame frame;
  reader.read(index, frame);
  std::vector<uint8_t> grey;
  to_grey(frame, grey);
  return cv::Mat(frame.height, frame.width, CV_8UC1, grey.data()).clone();
}

// ---------------------------------------------------------------------------------------------
// Geometry: a noise-free, blur-free chessboard through a distorted lens; OpenCV's sub-pixel
// corner detector finds each inner corner where mrcal projects the true 3D corner.

TEST(Simulator, ChessboardCornersLandWhereMrcalProjectsThem) {
  const int width = 480, height = 360;
  SimScene scene;
  scene.camera = exact_camera(width, height, 420);
  scene.camera.model = CameraModel(
      "LENSMODEL_OPENCV4", {420, 420, 241.5, 178.0, -0.05, 0.012, 0.0004, -0.0003}, width, height);
  scene.camera.exposure_ns = {1'000'000};
  scene.camera.sensor.sensitivity = 1000;  // 0.8 full scale for the paper, 0.03 for the ink
  SimTexture board;
  board.kind = SimTexture::Kind::Chessboard;
  board.rows = 7;
  board.cols = 9;
  board.margin_squares = 1;
  const double square = 0.025;
  SimObject plane = ground_plane("board", (board.cols + 2) * square, (board.rows + 2) * square, board);
  scene.objects.push_back(plane);
  scene.lights.push_back(overhead_sun(kPi));  // radiance = albedo
  scene.trajectory = still({0.06, -0.14, 0.36}, {0.0, 0.0, 0.0});
  scene.render.samples_per_pixel = 64;

  const fs::path dir = scratch_dir("corners");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  simulate(scene, options);
  const RecordingReader reader(dir);
  const cv::Mat grey = grey_frame(reader, 0);

  const cv::Size pattern(board.cols - 1, board.rows - 1);
  std::vector<cv::Point2f> found;
  ASSERT_TRUE(cv::findChessboardCorners(grey, pattern, found, cv::CALIB_CB_ADAPTIVE_THRESH));
  // cornerSubPix needs gradients across more than the one pixel a crisp edge has: a symmetric blur
  // keeps an X-junction's saddle point where it is and gives it them.
  cv::Mat smooth;
  cv::GaussianBlur(grey, smooth, cv::Size(0, 0), 1.0);
  cv::cornerSubPix(smooth, found, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));

  // The true inner corners (plane frame = world frame here): columns from the left edge, rows
  // from the printed top (+y).
  const SE3 T_cam_world = reader.ground_truth()[0].T_cam_world_mid;
  std::vector<Vec2> truth;
  for (int r = 1; r < board.rows; ++r)
    for (int c = 1; c < board.cols; ++c) {
      const Vec3 p{-plane.width_m / 2 + (board.margin_squares + c) * square,
                   plane.height_m / 2 - (board.margin_squares + r) * square, 0.0};
      const auto q = reader.camera_model().project(T_cam_world * p);
      ASSERT_TRUE(q.has_value());
      truth.push_back(*q);
    }
  ASSERT_EQ(found.size(), truth.size());
  double worst = 0, sum = 0;
  for (const cv::Point2f& corner : found) {
    double nearest = 1e9;
    for (const Vec2& q : truth) nearest = std::min(nearest, std::hypot(corner.x - q[0], corner.y - q[1]));
    worst = std::max(worst, nearest);
    sum += nearest;
  }
  // The budget: 0.1 px for every corner. Measured: worst 0.06, mean 0.035, with no
  // common offset; what is left is the detector's and 8-bit quantisation's own scatter (at 16
  // samples per pixel the area-sampling noise on crisp edges doubles it, hence 64 here).
  EXPECT_LT(worst, 0.1);
  EXPECT_LT(sum / double(found.size()), 0.05);
}

// ---------------------------------------------------------------------------------------------
// Physics: the linear image is radiance * exposure * sensitivity * gains, exactly, and an 8-bit
// linear-response frame is its rounding (clipped at full scale).

TEST(Simulator, IntensityIsLinearInExposureAndGain) {
  SimScene scene;
  scene.camera = exact_camera(32, 24, 30);
  scene.camera.exposure_ns = {2'000'000, 4'000'000, 8'000'000};
  scene.camera.analogue_gain = 1.5;
  scene.camera.digital_gain = 1.25;
  scene.camera.sensor.sensitivity = 100;
  SimObject plane = ground_plane("floor", 10, 10);
  plane.material.albedo = {0.5, 0.25, 0.125};
  scene.objects.push_back(plane);
  const double irradiance = 2.0;
  scene.lights.push_back(overhead_sun(irradiance));
  scene.trajectory = still({0, 0, 1}, {0, 0, 0});
  scene.render.samples_per_pixel = 1;
  scene.render.write_linear = true;

  const fs::path dir = scratch_dir("linear");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 3;
  simulate(scene, options);
  const RecordingReader reader(dir);
  ASSERT_EQ(reader.frame_count(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const GroundTruthFrame& truth = reader.ground_truth()[k];
    ASSERT_FALSE(truth.linear_image.empty());
    const cv::Mat linear = read_linear(dir / truth.linear_image);
    ASSERT_EQ(linear.type(), CV_32FC3);
    const double exposure_s = scene.camera.exposure_ns[k] * 1e-9;
    Frame frame;
    reader.read(k, frame);
    for (int c = 0; c < 3; ++c) {
      // Lambertian plane facing the light: L = albedo * E / pi.
      const double radiance = plane.material.albedo[size_t(c)] * irradiance / kPi;
      const double expected = radiance * exposure_s * 100 * 1.5 * 1.25;
      const double got = linear.at<cv::Vec3f>(12, 16)[2 - c];  // BGR
      EXPECT_NEAR(got, expected, 1e-6 * expected) << "frame " << k << " channel " << c;
      const int eight_bit = frame.data[12 * frame.bytes_per_line + 16 * 3 + size_t(c)];
      EXPECT_EQ(eight_bit, int(std::lround(std::min(expected, 1.0) * 255))) << "frame " << k << " channel " << c;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Motion: a camera translating at v over a dark|light edge, looking straight down from height Z
// through a pinhole: the scene moves f v / Z px/s in the image, so within one exposure e the edge
// is smeared into a ramp f v e / Z wide. Measured from the derivative's spread in the noise-free
// linear image: a box of width b, convolved with the unit pixel footprint and the unit difference
// kernel, has variance (b^2 + 2) / 12.

struct EdgeScene {
  SimScene scene;
  double speed_px_per_s = 0;
};

EdgeScene moving_edge_scene(double speed_m_per_s, int64_t exposure_ns, int64_t readout_ns) {
  const int width = 200, height = 120;
  const double focal = 400, Z = 0.5;
  EdgeScene out;
  SimScene& scene = out.scene;
  scene.camera = exact_camera(width, height, focal);
  scene.camera.fps = 30;
  scene.camera.exposure_ns = {exposure_ns};
  scene.camera.readout_ns = readout_ns;
  scene.camera.sensor.sensitivity = 1000;
  SimTexture edge;
  edge.kind = SimTexture::Kind::Chessboard;
  edge.rows = 1;
  edge.cols = 2;  // left half dark, right half light
  // Frame 3 starts at t = 0.1 s, when the camera is above x = 0.1 v: put the edge there.
  SimObject plane = ground_plane("edge", 4, 4, edge);
  plane.T_world_object = SE3(identity3(), {0.1 * speed_m_per_s, 0, 0});
  scene.objects.push_back(plane);
  scene.lights.push_back(overhead_sun(kPi));
  // Equally spaced collinear keyframes: constant velocity along +x between the outer ones.
  for (int i = 0; i <= 4; ++i) {
    const double t = 0.05 * i;
    scene.trajectory.keyframes.push_back(
        {t, {speed_m_per_s * t, 0, Z}, {speed_m_per_s * t, 0, 0}, {0, 1, 0}, 0.0});
  }
  scene.render.samples_per_pixel = 16;
  scene.render.write_linear = true;
  out.speed_px_per_s = focal * speed_m_per_s / Z;  // camera x = world x: the image moves at -this
  return out;
}

// Mean and variance of the edge's derivative along each row of the linear image's green channel.
struct EdgeProfile {
  std::vector<double> centre;    // per row, px
  std::vector<double> variance;  // per row, px^2
};

EdgeProfile edge_profile(const cv::Mat& linear) {
  EdgeProfile out;
  for (int y = 0; y < linear.rows; ++y) {
    const double dark = linear.at<cv::Vec3f>(y, 0)[1], light = linear.at<cv::Vec3f>(y, linear.cols - 1)[1];
    double sum = 0, first = 0, second = 0;
    for (int x = 0; x + 1 < linear.cols; ++x) {
      const double g = (linear.at<cv::Vec3f>(y, x + 1)[1] - linear.at<cv::Vec3f>(y, x)[1]) / (light - dark);
      const double position = x + 0.5;  // the difference sits between pixels x and x + 1
      sum += g, first += g * position, second += g * position * position;
    }
    const double mean = first / sum;
    out.centre.push_back(mean);
    out.variance.push_back(second / sum - mean * mean);
  }
  return out;
}

TEST(Simulator, MotionBlurRampIsSpeedTimesExposure) {
  const int64_t exposure_ns = 8'000'000;
  const EdgeScene edge = moving_edge_scene(3.0, exposure_ns, 0);
  const fs::path dir = scratch_dir("blur");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 4;
  simulate(edge.scene, options);
  const RecordingReader reader(dir);
  const EdgeProfile profile = edge_profile(read_linear(dir / reader.ground_truth()[3].linear_image));
  double variance = 0;
  for (double v : profile.variance) variance += v;
  variance /= double(profile.variance.size());
  const double measured_width = std::sqrt(12 * variance - 2);
  const double expected_width = edge.speed_px_per_s * exposure_ns * 1e-9;  // 19.2 px
  EXPECT_NEAR(measured_width, expected_width, 0.5);
}

TEST(Simulator, NoMotionNoBlur) {
  const EdgeScene edge = moving_edge_scene(0.0, 8'000'000, 0);
  const fs::path dir = scratch_dir("no-blur");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 4;
  simulate(edge.scene, options);
  const RecordingReader reader(dir);
  const cv::Mat linear = read_linear(dir / reader.ground_truth()[3].linear_image);
  // A still, crisp edge covers at most one pixel partly: every other pixel is pure ink or paper.
  for (int y = 0; y < linear.rows; ++y) {
    const double dark = linear.at<cv::Vec3f>(y, 0)[1], light = linear.at<cv::Vec3f>(y, linear.cols - 1)[1];
    int mixed = 0;
    for (int x = 0; x < linear.cols; ++x) {
      const double s = (linear.at<cv::Vec3f>(y, x)[1] - dark) / (light - dark);
      if (s > 1e-6 && s < 1 - 1e-6) ++mixed;
    }
    EXPECT_LE(mixed, 1) << "row " << y;
  }
  // And the edge is where the pinhole puts the world line x = 0 (plane at x = 0 here): the
  // image centre column, to the sampling's precision (16 area samples: 1/16 px steps).
  const EdgeProfile profile = edge_profile(linear);
  for (double centre : profile.centre) EXPECT_NEAR(centre, (linear.cols - 1) / 2.0, 0.07);
}

// ---------------------------------------------------------------------------------------------
// Rolling shutter: with a short exposure and readout R, row r exposes r/(H-1) R later than row 0,
// so a vertical edge seen by a camera moving sideways leans by speed * R over the image height.

TEST(Simulator, RollingShutterSkewMatchesReadoutTime) {
  const int64_t readout_ns = 20'000'000;
  const EdgeScene edge = moving_edge_scene(1.0, 1'000'000, readout_ns);
  const fs::path dir = scratch_dir("rolling");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 4;
  simulate(edge.scene, options);
  const RecordingReader reader(dir);
  const GroundTruthFrame& truth = reader.ground_truth()[3];
  const EdgeProfile profile = edge_profile(read_linear(dir / truth.linear_image));
  // Least-squares slope of the edge position against the row.
  const double n = double(profile.centre.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t r = 0; r < profile.centre.size(); ++r) {
    sx += double(r), sy += profile.centre[r], sxx += double(r * r), sxy += double(r) * profile.centre[r];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double skew_px = slope * (n - 1);
  // Later rows see the scene later, when it has moved further left (camera moving +x).
  const double expected_skew_px = -edge.speed_px_per_s * readout_ns * 1e-9;  // -16 px
  EXPECT_NEAR(skew_px, expected_skew_px, 0.2);

  // Ground truth has per-row poses from the first row to the last.
  ASSERT_GE(truth.rows.size(), 2u);
  EXPECT_EQ(truth.rows.front().row, 0);
  EXPECT_EQ(truth.rows.back().row, reader.info().height - 1);
  const double travelled = truth.rows.back().T_cam_world.inverse().translation()[0] -
                           truth.rows.front().T_cam_world.inverse().translation()[0];
  EXPECT_NEAR(travelled, 1.0 * readout_ns * 1e-9, 1e-6);  // v * R, metres
}

// ---------------------------------------------------------------------------------------------
// Determinism, ground truth contents and virtual objects.

SimScene small_noisy_scene() {
  SimScene scene;
  scene.camera.model = CameraModel::pinhole(60, 60, 31.5, 23.5, 64, 48);
  scene.camera.pixel_format = PixelFormat::YUYV;
  SimTexture tag;
  tag.kind = SimTexture::Kind::AprilTag;
  tag.family = "tag36h11";
  tag.tag_id = 3;
  scene.objects.push_back(ground_plane("tag", 0.125, 0.125, tag));
  SimObject table = ground_plane("table", 2, 2);
  table.T_world_object = SE3(identity3(), {0, 0, -0.001});
  scene.objects.push_back(table);
  SimLight sun = overhead_sun(5);  // paper at ~0.5 of full scale: nothing clips
  sun.name = "sun";
  sun.is_sun = true;
  sun.direction_to_light = normalized(Vec3{0.3, -0.4, 0.866});
  sun.angular_diameter_rad = 0.53 * kPi / 180;
  scene.lights.push_back(sun);
  scene.sun = SimSun{2.5, 1.05};
  scene.environment.radiance = {0.2, 0.25, 0.35};
  scene.trajectory = still({0.02, -0.1, 0.3}, {0, 0, 0});
  scene.render.samples_per_pixel = 4;
  return scene;
}

TEST(Simulator, SameSeedSameBytesOtherSeedOtherNoise) {
  const SimScene scene = small_noisy_scene();
  auto run = [&](const std::string& name, uint64_t seed) {
    const fs::path dir = scratch_dir(name);
    SimulateOptions options;
    options.out_dir = dir;
    options.frames = 2;
    options.seed = seed;
    options.threads = name == "seed-a2" ? 1 : 2;  // the thread count must not matter
    simulate(scene, options);
    return file_bytes(dir / "frames.bin");
  };
  const auto a = run("seed-a", 5), a2 = run("seed-a2", 5), b = run("seed-b", 6);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, a2);
  EXPECT_NE(a, b);
}

TEST(Simulator, GroundTruthHasPosesLightsSunAndExposure) {
  SimScene scene = small_noisy_scene();
  const fs::path dir = scratch_dir("truth");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 2;
  simulate(scene, options);
  const RecordingReader reader(dir);
  ASSERT_EQ(reader.ground_truth().size(), 2u);
  const GroundTruthFrame& truth = reader.ground_truth()[1];
  const SE3 expected = keyframe_pose(scene.trajectory.keyframes[0]);
  EXPECT_LT(rotation_angle_between(truth.T_cam_world_mid, expected), 1e-9);
  EXPECT_LT(norm(truth.T_cam_world_mid.translation() - expected.translation()), 1e-9);
  ASSERT_EQ(truth.lights.size(), 1u);
  EXPECT_EQ(truth.lights[0].kind, "directional");
  EXPECT_LT(norm(truth.lights[0].direction_to_light - scene.lights[0].direction_to_light), 1e-12);
  EXPECT_EQ(truth.lights[0].strength, scene.lights[0].irradiance);
  ASSERT_TRUE(truth.sun.has_value());
  EXPECT_NEAR(truth.sun->azimuth_rad, 2.5, 1e-12);
  EXPECT_NEAR(truth.sun->elevation_rad, 1.05, 1e-12);
  EXPECT_EQ(truth.exposure_ns, scene.camera.exposure_ns[0]);
  EXPECT_EQ(truth.exposure_ns, reader.metadata(1).exposure_ns);
  // The metadata's exposure start comes back from the raw timestamp as docs/DESIGN.md says.
  const FrameMetadata& meta = reader.metadata(1);
  EXPECT_EQ(exposure_start_from_raw(meta.raw_timestamp_ns, meta.raw_timestamp_meaning, meta.exposure_ns,
                                    meta.readout_ns, meta.timestamp_offset_ns),
            meta.exposure_start_ns);
  EXPECT_FALSE(fs::exists(dir / kGroundTruthCompositeDir));  // no virtual objects
}

TEST(Simulator, VirtualObjectsOnlyInTheGroundTruthComposite) {
  SimScene scene = small_noisy_scene();
  SimObject ball;
  ball.name = "virtual-ball";
  ball.shape = SimObject::Shape::Sphere;
  ball.radius_m = 0.03;
  ball.T_world_object = SE3(identity3(), {0, 0, 0.03});
  ball.material.albedo = {0.9, 0.1, 0.1};
  ball.is_virtual = true;
  scene.objects.push_back(ball);
  const fs::path dir = scratch_dir("virtual");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  const SimulateSummary summary = simulate(scene, options);
  EXPECT_TRUE(summary.wrote_composite);
  const RecordingReader camera(dir), composite(dir / kGroundTruthCompositeDir);
  ASSERT_EQ(composite.frame_count(), 1u);
  EXPECT_EQ(composite.info().pixel_format, PixelFormat::RGB24);
  Frame camera_frame, composite_frame;
  camera.read(0, camera_frame);
  composite.read(0, composite_frame);
  std::vector<uint8_t> camera_rgb, composite_rgb;
  to_rgb24(camera_frame, camera_rgb);
  to_rgb24(composite_frame, composite_rgb);
  // Where the ball's centre projects, the composite is red and the camera frame is not.
  const auto q = camera.camera_model().project(camera.ground_truth()[0].T_cam_world_mid * Vec3{0, 0, 0.03});
  ASSERT_TRUE(q.has_value());
  const size_t at = (size_t(std::lround((*q)[1])) * 64 + size_t(std::lround((*q)[0]))) * 3;
  EXPECT_GT(composite_rgb[at], composite_rgb[at + 1] + 60);
  EXPECT_LT(std::abs(int(camera_rgb[at]) - int(camera_rgb[at + 1])), 40);
  // A corner pixel far from the ball and its shadow: the same light and the same noise, so the same
  // value up to the camera frame's YUYV round trip.
  EXPECT_NEAR(camera_rgb[0], composite_rgb[0], 6);
}

}  // namespace
}  // namespace arpipe::sim
