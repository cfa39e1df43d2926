// The shadow map's fitted light view (render/shadow/shadow_frustum.h): every caster corner and the
// receiver patch inside the map, the patch holding each corner's shadow, the GL matrix agreeing
// with the CPU mapping, for a directional light and for a lamp.
#include <gtest/gtest.h>

#include <vector>

#include "render/shadow/shadow_frustum.h"

namespace arpipe {
namespace {

const std::vector<ShadowCaster> kCasters{
    {{{-0.03, -0.03, 0}, {0.03, 0.03, 0.06}}, SE3::from_rt({0, 0, 0.3}, {0.05, -0.02, 0})},
    {{{-0.02, -0.02, 0}, {0.02, 0.02, 0.1}}, SE3::from_rt({0, 0, 0}, {-0.1, 0.08, 0})}};

std::vector<Vec3> corners() {
  std::vector<Vec3> out;
  for (const ShadowCaster& c : kCasters)
    for (int i = 0; i < 8; ++i)
      out.push_back(c.T_world_object * Vec3{(i & 1) ? c.bounds.max[0] : c.bounds.min[0],
                                            (i & 2) ? c.bounds.max[1] : c.bounds.min[1],
                                            (i & 4) ? c.bounds.max[2] : c.bounds.min[2]});
  return out;
}

// clip = M (x, y, z, 1); u, v = clip.xy / clip.w * 0.5 + 0.5; depth from the plane.
Vec3 through_gl(const ShadowFrustum& f, const Vec3& p) {
  const std::array<float, 16> m = f.clip_from_world();
  std::array<double, 4> clip{};
  for (size_t row = 0; row < 4; ++row)
    clip[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row];
  const std::array<float, 4> plane = f.depth_plane();
  return {clip[0] / clip[3] * 0.5 + 0.5, clip[1] / clip[3] * 0.5 + 0.5,
          plane[0] * p[0] + plane[1] * p[1] + plane[2] * p[2] + plane[3]};
}

void expect_holds_everything(const ShadowFrustum& f, const Vec3& light_or_direction, bool local) {
  for (const Vec3& c : corners()) {
    const Vec3 m = f.map_coordinates(c);
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_GE(m[k], 0.0);
      EXPECT_LE(m[k], 1.0);
    }
    const Vec3 gl = through_gl(f, c);
    for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(gl[k], m[k], 1e-5);  // float matrix
    // The corner's shadow on the receiver lies in the patch.
    const Vec3 ray = local ? c - light_or_direction : -1.0 * light_or_direction;
    const double s = (f.receiver.height - c[2]) / ray[2];
    const Vec3 shadow = c + s * ray;
    EXPECT_GE(shadow[0], f.receiver.min[0]);
    EXPECT_LE(shadow[0], f.receiver.max[0]);
    EXPECT_GE(shadow[1], f.receiver.min[1]);
    EXPECT_LE(shadow[1], f.receiver.max[1]);
    // The receiver under a raised corner is farther from the light than the corner.
    if (c[2] > f.receiver.height + 1e-9) {
      EXPECT_GT(f.map_coordinates(shadow)[2], m[2]);
    }
  }
}

TEST(ShadowFrustum, DirectionalBoxHoldsCastersAndTheirShadows) {
  const Vec3 towards = normalized(Vec3{0.5, -0.5, 0.4});
  const auto f = fit_shadow_frustum(towards, kCasters, 0.0, 0.005);
  ASSERT_TRUE(f.has_value());
  EXPECT_FALSE(f->local);
  EXPECT_NEAR(f->max[0] - f->min[0], f->max[1] - f->min[1], 1e-12);  // square texels
  expect_holds_everything(*f, towards, false);
}

TEST(ShadowFrustum, LampConeHoldsCastersAndTheirShadows) {
  const Vec3 lamp{-0.45, 0.05, 0.45};
  const auto f = fit_local_shadow_frustum(lamp, kCasters, 0.0, 0.005);
  ASSERT_TRUE(f.has_value());
  EXPECT_TRUE(f->local);
  expect_holds_everything(*f, lamp, true);
}

TEST(ShadowFrustum, NoShadowFromBelowTheGroundOrAmongTheObjects) {
  EXPECT_FALSE(fit_shadow_frustum(normalized(Vec3{1, 0, -0.1}), kCasters, 0.0, 0.0).has_value());
  EXPECT_FALSE(fit_shadow_frustum(Vec3{0, 0, 1}, {}, 0.0, 0.0).has_value());
  EXPECT_FALSE(fit_local_shadow_frustum({0, 0, 0.05}, kCasters, 0.0, 0.0).has_value());  // below a top
  // Straight overhead is fine (the light frame's x falls back to world x).
  EXPECT_TRUE(fit_shadow_frustum(Vec3{0, 0, 1}, kCasters, 0.0, 0.0).has_value());
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

// A map fitted around the small casters alone, then grown along the light for a 30 m floor and a
// 3 m column beside them (a courtyard of proxies): it takes in every point of theirs inside its
// column of light (sampled densely), and only a little more along the light than that part spans;
// a box wholly outside the column leaves it as it was.
TEST(ShadowFrustum, DepthGrowsOnlyByWhatLiesInTheColumn) {
  const Vec3 towards = normalized(Vec3{-0.5, 0.55, 0.67});
  const ShadowFrustum fitted = *fit_shadow_frustum(towards, kCasters, 0.0, 0.005);
  const Bounds floor{{-15, -15, 0}, {15, 15, 0}};
  const Bounds column{{-0.3, 0.2, 0}, {-0.1, 0.4, 3.0}};  // up-light of the casters: it shades them
  ShadowFrustum grown = fitted;
  ASSERT_TRUE(extend_depth_over(grown, floor));
  ASSERT_TRUE(extend_depth_over(grown, column));
  EXPECT_FALSE(extend_depth_over(grown, Bounds{{8, 8, 0}, {9, 9, 1}}));
  EXPECT_EQ(grown.min[0], fitted.min[0]);
  EXPECT_EQ(grown.max[1], fitted.max[1]);
  const Vec3 l = towards;
  double lo = INFINITY, hi = -INFINITY;  // the sampled points' depths inside the column
  for (const Bounds& box : {floor, column})
    for (int i = 0; i <= 300; ++i)
      for (int j = 0; j <= 300; ++j)
        for (int k = 0; k <= (box.max[2] > box.min[2] ? 30 : 0); ++k) {
          const Vec3 p{box.min[0] + (box.max[0] - box.min[0]) * i / 300, box.min[1] + (box.max[1] - box.min[1]) * j / 300,
                       box.min[2] + (box.max[2] - box.min[2]) * k / 30};
          const Vec3 q = mat_mul(fitted.R_light_world, p);
          if (q[0] < fitted.min[0] || q[0] > fitted.max[0] || q[1] < fitted.min[1] || q[1] > fitted.max[1]) continue;
          lo = std::min(lo, dot(l, p));
          hi = std::max(hi, dot(l, p));
        }
  ASSERT_LT(lo, hi);
  EXPECT_LE(grown.min[2], lo);
  EXPECT_GE(grown.max[2], hi);
  // Conservative by a slab's worth (an eighth of the column's 3 m, leaning 1 / l_z along the
  // light), not by the floor's 30 m: the floor alone would span about 22 m along this light.
  EXPECT_LE((grown.max[2] - grown.min[2]) - (hi - lo), (3.0 / 8) / l[2]);
  EXPECT_LT(grown.max[2] - grown.min[2], 5.0);
}

}  // namespace
}  // namespace arpipe
