// plan_intraframe_warp_blur against analytic corner motions: translations (D, n, the warps), a rotation
// about the image centre, a scaling with partly hidden corners, a motion that turns back, a
// collapse onto a line, fixed sample counts and untrackable corners.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "core/motion/intraframe_warp_plan.h"

namespace arpipe {
namespace {

// Eight box corners on screen (base and top), no three of them needed to be collinear.
const std::vector<Vec2> kCorners{{200, 150}, {440, 150}, {440, 330}, {200, 330},
                                 {230, 100}, {410, 110}, {420, 300}, {220, 290}};
const Vec2 kCentre{320, 240};

// All kCorners moved by `shift(t)`.
template <class Shift>
CornerTrack translating(Shift shift) {
  return [shift](double t) {
    std::vector<std::optional<Vec2>> out;
    const Vec2 s = shift(t);
    for (const Vec2& c : kCorners) out.push_back(Vec2{c[0] + s[0], c[1] + s[1]});
    return out;
  };
}

Vec2 rotated_about_centre(const Vec2& p, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Vec2 d = p - kCentre;
  return {kCentre[0] + c * d[0] - s * d[1], kCentre[1] + s * d[0] + c * d[1]};
}

double max_entry_difference(const Affine2& a, const Affine2& b) {
  double worst = 0;
  for (size_t i = 0; i < 6; ++i) worst = std::max(worst, std::abs(a.m[i] - b.m[i]));
  return worst;
}

// The weights the brief fixes from the sample's time: the thesis's alpha/beta, written in t.
void expect_time_weights(const IntraframeWarpSample& s) {
  const double t = s.exposure_fraction;
  const double beta = std::clamp((t - 0.25) / 0.5, 0.0, 1.0);
  EXPECT_NEAR(s.weight_second, beta, 1e-15) << t;
  EXPECT_NEAR(s.weight_first, 1 - beta, 1e-15) << t;
  EXPECT_NEAR(s.weight_first + s.weight_second, 1.0, 1e-15) << t;
}

TEST(IntraframeWarpPlan, TranslationGivesTheTravelTheSampleCountAndTranslationWarps) {
  const Vec2 dir{0.6, 0.8};
  // D = L, then n = min(round(L), 48) + 2, at least 4: 0.3 -> 4, 2.6 -> 5, 10 -> 12, 47.4 -> 49,
  // 100 -> 50.
  const std::vector<std::pair<double, int>> cases{{0.3, 4}, {2.6, 5}, {10, 12}, {47.4, 49}, {100, 50}};
  for (const auto& [length, expected_n] : cases) {
    const auto motion = [dir, length = length](double t) { return Vec2{t * length * dir[0], t * length * dir[1]}; };
    const IntraframeWarpPlan plan = plan_intraframe_warp_blur(translating(motion));
    // 8 straight pieces of a straight path sum to its length; only rounding remains (1e-9 px).
    EXPECT_NEAR(plan.mean_corner_motion_px, length, 1e-9);
    ASSERT_EQ(int(plan.samples.size()), expected_n) << length;
    EXPECT_EQ(plan.worst_fit, AffineFitKind::Full);
    const int n = expected_n;
    for (int i = 0; i < n; ++i) {
      const IntraframeWarpSample& s = plan.samples[size_t(i)];
      const double t = (i + 0.5) / n;
      EXPECT_DOUBLE_EQ(s.exposure_fraction, t);
      expect_time_weights(s);
      // Output -> intraframe is the inverse of the forward shift from the intraframe time to t.
      // Exact data on corners within 640 px: the fit is exact up to rounding (1e-9 allowed).
      const Vec2 from_first = motion(0.25) - motion(t), from_second = motion(0.75) - motion(t);
      if (s.weight_first > 0)
        EXPECT_LT(max_entry_difference(s.first_from_output, Affine2::translation(from_first)), 1e-9) << i;
      else
        EXPECT_EQ(s.first_from_output.m, Affine2::identity().m);  // unused: left at the identity
      if (s.weight_second > 0)
        EXPECT_LT(max_entry_difference(s.second_from_output, Affine2::translation(from_second)), 1e-9) << i;
      else
        EXPECT_EQ(s.second_from_output.m, Affine2::identity().m);
    }
    // Samples lie symmetrically about mid-exposure, and so do the weights; none at t = 0 or 1.
    for (int i = 0; i < n; ++i) {
      const IntraframeWarpSample &a = plan.samples[size_t(i)], &b = plan.samples[size_t(n - 1 - i)];
      EXPECT_NEAR(a.exposure_fraction + b.exposure_fraction, 1.0, 1e-15);
      EXPECT_NEAR(a.weight_first, b.weight_second, 1e-15);
      EXPECT_GT(a.exposure_fraction, 0);
      EXPECT_LT(a.exposure_fraction, 1);
      if (i > 0) {  // monotonic cross-fade
        EXPECT_LE(a.weight_first, plan.samples[size_t(i - 1)].weight_first);
        EXPECT_GE(a.weight_second, plan.samples[size_t(i - 1)].weight_second);
        EXPECT_GT(a.exposure_fraction, plan.samples[size_t(i - 1)].exposure_fraction);
      }
    }
  }
}

TEST(IntraframeWarpPlan, RotationAboutTheImageCentre) {
  // Corners turning by omega t about the centre: each follows 8 chords of 2 r sin(omega/16).
  const double omega = 0.3;
  const CornerTrack track = [omega](double t) {
    std::vector<std::optional<Vec2>> out;
    for (const Vec2& c : kCorners) out.push_back(rotated_about_centre(c, omega * t));
    return out;
  };
  const IntraframeWarpPlan plan = plan_intraframe_warp_blur(track);
  double expected_d = 0;
  for (const Vec2& c : kCorners) expected_d += 16 * norm(c - kCentre) * std::sin(omega / 16);
  expected_d /= double(kCorners.size());
  EXPECT_NEAR(plan.mean_corner_motion_px, expected_d, 1e-9);
  const int n = std::min(int(std::round(expected_d)), 48) + 2;
  ASSERT_EQ(int(plan.samples.size()), n);
  EXPECT_EQ(plan.worst_fit, AffineFitKind::Full);
  // The inverse warp turns an output pixel back by the rotation since the intraframe's time.
  // Exact rigid motion of exact data: rounding only, 1e-9 px.
  for (const IntraframeWarpSample& s : plan.samples) {
    expect_time_weights(s);
    for (const Vec2& p : {Vec2{0, 0}, Vec2{640, 480}, Vec2{300, 260}}) {
      if (s.weight_first > 0) {
        const Vec2 want = rotated_about_centre(p, -omega * (s.exposure_fraction - 0.25));
        EXPECT_LT(norm(s.first_from_output.apply(p) - want), 1e-9);
      }
      if (s.weight_second > 0) {
        const Vec2 want = rotated_about_centre(p, -omega * (s.exposure_fraction - 0.75));
        EXPECT_LT(norm(s.second_from_output.apply(p) - want), 1e-9);
      }
    }
  }
}

TEST(IntraframeWarpPlan, PartlyHiddenCornersAreLeftOutWhereTheyAreNotSeen) {
  // Scaling about the centre by 1 + s t: corner j travels s r_j. Corner 0 is hidden before
  // t = 0.1 and corner 1 after t = 0.9 (both left out of D), corner 2 around mid-exposure (its
  // pieces touching t = 0.5 are not seen, so it counts 6/8 of its path), corner 3 only at the
  // sample times just past 1/4. The warps stay exact scalings over the corners that are seen.
  const double s = 0.2;
  const auto scale_at = [s](double t) { return 1 + s * t; };
  const CornerTrack track = [&](double t) {
    std::vector<std::optional<Vec2>> out;
    for (size_t j = 0; j < kCorners.size(); ++j) {
      const bool hidden = (j == 0 && t < 0.1) || (j == 1 && t > 0.9) || (j == 2 && t > 0.4 && t < 0.6) ||
                          (j == 3 && t > 0.26 && t < 0.35);
      if (hidden) {
        out.push_back(std::nullopt);
        continue;
      }
      const Vec2 d = kCorners[j] - kCentre;
      out.push_back(Vec2{kCentre[0] + scale_at(t) * d[0], kCentre[1] + scale_at(t) * d[1]});
    }
    return out;
  };
  const IntraframeWarpPlan plan = plan_intraframe_warp_blur(track, 12);
  double expected_d = 0;
  for (size_t j = 2; j < kCorners.size(); ++j) expected_d += (j == 2 ? 0.75 : 1.0) * s * norm(kCorners[j] - kCentre);
  expected_d /= 6;
  EXPECT_NEAR(plan.mean_corner_motion_px, expected_d, 1e-9);
  ASSERT_EQ(plan.samples.size(), 12u);
  EXPECT_EQ(plan.worst_fit, AffineFitKind::Full);
  for (const IntraframeWarpSample& sample : plan.samples) {
    const double t = sample.exposure_fraction;
    for (const Vec2& p : {Vec2{0, 0}, Vec2{640, 480}}) {
      const Vec2 d = p - kCentre;
      if (sample.weight_first > 0) {
        const double k = scale_at(0.25) / scale_at(t);
        EXPECT_LT(norm(sample.first_from_output.apply(p) - Vec2{kCentre[0] + k * d[0], kCentre[1] + k * d[1]}), 1e-9);
      }
      if (sample.weight_second > 0) {
        const double k = scale_at(0.75) / scale_at(t);
        EXPECT_LT(norm(sample.second_from_output.apply(p) - Vec2{kCentre[0] + k * d[0], kCentre[1] + k * d[1]}),
                  1e-9);
      }
    }
  }
}

TEST(IntraframeWarpPlan, UntrackableCornersGiveAnEmptyPlan) {
  const CornerTrack never = [](double) { return std::vector<std::optional<Vec2>>(8, std::nullopt); };
  const IntraframeWarpPlan none = plan_intraframe_warp_blur(never);
  EXPECT_TRUE(none.samples.empty());
  EXPECT_EQ(none.mean_corner_motion_px, 0);
  EXPECT_TRUE(plan_intraframe_warp_blur([](double) { return std::vector<std::optional<Vec2>>{}; }).samples.empty());

  // Seen at both ends but never at 1/4: D is known, but the first intraframe cannot be warped.
  const CornerTrack gap = [](double t) {
    std::vector<std::optional<Vec2>> out;
    for (const Vec2& c : kCorners) {
      if (std::abs(t - 0.25) < 0.01) out.push_back(std::nullopt);
      else out.push_back(Vec2{c[0] + 10 * t, c[1]});
    }
    return out;
  };
  const IntraframeWarpPlan gapped = plan_intraframe_warp_blur(gap);
  EXPECT_TRUE(gapped.samples.empty());
  EXPECT_NEAR(gapped.mean_corner_motion_px, 10.0 * 6 / 8, 1e-9);  // the two pieces touching 1/4 unseen

  // A corner position that is not finite counts as not seen.
  const CornerTrack nan_track = [](double) {
    return std::vector<std::optional<Vec2>>(4, Vec2{std::nan(""), 0.0});
  };
  EXPECT_TRUE(plan_intraframe_warp_blur(nan_track).samples.empty());
}

TEST(IntraframeWarpPlan, NoMotionStillGivesTheMinimumSamples) {
  // D = 0: the caller, not the plan, skips the blur below half a pixel; the plan is 4 identities.
  const IntraframeWarpPlan plan = plan_intraframe_warp_blur(translating([](double) { return Vec2{0, 0}; }));
  EXPECT_EQ(plan.mean_corner_motion_px, 0);
  ASSERT_EQ(plan.samples.size(), 4u);
  for (const IntraframeWarpSample& s : plan.samples) {
    EXPECT_LT(max_entry_difference(s.first_from_output, Affine2::identity()), 1e-12);
    EXPECT_LT(max_entry_difference(s.second_from_output, Affine2::identity()), 1e-12);
  }
}

TEST(IntraframeWarpPlan, FixedSampleCountsAreHonouredAndClamped) {
  const auto track = translating([](double t) { return Vec2{100 * t, 0}; });  // would give 50
  for (const auto& [asked, expected] : std::vector<std::pair<int, int>>{{5, 5}, {1, 4}, {3, 4}, {7, 7}, {50, 50},
                                                                         {51, 50}, {1000, 50}, {0, 50}, {-3, 50}}) {
    const IntraframeWarpPlan plan = plan_intraframe_warp_blur(track, asked);
    ASSERT_EQ(int(plan.samples.size()), expected) << asked;
    EXPECT_NEAR(plan.mean_corner_motion_px, 100, 1e-9);
    for (int i = 0; i < expected; ++i) {
      EXPECT_DOUBLE_EQ(plan.samples[size_t(i)].exposure_fraction, (i + 0.5) / expected);
      expect_time_weights(plan.samples[size_t(i)]);
    }
  }
}

TEST(IntraframeWarpPlan, AMotionThatTurnsBackCountsItsPath) {
  // Out by 5 px until mid-exposure and back: the ends coincide, but each corner travels 10 px
  // (the turn lies on one of the 8 path instants, so the chords sum to it exactly).
  const Vec2 dir{0.8, -0.6};
  const auto motion = [dir](double t) {
    const double out = 5 * (1 - std::abs(2 * t - 1));
    return Vec2{out * dir[0], out * dir[1]};
  };
  const IntraframeWarpPlan plan = plan_intraframe_warp_blur(translating(motion));
  EXPECT_NEAR(plan.mean_corner_motion_px, 10, 1e-9);
  ASSERT_EQ(plan.samples.size(), 12u);
  for (const IntraframeWarpSample& s : plan.samples) {
    if (s.weight_first > 0) {
      const Vec2 back = motion(0.25) - motion(s.exposure_fraction);
      EXPECT_LT(max_entry_difference(s.first_from_output, Affine2::translation(back)), 1e-9);
    }
  }
}

TEST(IntraframeWarpPlan, ACollapseOntoALineFallsBackToTheMeanShift) {
  // The box flattens vertically, y - 240 scaled by 1 - 2t: at t = 0.5 (sample 2 of 5) every corner
  // lies on y = 240, the forward warp from 1/4 has no inverse, and the mean shift stands in.
  const CornerTrack track = [](double t) {
    std::vector<std::optional<Vec2>> out;
    for (const Vec2& c : kCorners) out.push_back(Vec2{c[0], kCentre[1] + (1 - 2 * t) * (c[1] - kCentre[1])});
    return out;
  };
  const IntraframeWarpPlan plan = plan_intraframe_warp_blur(track, 5);
  ASSERT_EQ(plan.samples.size(), 5u);
  EXPECT_EQ(plan.worst_fit, AffineFitKind::Translation);
  const IntraframeWarpSample& mid = plan.samples[2];
  ASSERT_DOUBLE_EQ(mid.exposure_fraction, 0.5);
  double mean_dy = 0;  // forward shift from 1/4 (factor 0.5) to 1/2 (factor 0): -0.5 (y - 240)
  for (const Vec2& c : kCorners) mean_dy += -0.5 * (c[1] - kCentre[1]);
  mean_dy /= double(kCorners.size());
  EXPECT_LT(max_entry_difference(mid.first_from_output, Affine2::translation({0, -mean_dy})), 1e-9);
  // From 3/4 (factor -0.5) to 1/2 is singular too.
  EXPECT_LT(max_entry_difference(mid.second_from_output, Affine2::translation({0, mean_dy})), 1e-9);
  // Elsewhere the flattening is an invertible vertical scaling: y_out - 240 = k (y_in - 240).
  const IntraframeWarpSample& early = plan.samples[0];  // t = 0.1, factor 0.8, from 0.5
  EXPECT_LT(max_entry_difference(early.first_from_output, Affine2{{1, 0, 0, 0, 0.5 / 0.8, 240 * (1 - 0.5 / 0.8)}}),
            1e-9);
}

}  // namespace
}  // namespace arpipe
