// Seed 000's motion-blur schedule (Park, Lepetit and Woo 2012, as the thesis adapts it): how many
// samples, when each lies in the exposure, and the affine warps that make each from the two
// rendered intraframes at 1/4 and 3/4 of the exposure. CPU only; render/blur/intraframe_warp_blur_pass draws it.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "core/motion/affine_2d.h"

namespace arpipe {

inline constexpr double kFirstIntraframe = 0.25;   // exposure fractions of the two renders
inline constexpr double kSecondIntraframe = 0.75;
inline constexpr int kMaxInterframes = 48;         // the thesis's cap: 48 warped + 2 rendered
inline constexpr int kIntraframeWarpMinSamples = 4;              // below 4 the thesis's q = floor(n/4) is 0

struct IntraframeWarpSample {
  double exposure_fraction = 0;  // when in the exposure this sample shows the object, in (0, 1)
  // Weights of the two warped intraframes (premultiplied colour and alpha alike): 1/0 before the
  // first intraframe, 0/1 after the second, a linear cross-fade between them (the thesis's alpha
  // and beta); they sum to 1.
  double weight_first = 1;
  double weight_second = 0;
  // Output pixel -> where to sample each intraframe (pixel coordinates, centres at integers): the
  // inverse of the forward warp intraframe -> this sample, as the fragment shader needs it.
  Affine2 first_from_output;
  Affine2 second_from_output;
};

struct IntraframeWarpPlan {
  double mean_corner_motion_px = 0;  // D: mean path of the box corners over the exposure
  std::vector<IntraframeWarpSample> samples;  // in time order; empty = no corner could be tracked (the caller skips
                                        // blur below render.blur.min_motion_px)
  AffineFitKind worst_fit = AffineFitKind::Full;  // the weakest fit any sample's warp needed
};

// The box corners' pixel positions (any fixed number of them, in the same order each call) at
// exposure fraction t in [0, 1]; nullopt for a corner the camera cannot see at t.
using CornerTrack = std::function<std::vector<std::optional<Vec2>>(double t)>;

// Plans the blur from the corners' motion. Sample count: n = min(round(D), 48) + 2 (the thesis's
// interframes plus its two intraframes), at least kIntraframeWarpMinSamples; `fixed_samples` > 0 overrides it
// (clamped to [kIntraframeWarpMinSamples, 50]). Times: the midpoints (i + 0.5)/n of n equal slices of the
// exposure, so the samples stand for the whole shutter interval like a box filter (the thesis puts
// them at i/n and adds the current pose twice). Corners seen at both ends of a warp are used; fewer
// than one such corner gives an empty plan. D counts corners seen at t = 0 and t = 1, each path
// followed in 8 pieces.
IntraframeWarpPlan plan_intraframe_warp_blur(const CornerTrack& corners_at, int fixed_samples = 0);

}  // namespace arpipe
