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
