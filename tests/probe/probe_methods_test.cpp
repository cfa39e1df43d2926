// The probe analyses on every frame of the probe-indoor capture (configs/sim/probe-indoor.toml),
// with the ground-truth pose so the probe is tested alone, against the true key light.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "core/probe/diffuse_probe.h"
#include "core/probe/mirror_probe.h"
#include "core/probe/brightest_components.h"
#include "core/sh/sh_irradiance.h"
#include "tests/probe/probe_test_support.h"

namespace arpipe {
namespace {

using namespace probe_test;

struct Capture {
  RecordingReader rec{capture_dir()};
  PixelRayCache rays;
  Frame frame;
  ProbeRegion region;
  LinearPatch patch;
  // Loads frame i and the probe's region and pixels.
  void analyse(size_t i, const ProbeSphere& probe) {
    rec.read(i, frame);
    ASSERT_TRUE(compute_probe_region(probe, rec.camera_model(), truth(i).T_cam_world_mid, rays, region));
    ASSERT_TRUE(decode_linear_patch(frame, region.rect, CameraResponse(), patch));
  }
  const GroundTruthFrame& truth(size_t i) const { return rec.ground_truth()[i]; }
};

// Irradiance of the key light at the probe centre in scene-linear units, RGB.
Vec3 key_irradiance(const GroundTruthFrame& gt, const ProbeSphere& probe) {
  const GroundTruthLight& key = key_light(gt);
  const Vec3 d = key.position - probe.center_world;
  const double e = key.strength / dot(d, d) * kSensitivity;
  return {e * key.color[0], e * key.color[1], e * key.color[2]};
}

TEST(ProbeMethods, CaptureHasBothProbesInView) {
  Capture c;
  ASSERT_GT(c.rec.frame_count(), 0u);
  ASSERT_EQ(c.rec.ground_truth().size(), c.rec.frame_count());
  for (const ProbeSphere& probe : {mirror_probe(), diffuse_probe()}) {
    c.analyse(0, probe);
    EXPECT_EQ(c.region.rim_in_image, 1.0);
    // r 0.04 m at about 0.55 m with f = 520 px: about 35 px; the seed's I_e was 90 x 90.
    EXPECT_GT(c.region.radius_px, 25);
    EXPECT_LT(c.region.radius_px, 45);
  }
}

// Mirror, environment method (the default). A mirror ball sees the lamp from the point that
// reflects it, which is r sin(angle/2) / D off the direction from its centre (2.4 degrees here:
// r 0.04 m, D 0.51 m, camera-probe-light angle 66 degrees). So: <= 2 degrees against the direction
// from the reflecting point (what a single ball can measure), and <= 2 degrees against the centre's
// direction once the lamp's distance is configured roughly (0.5 m; truly 0.51 m).
TEST(ProbeMethods, MirrorEnvironmentDirectionWithinTwoDegrees) {
  Capture c;
  const ProbeSphere probe = mirror_probe();
  double worst_point = 0, worst_centre = 0, worst_far = 0;
  for (size_t i = 0; i < c.rec.frame_count(); ++i) {
    c.analyse(i, probe);
    const MirrorProbeResult far = analyse_mirror_probe(probe, c.region, c.patch, {});
    MirrorProbeOptions o;
    o.light_distance_m = 0.5;
    const MirrorProbeResult near = analyse_mirror_probe(probe, c.region, c.patch, o);
    ASSERT_FALSE(far.lights.empty()) << "frame " << i;
    ASSERT_FALSE(near.lights.empty()) << "frame " << i;
    const Vec3 lamp = key_light(c.truth(i)).position;
    const double e_point = angle_deg(far.lights[0].direction_from_point,
                                     normalized(lamp - far.lights[0].reflection_point_world));
    const double e_centre = angle_deg(near.lights[0].light.direction_world, true_direction(c.truth(i), probe));
    const double e_far = angle_deg(far.lights[0].light.direction_world, true_direction(c.truth(i), probe));
    EXPECT_LE(e_point, 2.0) << "frame " << i;
    EXPECT_LE(e_centre, 2.0) << "frame " << i;
    // Unconfigured: within 2 degrees plus the 2.4-degree parallax bound.
    EXPECT_LE(e_far, 2.0 + 2.4) << "frame " << i;
    worst_point = std::max(worst_point, e_point);
    worst_centre = std::max(worst_centre, e_centre);
    worst_far = std::max(worst_far, e_far);
  }
  std::printf("mirror environment: worst %.2f deg from the reflecting point, %.2f deg from the centre with D = 0.5 m, "
              "%.2f deg from the centre with D unknown\n", worst_point, worst_centre, worst_far);
}

// The lamp's distance need not come from a tape measure: the diffuse probe's near-field fit gives
// the lamp's position (its centre + D l), and from it the mirror's D. With that, the mirror's
// direction from its centre is within the 2 degrees, with no ground truth as input.
TEST(ProbeMethods, MirrorWithLampDistanceFromTheDiffuseFit) {
  Capture c;
  const ProbeSphere mirror = mirror_probe(), diffuse = diffuse_probe();
  double worst = 0;
  for (size_t i = 0; i < c.rec.frame_count(); ++i) {
    c.analyse(i, diffuse);
    const DiffuseFitResult fit = fit_diffuse_probe(diffuse, c.region, c.patch, {});
    ASSERT_TRUE(fit.ok);
    ASSERT_GT(fit.light_distance_m, 0);
    const Vec3 lamp = diffuse.center_world + fit.light_distance_m * fit.light.direction_world;
    c.analyse(i, mirror);
    MirrorProbeOptions o;
    o.light_distance_m = norm(lamp - mirror.center_world);
    const MirrorProbeResult r = analyse_mirror_probe(mirror, c.region, c.patch, o);
    ASSERT_FALSE(r.lights.empty());
    const double err = angle_deg(r.lights[0].light.direction_world, true_direction(c.truth(i), mirror));
    EXPECT_LE(err, 2.0) << "frame " << i;
    worst = std::max(worst, err);
  }
  std::printf("mirror with the lamp distance from the diffuse fit: worst %.2f deg\n", worst);
}

// The key light is 884 W/(m^2 sr) x 100 in scene-linear units against a clip level of 250 / 0.9:
// the highlight is clipped, so its irradiance must be flagged as a lower bound and stay below the
// truth; its apparent size must still be about the lamp's (2 atan(0.03 / 0.51) = 6.7 degrees).
TEST(ProbeMethods, MirrorClippedHighlightIsALowerBound) {
  Capture c;
  const ProbeSphere probe = mirror_probe();
  for (size_t i = 0; i < c.rec.frame_count(); ++i) {
    c.analyse(i, probe);
    const MirrorProbeResult r = analyse_mirror_probe(probe, c.region, c.patch, {});
    ASSERT_FALSE(r.lights.empty());
    const MirrorLight& l = r.lights[0];
    EXPECT_TRUE(l.clipped) << "frame " << i;
    const Vec3 truth = key_irradiance(c.truth(i), probe);
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_GT(l.light.irradiance[k], 0) << "frame " << i;
      EXPECT_LT(l.light.irradiance[k], truth[k]) << "frame " << i;
    }
    // The lamp's disc plus about one pixel all round (a pixel reflects about 1.5 degrees here).
    const double diameter_deg = l.light.angular_diameter_rad * 180 / std::numbers::pi;
    EXPECT_GT(diameter_deg, 6.7 - 3) << "frame " << i;
    EXPECT_LT(diameter_deg, 6.7 + 6) << "frame " << i;
  }
}

// SH ambient of the mirror (the lamp taken out): the sky is 0.04 (0.045 blue) W/(m^2 sr), x 100,
// so an upward surface gets pi x 4 = 12.6 from it (the ring of bright table at the horizon and the
// band limit move this by a few units: within 50%). From below the table (albedo 0.35/0.30/0.25,
// lit by the key at about 7 W/m^2) gives pi x 0.3 x 7 / pi x 100 ~ 200, warm: much more than from
// above, and red > green > blue.
TEST(ProbeMethods, MirrorAmbientShIsSane) {
  Capture c;
  const ProbeSphere probe = mirror_probe();
  for (size_t i = 0; i < c.rec.frame_count(); i += 3) {
    c.analyse(i, probe);
    const MirrorProbeResult r = analyse_mirror_probe(probe, c.region, c.patch, {});
    const ShRgb ambient = from_sh9(r.ambient_sh);
    const Vec3 up = sh_irradiance(ambient, {0, 0, 1}), down = sh_irradiance(ambient, {0, 0, -1});
    const Vec3 sky{4 * std::numbers::pi, 4 * std::numbers::pi, 4.5 * std::numbers::pi};
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_GT(up[k], 0.5 * sky[k]) << "frame " << i;
      EXPECT_LT(up[k], 1.5 * sky[k]) << "frame " << i;
      EXPECT_GT(down[k], 5 * up[k]) << "frame " << i;
    }
    EXPECT_GT(down[0], down[1]);
    EXPECT_GT(down[1], down[2]);
    EXPECT_GT(r.seen_fraction, 0.7);  // a ball seen from one side shows most directions
  }
}

