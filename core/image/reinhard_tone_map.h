// Reinhard's global photographic tone mapping (seed 002, after Reinhard et al. 2002) for writing an
// HDR image as a displayable one: key / log-average luminance, then x / (1 + x).
#pragma once

#include "core/image/hdr_image.h"

namespace arpipe {

struct ReinhardSettings {
  double key = 0.72;      // the seed's middle grey (its shader's value; Reinhard's paper uses 0.18)
  double delta = 1e-4;    // keeps log() finite on black pixels
  bool per_channel = false;  // the seed's shader maps each channel; false maps luminance and keeps hue
};

// Rec. 709 luminance with the seed's weights (0.2125, 0.7154, 0.0721).
double reinhard_luminance(const Vec3& rgb);
// exp(mean(log(delta + L))) over the image: the "scene key" L-bar.
double log_average_luminance(const HdrImage& image, double delta = 1e-4);
// Maps in place to [0, 1) linear values (encode to sRGB afterwards for an 8-bit file). log_average
// <= 0 takes it from the image itself.
void reinhard_tone_map(HdrImage& image, const ReinhardSettings& settings = {}, double log_average = 0);

// The seed's adaptive luminance: L <- L + (L_new - L) (1 - 0.98^(60 dt)), easing L-bar across frames
// so a video does not pump when the scene's key jumps. The first update takes L_new as it is.
class AdaptiveLuminance {
 public:
  double update(double log_average_now, double dt_s);
  double value() const { return value_; }

 private:
  double value_ = 0;
  bool started_ = false;
};

}  // namespace arpipe
