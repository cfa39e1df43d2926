// The ground-truth coverage (ground_truth_coverage/, capture/sim/ground_truth_coverage.h) against
// analytic truth: a virtual box behind a real one, seen through a pinhole, covers exactly the
// pixels inside its projected outline and outside the real box's (1), none elsewhere (0), and a
// fraction on its visible edges equal to the pixel's area inside, up to the sampling; with nothing
// in front, the coverage is sample for sample the virtual object's silhouette in the ground-truth
// composite.
#include "capture/sim/ground_truth_coverage.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/sim/simulator.h"
#include "core/image/pixel_convert.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

// ---- Plane geometry on pixel coordinates --------------------------------------------------------

using Polygon = std::vector<Vec2>;  // convex, counter-clockwise (in x right, y down: clockwise on screen)

double cross2(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Andrew's monotone chain: the convex hull, counter-clockwise (positive cross2 turns).
Polygon convex_hull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end());
  Polygon hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

double area(const Polygon& p) {
  double twice = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % p.size()];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return std::abs(twice) / 2;
}

// Sutherland-Hodgman: `subject` clipped to the inside of the convex counter-clockwise `clip`.
Polygon clip(const Polygon& subject, const Polygon& clip_polygon) {
  Polygon out = subject;
  for (size_t e = 0; e < clip_polygon.size() && !out.empty(); ++e) {
    const Vec2& a = clip_polygon[e];
    const Vec2& b = clip_polygon[(e + 1) % clip_polygon.size()];
    const Polygon in = out;
    out.clear();
    for (size_t i = 0; i < in.size(); ++i) {
      const Vec2& p = in[i];
      const Vec2& q = in[(i + 1) % in.size()];
      const double dp = cross2(a, b, p), dq = cross2(a, b, q);
      if (dp >= 0) out.push_back(p);
      if ((dp >= 0) != (dq >= 0)) {
        const double s = dp / (dp - dq);
        out.push_back({p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])});
      }
    }
  }
  return out;
}

// Signed distance from a point to a convex counter-clockwise polygon's outline: negative inside.
double signed_distance(const Polygon& polygon, const Vec2& p) {
  double inside_depth = 1e300, outside = 0;
  for (size_t e = 0; e < polygon.size(); ++e) {
    const Vec2& a = polygon[e];
    const Vec2& b = polygon[(e + 1) % polygon.size()];
    const double length = std::hypot(b[0] - a[0], b[1] - a[1]);
    const double d = -cross2(a, b, p) / length;  // > 0 outside this edge
    inside_depth = std::min(inside_depth, -d);
    // Distance to the segment, for the outside case.
    const double s = std::clamp(((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1])) / (length * length), 0.0, 1.0);
    const double to_segment = std::hypot(p[0] - a[0] - s * (b[0] - a[0]), p[1] - a[1] - s * (b[1] - a[1]));
    if (d > 0) outside = std::max(outside, to_segment);
  }
  if (outside > 0) {
    double nearest = 1e300;  // outside: the distance to the nearest edge segment
    for (size_t e = 0; e < polygon.size(); ++e) {
      const Vec2& a = polygon[e];
      const Vec2& b = polygon[(e + 1) % polygon.size()];
      const double length2 = (b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]);
      const double s = std::clamp(((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1])) / length2, 0.0, 1.0);
      nearest = std::min(nearest, std::hypot(p[0] - a[0] - s * (b[0] - a[0]), p[1] - a[1] - s * (b[1] - a[1])));
    }
    return nearest;
  }
  return -inside_depth;
}

Polygon pixel_square(int x, int y) {  // pixel centres at integer coordinates (mrcal, OpenCV)
  return {{x - 0.5, y - 0.5}, {x + 0.5, y - 0.5}, {x + 0.5, y + 0.5}, {x - 0.5, y + 0.5}};
}

// An independent look-at pose (camera x right, y down, z forward; image up along `up`).
SE3 look_at_pose(const Vec3& position, const Vec3& look_at, const Vec3& up) {
  const Vec3 z = normalized(look_at - position);
  const Vec3 down = -1.0 * up;
  const Vec3 y = normalized(down - dot(down, z) * z);
  const Vec3 x = cross(y, z);
  const Mat3 R{{{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}}};
  return SE3(R, -1.0 * mat_mul(R, position));
}