// Diffuse, fitted light (the default): within 5 degrees (the bound) and its irradiance
// within 5% of intensity / d^2 x 100 x colour. Where the 5% comes from: shot noise averages out
// over ~2800 pixels; the lamp is a 3 cm sphere, not a point (its irradiance differs from
// I / d^2 by (r_lamp / d)^2 ~ 0.2%); the fill light and table bounce are not in the first-order
// ambient model and leak into the light by a few per cent.
TEST(ProbeMethods, DiffuseFitDirectionAndIrradiance) {
  Capture c;
  const ProbeSphere probe = diffuse_probe();
  double worst = 0, worst_e = 0;
  for (size_t i = 0; i < c.rec.frame_count(); ++i) {
    c.analyse(i, probe);
    const DiffuseFitResult r = fit_diffuse_probe(probe, c.region, c.patch, {});
    ASSERT_TRUE(r.ok) << "frame " << i;
    const double err = angle_deg(r.light.direction_world, true_direction(c.truth(i), probe));
    EXPECT_LE(err, 5.0) << "frame " << i;
    worst = std::max(worst, err);
    const Vec3 truth = key_irradiance(c.truth(i), probe);
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(r.light.irradiance[k], truth[k], 0.05 * truth[k]) << "frame " << i << " channel " << k;
      worst_e = std::max(worst_e, std::abs(r.light.irradiance[k] / truth[k] - 1));
    }
    // The fitted lamp distance (near-field shading): truly 0.735 m; within 25%.
    EXPECT_NEAR(r.light_distance_m, 0.735, 0.25 * 0.735) << "frame " << i;
  }
  std::printf("diffuse fit: worst %.2f deg, worst irradiance error %.1f%%\n", worst, 100 * worst_e);
}

