// Seed 000's blur schedule: the sample count from the box corners' screen paths, the sample times
// and cross-fade weights, and the inverse affine warps from each output sample into the intraframes.
#include "core/motion/intraframe_warp_plan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace arpipe {
namespace {

using Corners = std::vector<std::optional<Vec2>>;

constexpr int kPathPieces = 8;  // D follows each corner's path in 8 straight pieces
constexpr int kMaxSamples = kMaxInterframes + 2;

// A corner that is missing, or whose position is not finite, counts as not seen.
const Vec2* seen(const Corners& corners, size_t i) {
  if (i >= corners.size() || !corners[i]) return nullptr;
  const Vec2& p = *corners[i];
  return std::isfinite(p[0]) && std::isfinite(p[1]) ? &p : nullptr;
}

AffineFitKind weaker(AffineFitKind a, AffineFitKind b) { return int(a) >= int(b) ? a : b; }

// The inverse of the forward warp from the corners at `from` to those at `to`, over the corners
// seen at both; nullopt when no corner is. `src`/`dst` are scratch buffers reused across samples.
struct InverseWarp {
  Affine2 output_to_intraframe;
  AffineFitKind kind = AffineFitKind::Full;
};
std::optional<InverseWarp> inverse_warp(const Corners& from, const Corners& to, std::vector<Vec2>& src,
                                        std::vector<Vec2>& dst) {
  src.clear();
  dst.clear();
  for (size_t i = 0; i < from.size(); ++i) {
    const Vec2* a = seen(from, i);
    const Vec2* b = seen(to, i);
    if (a && b) {
      src.push_back(*a);
      dst.push_back(*b);
    }
  }
  const std::optional<AffineFit> fit = fit_affine(src, dst);
  if (!fit) return std::nullopt;
  if (const std::optional<Affine2> inverse = fit->map.inverse())
    return InverseWarp{*inverse, fit->kind};
  // The object collapses (nearly) onto a line or a point on screen at this time: the affine map
  // has no inverse, so move the intraframe by the corners' mean shift instead.
  Vec2 mean{0, 0};
  for (size_t i = 0; i < src.size(); ++i) mean = {mean[0] + dst[i][0] - src[i][0], mean[1] + dst[i][1] - src[i][1]};
  const double count = double(src.size());
  return InverseWarp{Affine2::translation({-mean[0] / count, -mean[1] / count}), AffineFitKind::Translation};
}

// An empty plan that still reports D.
IntraframeWarpPlan no_samples(IntraframeWarpPlan& plan) {
  plan.samples.clear();
  plan.worst_fit = AffineFitKind::Full;
  return std::move(plan);
}

}  // namespace

IntraframeWarpPlan plan_intraframe_warp_blur(const CornerTrack& corners_at, int fixed_samples) {
  IntraframeWarpPlan plan;

  // D: each corner seen at both ends of the exposure, followed through 9 instants. Like
  // max_image_motion_px, a piece counts only when the corner is seen at both of its ends.
  std::array<Corners, kPathPieces + 1> path;
  for (int k = 0; k <= kPathPieces; ++k) path[size_t(k)] = corners_at(double(k) / kPathPieces);
  const Corners& at_start = path.front();
  const Corners& at_end = path.back();
  const size_t corner_count = std::max(at_start.size(), at_end.size());
  double total = 0;
  int tracked = 0;
  for (size_t i = 0; i < corner_count; ++i) {
    if (!seen(at_start, i) || !seen(at_end, i)) continue;
    ++tracked;
    for (int k = 0; k < kPathPieces; ++k) {
      const Vec2* a = seen(path[size_t(k)], i);
      const Vec2* b = seen(path[size_t(k) + 1], i);
      if (a && b) total += norm(*b - *a);
    }
  }
  if (tracked == 0) return plan;  // nothing tracked: no motion to blur with
  plan.mean_corner_motion_px = total / tracked;

  // Seed defect: the thesis gives no minimum, and below 4 samples its q = floor(n/4) is 0
  // (Algorithm 2 divides by zero and never adds the intraframes); clamp to kIntraframeWarpMinSamples.
  // A tiny D still gives 4 samples; the caller skips the blur below half a pixel.
  int n = 0;
  if (fixed_samples > 0) {
    n = std::clamp(fixed_samples, kIntraframeWarpMinSamples, kMaxSamples);
  } else {
    const double interframes = std::min(std::round(plan.mean_corner_motion_px), double(kMaxInterframes));
    n = std::max(int(interframes) + 2, kIntraframeWarpMinSamples);
  }

  const Corners& at_first = path[size_t(kPathPieces / 4)];       // t = 0.25
  const Corners& at_second = path[size_t(3 * kPathPieces / 4)];  // t = 0.75
  static_assert(kPathPieces % 4 == 0, "the intraframe instants must be among the path instants");

  std::vector<Vec2> src, dst;
  src.reserve(corner_count);
  dst.reserve(corner_count);
  plan.samples.reserve(size_t(n));
  for (int i = 0; i < n; ++i) {
    // Seed defect: the thesis samples at i/n, i = 1..n, and then adds the current pose again
    // (the last interframe is t = 1 and the shader adds MainTex too), so the end pose counts twice.
    // Midpoints of n equal slices give a box filter over the shutter with no doubled pose; the
    // caller must not add a separate current-pose sample.
    IntraframeWarpSample sample;
    sample.exposure_fraction = (double(i) + 0.5) / n;
    const double t = sample.exposure_fraction;
    // Seed defect: with n not divisible by 4 the thesis's intraframe indices q and 3q do not sit at
    // 1/4 and 3/4 although the intraframes are rendered there. Weights from the sample's time, not
    // its index, keep the cross-fade right for any n.
    if (t <= kFirstIntraframe) {
      sample.weight_first = 1;
      sample.weight_second = 0;
    } else if (t >= kSecondIntraframe) {
      sample.weight_first = 0;
      sample.weight_second = 1;
    } else {
      const double beta = (t - kFirstIntraframe) / (kSecondIntraframe - kFirstIntraframe);
      sample.weight_first = 1 - beta;
      sample.weight_second = beta;
    }

    // A warp whose weight is 0 is never sampled: it stays the identity and is not fitted.
    const Corners at_t = corners_at(t);
    if (sample.weight_first > 0) {
      const auto warp = inverse_warp(at_first, at_t, src, dst);
      if (!warp) return no_samples(plan);  // no corner seen at both times: cannot place this sample
      sample.first_from_output = warp->output_to_intraframe;
      plan.worst_fit = weaker(plan.worst_fit, warp->kind);
    }
    if (sample.weight_second > 0) {
      const auto warp = inverse_warp(at_second, at_t, src, dst);
      if (!warp) return no_samples(plan);
      sample.second_from_output = warp->output_to_intraframe;
      plan.worst_fit = weaker(plan.worst_fit, warp->kind);
    }
    plan.samples.push_back(sample);
  }
  return plan;
}

}  // namespace arpipe