SimObject sized_box(const std::string& name, const Vec3& size, const Vec3& position, double yaw_rad, bool is_virtual) {
  SimObject box;
  box.name = name;
  box.shape = SimObject::Shape::Mesh;
  box.mesh_builtin = "builtin:box";
  box.mesh_size_m = size;
  box.T_world_object = SE3::from_rt({0, 0, yaw_rad}, position);
  box.is_virtual = is_virtual;
  return box;
}

// The outline of a box object (size, base on z = 0, centred) in the image: the convex hull of its
// eight projected corners (a pinhole maps the box's silhouette edges to straight lines).
Polygon box_outline(const CameraModel& model, const SE3& T_cam_world, const SimObject& box) {
  std::vector<Vec2> corners;
  const Vec3& s = *box.mesh_size_m;
  for (double sx : {-0.5, 0.5})
    for (double sy : {-0.5, 0.5})
      for (double sz : {0.0, 1.0}) {
        const auto q = model.project(T_cam_world * (box.T_world_object * Vec3{sx * s[0], sy * s[1], sz * s[2]}));
        EXPECT_TRUE(q);
        corners.push_back(*q);
      }
  return convex_hull(corners);
}

// ---- A virtual box partly behind a real box -------------------------------------------------------

TEST(GroundTruthCoverage, OneInsideTheVisiblePartZeroBehindTheRealBoxAndAwayFractionalOnEdges) {
  const int width = 160, height = 120;
  SimScene scene;
  scene.camera = exact_camera(width, height, 170);
  const Vec3 position{-0.02, -0.40, 0.30}, look_at{0.02, 0.06, 0.03}, up{0, 0, 1};
  scene.trajectory = still(position, look_at, up);
  scene.render.samples_per_pixel = 16;
  SimObject table = ground_plane("table", 2, 2);
  table.T_world_object = SE3(identity3(), {0, 0, -0.0005});
  scene.objects.push_back(table);
  // The real box stands wholly nearer the camera (y in [-0.035, 0.035]) than the virtual one
  // (y in [0.09, 0.15]): every camera ray runs towards +y, so where both outlines overlap the
  // real box is hit first.
  const SimObject real = sized_box("real-box", {0.06, 0.05, 0.09}, {0, 0, 0}, 0.2, false);
  const SimObject virt = sized_box("virtual-box", {0.09, 0.04, 0.06}, {0.04, 0.12, 0}, -0.3, true);
  scene.objects.push_back(real);
  scene.objects.push_back(virt);
  scene.lights.push_back(overhead_sun(3));

  const fs::path dir = scratch_dir("coverage-boxes");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  simulate(scene, options);
  ASSERT_EQ(coverage_frame_count(dir), 1u);
  const CoverageImage coverage = read_coverage_frame(dir, 0);
  ASSERT_EQ(coverage.width, width);
  ASSERT_EQ(coverage.height, height);

  const SE3 T_cam_world = look_at_pose(position, look_at, up);
  const RecordingReader camera(dir);
  const SE3 T_truth = camera.ground_truth()[0].T_cam_world_mid;
  for (size_t i = 0; i < 3; ++i) ASSERT_NEAR(T_truth.translation()[i], T_cam_world.translation()[i], 1e-9);
  const CameraModel& model = scene.camera.model;
  const Polygon real_outline = box_outline(model, T_cam_world, real);
  const Polygon virtual_outline = box_outline(model, T_cam_world, virt);
  const double visible_area = area(virtual_outline) - area(clip(virtual_outline, real_outline));
  ASSERT_GT(area(clip(virtual_outline, real_outline)), 0.2 * area(virtual_outline));  // partly hidden...
  ASSERT_GT(visible_area, 0.3 * area(virtual_outline));                                // ...partly not

  // Whole pixel squares inside or outside an outline: the centre farther than half the diagonal.
  const double certain = 0.5 * std::sqrt(2.0) + 1e-6;
  int ones = 0, hidden_zeros = 0, away_zeros = 0, edges = 0;
  double sum = 0, edge_error = 0, worst_edge_error = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float c = coverage.at(x, y);
      sum += c;
      const Vec2 centre{double(x), double(y)};
      const double dv = signed_distance(virtual_outline, centre), dr = signed_distance(real_outline, centre);
      if (dv < -certain && dr > certain) {
        EXPECT_EQ(c, 1.0f) << x << "," << y;
        ++ones;
      } else if (dr < -certain) {
        EXPECT_EQ(c, 0.0f) << x << "," << y << " (behind the real box)";
        ++hidden_zeros;
      } else if (dv > certain) {
        EXPECT_EQ(c, 0.0f) << x << "," << y << " (away from the virtual box)";
        ++away_zeros;
      } else if (dr > certain) {
        // On the virtual box's visible edge: the exact share of the pixel's area inside the
        // outline. 16 stratified samples: a straight edge crosses at most 7 of the 4 x 4 strata,
        // each 1/16 of the pixel, so the estimate is within 7/16 of it (plus 1/510 of rounding);
        // an edge within 0.2 px of the centre leaves whole strata on both sides: strictly between.
        const double exact = area(clip(pixel_square(x, y), virtual_outline));
        const double error = std::abs(c - exact);
        EXPECT_LE(error, 7.0 / 16 + 1.0 / 510) << x << "," << y << ": exact " << exact;
        if (std::abs(dv) < 0.2) {
          EXPECT_GT(c, 0.0f) << x << "," << y;
          EXPECT_LT(c, 1.0f) << x << "," << y;
        }
        edge_error += error;
        worst_edge_error = std::max(worst_edge_error, error);
        ++edges;
      }
    }
  EXPECT_GT(ones, 200);
  EXPECT_GT(hidden_zeros, 200);
  EXPECT_GT(away_zeros, 10000);
  ASSERT_GT(edges, 50);
  // Jittered strata: the errors are those of 4 x 4 stratified sampling of a straight edge; the
  // area adds them up with their signs. Measured: 279 ones, 814 hidden, 17967 away, 90 edge pixels
  // with a mean error of 0.029 (worst 0.13); the sum 346.64 px^2 against the exact 346.78.
  EXPECT_LT(edge_error / edges, 0.06) << "worst " << worst_edge_error;
  EXPECT_NEAR(sum, visible_area, 0.005 * visible_area + 2.0);
}

