// ProbeLightEstimator on the probe-indoor capture: per-frame states, confidence, smoothing, and
// the frames it must not measure (over-exposed, partly outside, out of view, no pose).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/image/pixel_convert.h"
#include "core/image/srgb.h"
#include "core/probe/probe_light_estimator.h"
#include "tests/probe/probe_test_support.h"

namespace arpipe {
namespace {

using namespace probe_test;

ProbeLightEstimator make(const ProbeSphere& probe, double light_distance_m = 0, double smoothing_s = 0.1) {
  ProbeLightConfig c;
  c.sphere = probe;
  c.light_distance_m = light_distance_m;
  c.smoothing_s = smoothing_s;
  ProbeLightEstimator e;
  e.configure(c);
  return e;
}

// The frame as the sensor would have taken it with `factor` times the exposure: each pixel's linear
// value scaled and clipped at full scale, re-encoded (sRGB), as RGB24, exposure metadata scaled too.
Frame overexposed(const Frame& f, double factor) {
  std::vector<uint8_t> rgb;
  to_rgb24(f, rgb);
  for (uint8_t& v : rgb) v = uint8_t(std::lround(255 * srgb_encode(std::min(1.0, factor * srgb_decode(v / 255.0)))));
  Frame out = from_rgb24(rgb.data(), f.width, f.height, PixelFormat::RGB24);
  out.meta = f.meta;
  out.meta.exposure_ns = int64_t(double(f.meta.exposure_ns) * factor);
  return out;
}

// The frame shifted left by `s` pixels (black on the right), with the principal point moved by the
// same amount: the same picture through the same lens, with the image border elsewhere.
Frame shifted(const Frame& f, int s) {
  std::vector<uint8_t> rgb, out(size_t(f.width * f.height * 3), 0);
  to_rgb24(f, rgb);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x + s < f.width; ++x)
      for (int c = 0; c < 3; ++c) out[size_t((y * f.width + x) * 3 + c)] = rgb[size_t((y * f.width + x + s) * 3 + c)];
  Frame r = from_rgb24(out.data(), f.width, f.height, PixelFormat::RGB24);
  r.meta = f.meta;
  return r;
}
CameraModel shifted(const CameraModel& m, int s) {
  std::vector<double> k = m.intrinsics();
  k[2] -= s;
  return CameraModel(m.lensmodel(), k, m.width(), m.height());
}

TEST(ProbeEstimator, MirrorDefaultEveryFrame) {
  RecordingReader rec(capture_dir());
  ProbeLightEstimator est = make(mirror_probe(), 0.5);
  EXPECT_EQ(est.method(), ProbeMethod::Environment);
  EXPECT_EQ(est.last().state, LightState::None);
  Frame frame;
  for (size_t i = 0; i < rec.frame_count(); ++i) {
    rec.read(i, frame);
    const GroundTruthFrame& gt = rec.ground_truth()[i];
    const LightEstimate e = est.update(frame, rec.camera_model(), gt.T_cam_world_mid, true);
    ASSERT_EQ(e.state, LightState::Estimated) << e.note;
    EXPECT_EQ(e.source, "mirror-probe");
    EXPECT_TRUE(e.scene_linear);
    ASSERT_EQ(e.lights.size(), 1u);
    // Smoothed over frames whose truth moves by < 0.5 degree: same 2-degree bound (see
    // probe_methods_test.cpp for the configured lamp distance).
    EXPECT_LE(angle_deg(e.lights[0].direction_world, true_direction(gt, mirror_probe())), 2.0) << "frame " << i;
    EXPECT_GT(e.confidence, 0.5);
    EXPECT_LE(e.confidence, 1.0);
    ASSERT_EQ(est.diagnostics().light_clipped.size(), 1u);
    EXPECT_TRUE(est.diagnostics().light_clipped[0]);
    EXPECT_NE(e.note.find("lower bound"), std::string::npos) << e.note;
  }
}

TEST(ProbeEstimator, DiffuseDefaultEveryFrame) {
  RecordingReader rec(capture_dir());
  ProbeLightEstimator est = make(diffuse_probe());
  EXPECT_EQ(est.method(), ProbeMethod::Fit);
  Frame frame;
  for (size_t i = 0; i < rec.frame_count(); ++i) {
    rec.read(i, frame);
    const GroundTruthFrame& gt = rec.ground_truth()[i];
    const LightEstimate e = est.update(frame, rec.camera_model(), gt.T_cam_world_mid, true);
    ASSERT_EQ(e.state, LightState::Estimated) << e.note;
    EXPECT_EQ(e.source, "diffuse-probe");
    ASSERT_EQ(e.lights.size(), 1u);
    EXPECT_LE(angle_deg(e.lights[0].direction_world, true_direction(gt, diffuse_probe())), 5.0) << "frame " << i;
    EXPECT_GT(e.confidence, 0.5);
  }
}

TEST(ProbeEstimator, NoPoseNoneThenHeld) {
  RecordingReader rec(capture_dir());
  ProbeLightEstimator est = make(diffuse_probe());
  Frame frame;
  rec.read(0, frame);
  const SE3 pose = rec.ground_truth()[0].T_cam_world_mid;
  LightEstimate e = est.update(frame, rec.camera_model(), pose, false);
  EXPECT_EQ(e.state, LightState::None);
  EXPECT_NE(e.note.find("pose"), std::string::npos);
  e = est.update(frame, rec.camera_model(), pose, true);
  ASSERT_EQ(e.state, LightState::Estimated);
  const Vec3 measured = e.lights[0].direction_world;
  e = est.update(frame, rec.camera_model(), pose, false);
  EXPECT_EQ(e.state, LightState::Held);
  EXPECT_EQ(e.frames_since_measured, 1);
  EXPECT_EQ(e.lights[0].direction_world, measured);
}

// The camera turned away (the probe behind it), then back: Held with the reason, counting frames,
// the last estimate kept; then Estimated again.
TEST(ProbeEstimator, OutOfViewHoldsTheLastEstimate) {
  RecordingReader rec(capture_dir());
  ProbeLightEstimator est = make(mirror_probe());
  Frame frame;
  rec.read(0, frame);
  const SE3 pose = rec.ground_truth()[0].T_cam_world_mid;
  const LightEstimate first = est.update(frame, rec.camera_model(), pose, true);
  ASSERT_EQ(first.state, LightState::Estimated);
  const SE3 away = SE3::from_rt({0, std::numbers::pi, 0}, {0, 0, 0}) * pose;  // turned half round
  for (int k = 1; k <= 3; ++k) {
    const LightEstimate e = est.update(frame, rec.camera_model(), away, true);
    EXPECT_EQ(e.state, LightState::Held);
    EXPECT_EQ(e.frames_since_measured, k);
    EXPECT_FALSE(e.note.empty());
    ASSERT_EQ(e.lights.size(), first.lights.size());
    EXPECT_EQ(e.lights[0].direction_world, first.lights[0].direction_world);
    EXPECT_EQ(e.confidence, first.confidence);
  }
  // Looking to the side: in front, but outside the image.
  const SE3 aside = SE3::from_rt({0, 1.2, 0}, {0, 0, 0}) * pose;
  const LightEstimate e = est.update(frame, rec.camera_model(), aside, true);
  EXPECT_EQ(e.state, LightState::Held);
  EXPECT_NE(e.note.find("out"), std::string::npos) << e.note;
  EXPECT_EQ(est.update(frame, rec.camera_model(), pose, true).state, LightState::Estimated);
}

// 30x the exposure clips most of both probes: a clear Held state whose note names the clipping
// (over-exposed outright, or a confidence too low because of it), no crash; 3x
// clips the diffuse probe's lit side partly: still measured (clipped pixels left out of the fit)
// with a lower confidence than the normal frame.
TEST(ProbeEstimator, SaturatedProbe) {
  RecordingReader rec(capture_dir());
  Frame frame;
  rec.read(0, frame);
  const SE3 pose = rec.ground_truth()[0].T_cam_world_mid;
  for (const ProbeSphere& probe : {mirror_probe(), diffuse_probe()}) {
    ProbeLightEstimator est = make(probe);
    const LightEstimate normal = est.update(frame, rec.camera_model(), pose, true);
    ASSERT_EQ(normal.state, LightState::Estimated);
    const LightEstimate burnt = est.update(overexposed(frame, 30), rec.camera_model(), pose, true);
    EXPECT_EQ(burnt.state, LightState::Held);
    EXPECT_NE(burnt.note.find("clipped"), std::string::npos) << burnt.note;
    EXPECT_EQ(burnt.frames_since_measured, 1);
    std::printf("%s probe at 30x exposure: %s: %s\n", probe.kind == ProbeSphere::Kind::Mirror ? "mirror" : "diffuse",
                std::string(light_state_name(burnt.state)).c_str(), burnt.note.c_str());
    if (probe.kind == ProbeSphere::Kind::Diffuse) {
      ProbeLightEstimator fresh = make(probe, 0, 0);
      const LightEstimate bright = fresh.update(overexposed(frame, 3), rec.camera_model(), pose, true);
      EXPECT_GT(fresh.diagnostics().clipped_fraction, 0.05);
      std::printf("diffuse probe at 3x exposure: %.0f%% clipped, %s, confidence %.2f (normal %.2f)\n",
                  100 * fresh.diagnostics().clipped_fraction, std::string(light_state_name(bright.state)).c_str(),
                  bright.confidence, normal.confidence);
      if (bright.state == LightState::Estimated) {
        EXPECT_LT(bright.confidence, normal.confidence);
        EXPECT_LE(angle_deg(bright.lights[0].direction_world, true_direction(rec.ground_truth()[0], probe)), 5.0);
      } else {
        EXPECT_FALSE(bright.note.empty());
      }
    }
  }
}

// The mirror ball pushed over the left image border (same picture, principal point moved): a
// little over the border it is measured with a lower confidence; mostly outside it is Held.
TEST(ProbeEstimator, ProbePartlyOutsideTheImage) {
  RecordingReader rec(capture_dir());
  Frame frame;
  rec.read(0, frame);
  const SE3 pose = rec.ground_truth()[0].T_cam_world_mid;
  PixelRayCache rays;
  ProbeRegion region;
  ASSERT_TRUE(compute_probe_region(mirror_probe(), rec.camera_model(), pose, rays, region));
  const double cx = region.center_px[0], r = region.radius_px;
  ProbeLightEstimator est = make(mirror_probe());
  const LightEstimate whole = est.update(frame, rec.camera_model(), pose, true);
  ASSERT_EQ(whole.state, LightState::Estimated);
  // A quarter of the radius over the border.
  const int s1 = int(cx - 0.75 * r);
  const LightEstimate partly = est.update(shifted(frame, s1), shifted(rec.camera_model(), s1), pose, true);
  EXPECT_LT(est.diagnostics().rim_in_view, 1.0);
  EXPECT_GE(est.diagnostics().rim_in_view, 0.5);
  if (partly.state == LightState::Estimated) {
    EXPECT_LT(partly.confidence, whole.confidence);
  } else {
    EXPECT_FALSE(partly.note.empty());
  }
  std::printf("partly outside (%.0f%% of the outline in view): %s, confidence %.2f (whole %.2f) %s\n", 100 * est.diagnostics().rim_in_view, std::string(light_state_name(partly.state)).c_str(), partly.confidence, whole.confidence, partly.note.c_str());
  // The centre 0.3 radius beyond the border.
  ProbeLightEstimator est2 = make(mirror_probe());
  const int s2 = int(cx + 0.3 * r);
  const LightEstimate outside = est2.update(shifted(frame, s2), shifted(rec.camera_model(), s2), pose, true);
  EXPECT_EQ(outside.state, LightState::None);
  EXPECT_NE(outside.note.find("partly outside"), std::string::npos) << outside.note;
}

// Smoothing: with a 0.1 s time constant and frames 1/30 s apart, a step in the measured direction
// moves the estimate by 1 - exp(-1/3) = 28.3% of the step on the next frame. The step: the same
// picture with the world turned 10 degrees about the probe's centre (the probe stays put, the
// measured light turns by exactly that rotation).
TEST(ProbeEstimator, ExponentialSmoothing) {
  RecordingReader rec(capture_dir());
  Frame frame;
  rec.read(0, frame);
  const SE3 pose = rec.ground_truth()[0].T_cam_world_mid;
  const ProbeSphere probe = diffuse_probe();
  const SE3 rot = SE3::from_rt({0, 0, 10 * std::numbers::pi / 180}, {0, 0, 0});
  const SE3 about_probe(rot.rotation(), probe.center_world - rot * probe.center_world);
  ProbeLightEstimator est = make(probe, 0, 0.1);
  const Vec3 d0 = est.update(frame, rec.camera_model(), pose, true).lights[0].direction_world;
  Frame next = frame;
  next.meta.exposure_start_ns += 33'333'333;
  const LightEstimate e = est.update(next, rec.camera_model(), pose * about_probe.inverse(), true);
  ASSERT_EQ(e.state, LightState::Estimated);
  const Vec3 raw = est.diagnostics().raw_directions.at(0);
  EXPECT_NEAR(angle_deg(raw, rot.rotate(d0)), 0, 0.2);
  const double expected = (1 - std::exp(-1.0 / 3)) * angle_deg(d0, raw);
  EXPECT_NEAR(angle_deg(d0, e.lights[0].direction_world), expected, 0.1);
  // No smoothing: the raw measurement.
  ProbeLightEstimator sharp = make(probe, 0, 0);
  sharp.update(frame, rec.camera_model(), pose, true);
  const LightEstimate s = sharp.update(next, rec.camera_model(), pose * about_probe.inverse(), true);
  EXPECT_NEAR(angle_deg(s.lights[0].direction_world, raw), 0, 1e-9);
}

TEST(ProbeEstimator, ConfigErrors) {
  ProbeLightEstimator est;
  ProbeLightConfig c;
  c.sphere = mirror_probe();
  c.method = ProbeMethod::Fit;
  EXPECT_THROW(est.configure(c), std::invalid_argument);
  c.method = ProbeMethod::BrightestSphere;
  EXPECT_NO_THROW(est.configure(c));
  EXPECT_EQ(est.method(), ProbeMethod::BrightestSphere);
  c.sphere = diffuse_probe();
  c.method = ProbeMethod::Environment;
  EXPECT_THROW(est.configure(c), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

// Stress: random and degenerate poses (camera inside the probe, on its surface, NaN, far away)
// and frames that do not fit (empty, wrong size, no exposure): never a throw, always a clear state.
TEST(ProbeEstimator, DegenerateInputsNeverThrow) {
  using namespace probe_test;
  RecordingReader rec(capture_dir());
  Frame frame;
  rec.read(0, frame);
  const CameraModel& model = rec.camera_model();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const ProbeSphere& probe : {mirror_probe(), diffuse_probe()}) {
    ProbeLightEstimator est = make(probe);
    const Vec3 c = probe.center_world;
    std::vector<SE3> poses = {
        SE3(identity3(), Vec3{0, 0, 0} - c),  // camera at the probe's centre
        SE3(identity3(), Vec3{0, 0, -probe.radius_m} - c),  // on its surface
        SE3(identity3(), {0, 0, 1e9}),
        SE3(identity3(), {std::nan(""), 0, 0}),
    };
    for (int i = 0; i < 200; ++i)
      poses.push_back(SE3::from_rt({3 * u(rng), 3 * u(rng), 3 * u(rng)}, {0.5 * u(rng), 0.5 * u(rng), 0.2 + u(rng)}));
    for (const SE3& pose : poses) {
      const LightEstimate e = est.update(frame, model, pose, true);
      EXPECT_TRUE(e.state == LightState::Estimated || e.state == LightState::None || e.state == LightState::Held);
      if (e.state != LightState::Estimated) {
        EXPECT_FALSE(e.note.empty());
      }
      EXPECT_GE(e.confidence, 0);
      EXPECT_LE(e.confidence, 1);
    }
    const SE3 good = rec.ground_truth()[0].T_cam_world_mid;
    Frame empty;
    EXPECT_NE(est.update(empty, model, good, true).state, LightState::Estimated);
    Frame no_exposure = frame;
    no_exposure.meta.exposure_ns = 0;
    EXPECT_NE(est.update(no_exposure, model, good, true).state, LightState::Estimated);
    Frame small = Frame::allocate(PixelFormat::RGB24, 64, 48);
    small.meta = frame.meta;
    EXPECT_NE(est.update(small, model, good, true).state, LightState::Estimated);
    EXPECT_EQ(est.update(frame, model, good, true).state, LightState::Estimated);
  }
}

}  // namespace
}  // namespace arpipe
