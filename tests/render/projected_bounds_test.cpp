// Tests of the screen rectangle of an object's box: it holds every projected point of the box,
// that of its part in front of the near plane when it reaches behind the camera, and it is absent
// when the box is out of view.
#include "render/projected_bounds.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "render_test_support.h"

namespace arpipe {
namespace {

using render_test::look_at;

const CameraModel kCamera("LENSMODEL_OPENCV8",
                          {300.0, 302.0, 158.9, 121.4, 0.35, -0.12, 0.0011, -0.0009, 0.02, 0.62, -0.05, 0.03}, 320, 240);
const Bounds kBox{{-0.03, -0.03, 0.0}, {0.03, 0.03, 0.06}};

TEST(ProjectedBounds, RectangleHoldsEveryProjectedPointOfTheBox) {
  const SE3 pose = look_at({0.1, -0.25, 0.2}, {-0.05, 0.0, 0.03});
  const auto rect = projected_box_rect(kCamera, pose, kBox, 0.0);
  ASSERT_TRUE(rect.has_value());
  // A dense grid over the box's surface: each projection lies in the rectangle, whose pixels span
  // [x - 0.5, x + width - 0.5).
  double min_u = INFINITY, max_u = -INFINITY;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j)
      for (int k = 0; k <= 20; ++k) {
        const Vec3 p{kBox.min[0] + (kBox.max[0] - kBox.min[0]) * i / 20, kBox.min[1] + (kBox.max[1] - kBox.min[1]) * j / 20,
                     kBox.min[2] + (kBox.max[2] - kBox.min[2]) * k / 20};
        const auto pixel = kCamera.project(pose * p);
        ASSERT_TRUE(pixel.has_value());
        min_u = std::min(min_u, (*pixel)[0]);
        max_u = std::max(max_u, (*pixel)[0]);
        EXPECT_GE((*pixel)[0], rect->x - 0.5);
        EXPECT_LT((*pixel)[0], rect->right() - 0.5);
        EXPECT_GE((*pixel)[1], rect->y - 0.5);
        EXPECT_LT((*pixel)[1], rect->bottom() - 0.5);
      }
  // And it is tight: no more than a pixel of slack on a side without margin (rounding out to whole pixels).
  EXPECT_LE(min_u - (rect->x - 0.5), 1.0);
  EXPECT_LE((rect->right() - 0.5) - max_u, 1.0);
}

// The outline of a convex hull as a pinhole sees it bounds, through a distorting lens, every point
// of the hull (random convex combinations of its vertices), and it is as tight as the rectangle of
// every segment between two vertices.
TEST(ProjectedBounds, ThePinholeOutlineBoundsTheWholeHullThroughTheLens) {
  const SE3 pose = look_at({0.1, -0.25, 0.2}, {-0.05, 0.0, 0.03});
  uint64_t state = 12345;
  const auto uniform = [&state] {  // a fixed sequence in [0, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) * 0x1.0p-53;
  };
  std::vector<Vec3> vertices;
  for (int i = 0; i < 64; ++i)
    vertices.push_back(pose * Vec3{0.12 * uniform() - 0.06, 0.12 * uniform() - 0.06, 0.08 * uniform()});
  std::vector<Vec3> outline;
  ASSERT_TRUE(append_pinhole_outline(outline, vertices, 16));
  EXPECT_LT(outline.size(), size_t(17 * 20)) << "an outline, not every edge";
  const auto rect = projected_points_rect(kCamera, outline, 0.0);
  ASSERT_TRUE(rect.has_value());
  for (int n = 0; n < 20000; ++n) {
    // A random point of the hull: a convex combination of four random vertices.
    std::array<double, 4> w{};
    double total = 0;
    for (double& x : w) total += (x = uniform());
    Vec3 p{0, 0, 0};
    for (double x : w) p = p + (x / total) * vertices[size_t(uniform() * 64) % 64];
    const auto pixel = kCamera.project(p);
    ASSERT_TRUE(pixel.has_value());
    ASSERT_GE((*pixel)[0], rect->x - 0.5);
    ASSERT_LT((*pixel)[0], rect->right() - 0.5);
    ASSERT_GE((*pixel)[1], rect->y - 0.5);
    ASSERT_LT((*pixel)[1], rect->bottom() - 0.5);
  }
  std::vector<Vec3> every_edge;
  for (size_t a = 0; a < vertices.size(); ++a)
    for (size_t b = a + 1; b < vertices.size(); ++b) append_segment_in_front(every_edge, vertices[a], vertices[b], 16);
  const auto all = projected_points_rect(kCamera, every_edge, 0.0);
  ASSERT_TRUE(all.has_value());
  EXPECT_LE(std::abs(rect->x - all->x), 1);
  EXPECT_LE(std::abs(rect->y - all->y), 1);
  EXPECT_LE(std::abs(rect->right() - all->right()), 1);
  EXPECT_LE(std::abs(rect->bottom() - all->bottom()), 1);
  // A vertex at the near plane: no outline (the caller cuts the edges there instead).
  std::vector<Vec3> none;
  vertices.push_back(Vec3{0.0, 0.0, 0.0});
  EXPECT_FALSE(append_pinhole_outline(none, vertices, 16));
  EXPECT_TRUE(none.empty());
  // Nor with a point that is not finite (a sort by its coordinates would be undefined).
  vertices.back() = Vec3{std::nan(""), 0.0, 0.5};
  EXPECT_FALSE(append_pinhole_outline(none, vertices, 16));
  EXPECT_TRUE(none.empty());
}

TEST(ProjectedBounds, MarginWidensAndTheImageClips) {
  const SE3 pose = look_at({0.1, -0.25, 0.2}, {-0.05, 0.0, 0.03});
  const PixelRect tight = *projected_box_rect(kCamera, pose, kBox, 0.0);
  const PixelRect wide = *projected_box_rect(kCamera, pose, kBox, 3.0);
  EXPECT_EQ(wide.x, std::max(0, tight.x - 3));
  EXPECT_EQ(wide.y, std::max(0, tight.y - 3));
  EXPECT_EQ(wide.right(), std::min(320, tight.right() + 3));
  EXPECT_EQ(wide.bottom(), std::min(240, tight.bottom() + 3));
  // Close up, the box fills more than the image: the rectangle is the image.
  const PixelRect close = *projected_box_rect(kCamera, look_at({0.0, -0.05, 0.04}, {0.0, 0.0, 0.03}), kBox, 2.0);
  EXPECT_EQ(close, PixelRect::full(320, 240));
}

TEST(ProjectedBounds, BoxAcrossTheNearPlaneIsBoundedByItsPartInFront) {
  // The camera inside the box: its part in front surrounds the view, the whole image.
  EXPECT_EQ(projected_box_rect(kCamera, look_at({0.0, 0.0, 0.03}, {1.0, 0.0, 0.03}), kBox, 2.0),
            PixelRect::full(320, 240));
  // The image plane cuts through the box beside the camera, whose part in front lies 86 degrees off
  // the axis: out of view, as GL clips it.
  EXPECT_FALSE(projected_box_rect(kCamera, look_at({0.0, -0.5, 0.03}, {1.0, -0.5, 0.03}), kBox, 2.0).has_value());
  // A camera 1 cm beside the box's face, looking along it: the part in front of the near plane
  // reaches into the image from one side. Every point of it that projects into the image lies in
  // the rectangle, and the rectangle is not the whole image.
  const SE3 pose = look_at({0.0, -0.04, 0.03}, {1.0, -0.04, 0.03});
  const auto rect = projected_box_rect(kCamera, pose, kBox, 0.0);
  ASSERT_TRUE(rect.has_value());
  EXPECT_LT(rect->width, 320);
  int inside = 0;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j)
      for (int k = 0; k <= 40; ++k) {
        const Vec3 p = pose * Vec3{kBox.min[0] + (kBox.max[0] - kBox.min[0]) * i / 40,
                                   kBox.min[1] + (kBox.max[1] - kBox.min[1]) * j / 40,
                                   kBox.min[2] + (kBox.max[2] - kBox.min[2]) * k / 40};
        if (p[2] <= 0.01) continue;  // behind the near plane: GL draws none of it
        const auto pixel = kCamera.project(p);
        if (!pixel || (*pixel)[0] < -0.5 || (*pixel)[0] >= 319.5 || (*pixel)[1] < -0.5 || (*pixel)[1] >= 239.5) continue;
        ++inside;
        EXPECT_GE((*pixel)[0], rect->x - 0.5);
        EXPECT_LT((*pixel)[0], rect->right() - 0.5);
        EXPECT_GE((*pixel)[1], rect->y - 0.5);
        EXPECT_LT((*pixel)[1], rect->bottom() - 0.5);
      }
  EXPECT_GT(inside, 100);  // the case is the one meant: much of the box is in view
}

TEST(ProjectedBounds, BoxBehindOrBesideTheViewIsAbsent) {
  // Looking straight away from the box.
  EXPECT_FALSE(projected_box_rect(kCamera, look_at({0.0, -0.3, 0.03}, {0.0, -1.0, 0.03}), kBox, 2.0).has_value());
  // In front of the camera but 79 degrees off its axis, far outside the 56-degree field of view.
  const CameraModel pinhole = CameraModel::pinhole(300, 300, 159.5, 119.5, 320, 240);
  EXPECT_FALSE(projected_box_rect(pinhole, look_at({0.0, -0.5, 0.03}, {1.0, -0.3, 0.03}), kBox, 2.0).has_value());
}

}  // namespace
}  // namespace arpipe