// Without the near-field term the lamp at 0.74 m biases the fit (terminator shifted by r/D = 3
// degrees towards the lamp, the near side 11% brighter), and the ambient's linear term trades with
// the light's direction: a bias of the order of 2 r/D rad = 6 degrees. Reported (the near-field
// model above is what meets the bound); asserted only against 10 degrees.
TEST(ProbeMethods, DiffuseFitFarLightModel) {
  Capture c;
  const ProbeSphere probe = diffuse_probe();
  double worst = 0;
  for (size_t i = 0; i < c.rec.frame_count(); ++i) {
    c.analyse(i, probe);
    DiffuseFitOptions o;
    o.fit_distance = false;
    const DiffuseFitResult r = fit_diffuse_probe(probe, c.region, c.patch, o);
    ASSERT_TRUE(r.ok);
    worst = std::max(worst, angle_deg(r.light.direction_world, true_direction(c.truth(i), probe)));
  }
  std::printf("diffuse fit, far-light model: worst %.2f deg\n", worst);
  EXPECT_LE(worst, 10.0);
}

// The diffuse fit's first-order ambient towards the fill light (0.4 W/sr at 0.87 m: 53 x colour
// (0.85, 0.9, 1.0)) holds the fill plus some sky and table: between 0.75 (an order-1 clamped
// cosine keeps 3/4 of its peak) and 1.75 times the fill, and blue-shifted like the fill.
TEST(ProbeMethods, DiffuseAmbientHoldsTheFill) {
  Capture c;
  const ProbeSphere probe = diffuse_probe();
  c.analyse(0, probe);
  const DiffuseFitResult r = fit_diffuse_probe(probe, c.region, c.patch, {});
  ASSERT_TRUE(r.ok);
  const Vec3 fill_pos{0.5, -0.4, 0.6};
  const Vec3 d = fill_pos - probe.center_world;
  const double e_fill = 0.4 / dot(d, d) * kSensitivity;
  const Vec3 colour{0.85, 0.9, 1.0};
  const Vec3 e = sh_irradiance(from_sh9(r.ambient_sh), normalized(d));
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_GT(e[k], 0.75 * e_fill * colour[k]) << k;
    EXPECT_LT(e[k], 1.75 * e_fill * colour[k]) << k;
  }
  EXPECT_GT(e[2], e[0]);
}

