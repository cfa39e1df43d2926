// Tests of which objects skip their shadow lookups (render/shadow/unshadowed_objects.h): the
// geometric cases one by one, then through the render stage, where a lone cube's faces keep the
// exact Lambert colour with PCSS on, and a cube in another's shadow still gets it.
#include "render/shadow/unshadowed_objects.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>

#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

// A 6 cm convex cube standing at (x, y, z), as the render stage holds it (no GL needed here).
UploadedObject cube_at(double x, double y, double z = 0) {
  UploadedObject object;
  object.bounds = {{-0.03, -0.03, 0.0}, {0.03, 0.03, 0.06}};
  object.T_world_object = SE3::from_rt({0, 0, 0}, {x, y, z});
  object.closed_convex = true;
  return object;
}

std::vector<const UploadedObject*> unshadowed(const std::vector<const UploadedObject*>& casters, const Vec3& towards_light,
                                              ShadowMethod method = ShadowMethod::Pcss, double reach_m = 0.005) {
  std::vector<ShadowCaster> boxes;
  for (const UploadedObject* caster : casters) boxes.push_back({caster->bounds, caster->T_world_object});
  const std::optional<ShadowFrustum> frustum = fit_shadow_frustum(normalized(towards_light), boxes, 0.0, 0.01);
  EXPECT_TRUE(frustum.has_value());
  return frustum ? unshadowed_objects(casters, *frustum, method, reach_m) : std::vector<const UploadedObject*>{};
}

bool contains(const std::vector<const UploadedObject*>& list, const UploadedObject& object) {
  return std::find(list.begin(), list.end(), &object) != list.end();
}

TEST(UnshadowedObjects, ALoneConvexObjectNeedsNoLookupsAndAConcaveOneDoes) {
  UploadedObject cube = cube_at(0, 0);
  EXPECT_TRUE(contains(unshadowed({&cube}, {0.3, -0.4, 1.0}), cube));
  cube.closed_convex = false;
  EXPECT_TRUE(unshadowed({&cube}, {0.3, -0.4, 1.0}).empty());
}

TEST(UnshadowedObjects, ObjectsApartAcrossTheLightSkipAndOneBehindAnotherDoesNot) {
  // Light from +x, 45 degrees up. Side by side along y, 10 cm apart: neither reaches the other.
  UploadedObject a = cube_at(0, 0), b = cube_at(0, 0.10);
  std::vector<const UploadedObject*> out = unshadowed({&a, &b}, {1, 0, 1});
  EXPECT_TRUE(contains(out, a));
  EXPECT_TRUE(contains(out, b));
  // b raised on the light's side of a, its shadow over a: a keeps its lookups. a lies wholly
  // farther from the light than b, so b skips. (Beside a on the ground, 8 cm towards the light, b
  // would keep them too: a's top corner is nearer the light than b's foot, and the test is on boxes.)
  b = cube_at(0.15, 0, 0.10);
  out = unshadowed({&a, &b}, {1, 0, 1});
  EXPECT_FALSE(contains(out, a));
  EXPECT_TRUE(contains(out, b));
  // The lookup's reach counts: 4 cm apart across the light, missed at 5 mm, reached at 5 cm.
  b = cube_at(0.08, 0.10);
  EXPECT_TRUE(contains(unshadowed({&a, &b}, {1, 0, 1}, ShadowMethod::Pcss, 0.005), a));
  EXPECT_FALSE(contains(unshadowed({&a, &b}, {1, 0, 1}, ShadowMethod::Pcss, 0.05), a));
}

TEST(UnshadowedObjects, ProxiesVarianceMapsAndLampsKeepTheLookups) {
  UploadedObject a = cube_at(0, 0), wall = cube_at(0.08, 0);
  wall.proxy = true;  // a real caster on the light's side
  std::vector<const UploadedObject*> out = unshadowed({&a, &wall}, {1, 0, 1});
  EXPECT_FALSE(contains(out, a));
  EXPECT_FALSE(contains(out, wall)) << "a proxy is never shaded";
  EXPECT_TRUE(unshadowed({&a}, {0.3, -0.4, 1.0}, ShadowMethod::Vsm).empty()) << "the map holds the ground";
  EXPECT_TRUE(unshadowed({&a}, {0.3, -0.4, 1.0}, ShadowMethod::Off).empty());
  // A lamp: only a lone object skips.
  UploadedObject b = cube_at(0, 0.5);
  const std::vector<ShadowCaster> boxes{{a.bounds, a.T_world_object}, {b.bounds, b.T_world_object}};
  const std::optional<ShadowFrustum> lamp = fit_local_shadow_frustum({0, 0.25, 1.0}, boxes, 0.0, 0.01);
  ASSERT_TRUE(lamp.has_value());
  EXPECT_TRUE(unshadowed_objects(std::vector<const UploadedObject*>{&a, &b}, *lamp, ShadowMethod::Pcss, 0.005).empty());
  const std::optional<ShadowFrustum> lamp_one = fit_local_shadow_frustum({0, 0.25, 1.0}, std::span(boxes).first(1), 0.0, 0.01);
  ASSERT_TRUE(lamp_one.has_value());
  EXPECT_EQ(unshadowed_objects(std::vector<const UploadedObject*>{&a}, *lamp_one, ShadowMethod::Pcss, 0.005).size(), 1u);
}