// ---- Nothing in front: the composite's silhouette, sample for sample --------------------------------

TEST(GroundTruthCoverage, WithNothingInFrontItIsTheCompositesSilhouetteSampleForSample) {
  // A black virtual ball that casts no shadow, over a grey table lit by a light without a disc and
  // no sky: every sample sees either the table (radiance L, no random numbers involved) or the
  // ball (0), so the composite's linear value is L (1 - coverage) exactly; the camera moves, so
  // edges are blurred too.
  const int width = 96, height = 72;
  SimScene scene;
  scene.camera = exact_camera(width, height, 100);
  scene.camera.exposure_ns = {8'000'000};
  scene.render.samples_per_pixel = 16;
  // The camera slides sideways without turning: the ball moves across the image.
  const Vec3 ahead{0.03, 0.25, -0.28};
  scene.trajectory.keyframes = {{0.0, {-0.03, -0.25, 0.3}, Vec3{-0.03, -0.25, 0.3} + ahead, {0, 0, 1}, 0.0},
                                {0.1, {0.05, -0.25, 0.3}, Vec3{0.05, -0.25, 0.3} + ahead, {0, 0, 1}, 0.0}};
  SimObject table = ground_plane("table", 3, 3);
  table.material.albedo = {0.8, 0.8, 0.8};
  scene.objects.push_back(table);
  SimObject ball;
  ball.name = "ball";
  ball.shape = SimObject::Shape::Sphere;
  ball.radius_m = 0.04;
  ball.T_world_object = SE3(identity3(), {0, 0, 0.06});
  ball.material.albedo = {0, 0, 0};
  ball.casts_shadows = false;
  ball.is_virtual = true;
  scene.objects.push_back(ball);
  scene.lights.push_back(overhead_sun(std::numbers::pi));
  const double full_value = 0.8 * 0.008 * 100;  // radiance 0.8 (albedo / pi x pi) x 8 ms x sensitivity 100

  const fs::path dir = scratch_dir("coverage-silhouette");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 3;
  simulate(scene, options);
  const RecordingReader composite(dir / kGroundTruthCompositeDir), frames(dir);
  ASSERT_EQ(coverage_frame_count(dir), 3u);
  int fractional = 0, covered = 0;
  for (size_t k = 0; k < 3; ++k) {
    const CoverageImage coverage = read_coverage_frame(dir, k);
    Frame composite_frame, camera_frame;
    composite.read(k, composite_frame);
    frames.read(k, camera_frame);
    std::vector<uint8_t> rgb, camera_rgb;
    to_rgb24(composite_frame, rgb);
    to_rgb24(camera_frame, camera_rgb);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t p = size_t(y) * size_t(width) + size_t(x);
        const double c = coverage.coverage[p];
        // Both hold k / 16 after 8-bit rounding; they must name the same k.
        const long from_coverage = std::lround(c * 16);
        const long from_composite = std::lround(16 * (1 - rgb[p * 3] / (255 * full_value)));
        ASSERT_EQ(from_coverage, from_composite) << "frame " << k << " pixel " << x << "," << y;
        EXPECT_NEAR(c * 16, double(from_coverage), 16.0 / 510 + 1e-6);
        EXPECT_EQ(camera_rgb[p * 3], uint8_t(std::lround(255 * full_value)));  // the table alone
        fractional += (c > 0 && c < 1) ? 1 : 0;
        covered += c == 1 ? 1 : 0;
      }
  }
  EXPECT_GT(covered, 3 * 150);
  EXPECT_GT(fractional, 3 * 40);
}