// The seed's method, both variants. On the mirror its l_max component is the clipped highlight;
// its direction is taken from the centroid point, so it carries the same 2.4-degree parallax as
// above plus the highlight's pixel quantisation: within 5 degrees. On the diffuse sphere the
// "brightest point" of a cosine lobe is flat-topped: shot noise of ~1% moves the maximum by about
// sqrt(2 x 0.01) rad = 8 degrees, so the seed's rule is only good to ~15 degrees there.
TEST(ProbeMethods, SeedVariants) {
  Capture c;
  struct Worst {
    double image = 0, sphere = 0;
  };
  Worst mirror, diffuse;
  for (size_t i = 0; i < c.rec.frame_count(); ++i) {
    for (const ProbeSphere& probe : {mirror_probe(), diffuse_probe()}) {
      c.analyse(i, probe);
      const CameraModel& model = c.rec.camera_model();
      const SE3& pose = c.truth(i).T_cam_world_mid;
      const BrightestComponentsResult si = brightest_components_image(probe, c.region, c.patch, model, pose, {});
      const BrightestComponentsResult ss = brightest_components_sphere(probe, c.region, c.patch, model, pose, {});
      ASSERT_EQ(si.components.size(), 1u);
      ASSERT_EQ(ss.components.size(), 1u);
      const Vec3 truth = true_direction(c.truth(i), probe);
      const double ei = angle_deg(si.components[0].light_world, truth);
      const double es = angle_deg(ss.components[0].light_world, truth);
      Worst& w = probe.kind == ProbeSphere::Kind::Mirror ? mirror : diffuse;
      w.image = std::max(w.image, ei);
      w.sphere = std::max(w.sphere, es);
      if (probe.kind == ProbeSphere::Kind::Mirror) {
        EXPECT_TRUE(si.components[0].clipped);
        EXPECT_LE(ei, 5.0) << "frame " << i;
        EXPECT_LE(es, 5.0) << "frame " << i;
      } else {
        EXPECT_LE(ei, 15.0) << "frame " << i;
        EXPECT_LE(es, 15.0) << "frame " << i;
      }
    }
  }
  std::printf("seed: mirror worst image %.2f / sphere %.2f deg; diffuse worst image %.2f / sphere %.2f deg\n",
              mirror.image, mirror.sphere, diffuse.image, diffuse.sphere);
}

}  // namespace
}  // namespace arpipe