// Through the render stage: two cubes under a low light from -x, the second (scale 1.5, 9 cm)
// 13 cm towards the light, so its shadow covers the first's -x face. The first is drawn with its
// lookups (that face darker than Lambert), the second without them: its lit faces are exactly
// Lambert with PCSS on.
constexpr int kWidth = 320, kHeight = 240;
const Vec3 kColor{0.8, 0.3, 0.1};

TEST(UnshadowedObjects, TheShadowedCubeKeepsItsShadowAndTheLoneOneIsExactLambert) {
  Config config;
  config.render.objects = {SceneObject{}, SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";
  config.render.objects[0].color = kColor;
  config.render.objects[1].mesh = "builtin:cube";
  config.render.objects[1].color = kColor;
  config.render.objects[1].scale = 1.5;
  config.render.objects[1].position_m = {-0.13, 0.0, 0.0};
  config.render.ambient = {0, 0, 0};  // then a face's colour is base x light x cos: nothing else
  config.render.light_color = {1, 1, 1};
  config.render.light_direction = normalized(Vec3{-1.0, -0.3, 0.45});
  config.render.objects[0].prt = ObjectPrt::Off;
  config.render.objects[1].prt = ObjectPrt::Off;
  ASSERT_EQ(config.render.shadows.method, ShadowMethod::Pcss);
  StageHarness harness;
  harness.configure(config);
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(300.0, 300.0, 159.5, 119.5, kWidth, kHeight));
  const SE3 pose = look_at({-0.30, -0.40, 0.22}, {-0.06, 0.0, 0.03});
  Frame black = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(black.data.begin(), black.data.end(), uint8_t{0});
  FrameContext ctx = make_context(black, camera, pose);
  harness.process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);

  const Box first{{-0.03, -0.03, 0.0}, {0.03, 0.03, 0.06}}, second{{-0.175, -0.045, 0.0}, {-0.085, 0.045, 0.09}};
  const std::vector<PixelTruth> first_truth = classify_image(*camera, pose, first, 1.0);
  const std::vector<PixelTruth> second_truth = classify_image(*camera, pose, second, 1.0);
  const Vec3 normals[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  int first_shadowed = 0, first_lit_face = 0, second_checked = 0;
  std::set<int> second_faces;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = size_t(y) * kWidth + x;
      const PixelTruth& a = first_truth[i];
      const PixelTruth& b = second_truth[i];
      const uint8_t* out = ctx.output.data.data() + size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3;
      if (b.cls == PixelClass::Inside && a.cls == PixelClass::Outside) {
        const double lambert = std::max(dot(normals[b.face], config.render.light_direction), 0.0);
        if (lambert <= 0) continue;
        second_faces.insert(b.face);
        ++second_checked;
        for (size_t c = 0; c < 3; ++c)
          ASSERT_NEAR(out[c], encode_srgb_8bit(kColor[c] * lambert), 1) << "second cube, face " << b.face << " (" << x << ", " << y << ")";
      }
      if (a.cls == PixelClass::Inside && b.cls == PixelClass::Outside && a.face == 0) {
        ++first_lit_face;
        const double lambert = dot(normals[0], config.render.light_direction);
        if (out[0] < 0.5 * encode_srgb_8bit(kColor[0] * lambert)) ++first_shadowed;
      }
    }
  EXPECT_GT(second_checked, 200);
  EXPECT_EQ(second_faces, (std::set<int>{0, 2, 5})) << "the second cube's lit -x, -y and +z faces show";
  ASSERT_GT(first_lit_face, 100) << "the first cube's -x face shows";
  EXPECT_GT(first_shadowed, first_lit_face / 2) << "the second cube's shadow darkens the first's -x face";
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

// How far a lookup reads, in metres across the map: a PCF kernel's half-width, or the PCSS search,
// which for a directional light is at most the penumbra of a blocker at the light's end of the
// depth range (per_depth texels) and never beyond max_search; a texel more for the bilinear tap.
TEST(ShadowLookupReach, PcssReadsNoFurtherThanTheWidestPenumbraOrTheSearchCap) {
  ShadowFrustum frustum;
  frustum.min = {0, 0, 0};
  frustum.max = {2.048, 2.048, 1};  // 2 mm texels on a 1024 map
  ShadowLookup lookup;
  lookup.texel = 1.0f / 1024;
  lookup.method = ShadowMethod::Pcss;
  lookup.max_search_texels = 32;
  lookup.penumbra_texels_per_depth = 5;
  EXPECT_NEAR(shadow_lookup_reach_m(lookup, frustum), 6 * 0.002, 1e-9);
  lookup.penumbra_texels_per_depth = 100;
  EXPECT_NEAR(shadow_lookup_reach_m(lookup, frustum), 33 * 0.002, 1e-9);
  lookup.penumbra_texels_per_depth = 0.1f;  // the search reads at least a texel around
  EXPECT_NEAR(shadow_lookup_reach_m(lookup, frustum), 2 * 0.002, 1e-9);
  lookup.local = true;  // a lamp's penumbra grows towards it: the cap
  EXPECT_NEAR(shadow_lookup_reach_m(lookup, frustum), 33 * 0.002, 1e-9);
  lookup.method = ShadowMethod::Pcf;
  lookup.pcf_radius_texels = 1.5f;
  EXPECT_NEAR(shadow_lookup_reach_m(lookup, frustum), 2.5 * 0.002, 1e-9);
}

}  // namespace
}  // namespace arpipe