// ---- The recording and its reader ----------------------------------------------------------------

TEST(GroundTruthCoverage, IsAGreyRecordingWithTheCameraFramesMetadataAndTruth) {
  SimScene scene;
  scene.camera = exact_camera(32, 24, 30);
  scene.trajectory = still({0, -0.2, 0.3}, {0, 0, 0}, {0, 0, 1});
  scene.render.samples_per_pixel = 1;
  scene.objects.push_back(ground_plane("table", 2, 2));
  SimObject cube;
  cube.name = "cube";
  cube.shape = SimObject::Shape::Mesh;
  cube.mesh_builtin = "builtin:cube";
  cube.is_virtual = true;
  scene.objects.push_back(cube);
  scene.lights.push_back(overhead_sun(3));
  const fs::path dir = scratch_dir("coverage-recording");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 2;
  EXPECT_TRUE(simulate(scene, options).wrote_composite);
  const RecordingReader frames(dir), coverage(dir / kGroundTruthCoverageDir);
  EXPECT_EQ(coverage.info().pixel_format, PixelFormat::GREY);
  EXPECT_EQ(coverage.info().width, 32);
  ASSERT_EQ(coverage.frame_count(), 2u);
  ASSERT_EQ(coverage.ground_truth().size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(coverage.metadata(k).sequence, frames.metadata(k).sequence);
    EXPECT_EQ(coverage.metadata(k).exposure_start_ns, frames.metadata(k).exposure_start_ns);
    EXPECT_EQ(coverage.ground_truth()[k].T_cam_world_mid.translation(),
              frames.ground_truth()[k].T_cam_world_mid.translation());
  }
  // The cube stands at the image centre; the corners see the table.
  const CoverageImage image = read_coverage_frame(dir, 1);
  EXPECT_EQ(image.at(16, 12), 1.0f);
  EXPECT_EQ(image.at(0, 0), 0.0f);
  EXPECT_THROW(read_coverage_frame(dir, 2), RecordingError);

  // No virtual objects: no coverage, and the reader says so.
  scene.objects.pop_back();
  const fs::path plain = scratch_dir("coverage-none");
  options.out_dir = plain;
  EXPECT_FALSE(simulate(scene, options).wrote_composite);
  EXPECT_FALSE(fs::exists(plain / kGroundTruthCoverageDir));
  try {
    read_coverage_frame(plain, 0);
    ADD_FAILURE() << "no RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find(kGroundTruthCoverageDir), std::string::npos) << e.what();
  }
}

TEST(GroundTruthCoverage, BytesRoundTrip) {
  EXPECT_EQ(coverage_to_byte(0.0), 0);
  EXPECT_EQ(coverage_to_byte(1.0), 255);
  EXPECT_EQ(coverage_to_byte(0.25), 64);  // 63.75
  EXPECT_EQ(coverage_to_byte(-0.5), 0);
  EXPECT_EQ(coverage_to_byte(2.0), 255);
  EXPECT_EQ(coverage_to_byte(std::nan("")), 0);
  for (int b = 0; b < 256; ++b) EXPECT_EQ(coverage_to_byte(coverage_from_byte(uint8_t(b))), b);
}

}  // namespace
}  // namespace arpipe::sim
