// Reinhard's global operator (see reinhard_tone_map.h).
#include "core/image/reinhard_tone_map.h"

#include <cmath>

namespace arpipe {

double reinhard_luminance(const Vec3& rgb) { return 0.2125 * rgb[0] + 0.7154 * rgb[1] + 0.0721 * rgb[2]; }

double log_average_luminance(const HdrImage& image, double delta) {
  const size_t pixels = size_t(image.width) * size_t(image.height);
  if (pixels == 0) return 0;
  double sum = 0;
  for (size_t i = 0; i < pixels; ++i) {
    const Vec3 rgb{image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]};
    sum += std::log(delta + std::max(0.0, reinhard_luminance(rgb)));
  }
  return std::exp(sum / double(pixels));
}

void reinhard_tone_map(HdrImage& image, const ReinhardSettings& settings, double log_average) {
  if (log_average <= 0) log_average = log_average_luminance(image, settings.delta);
  const double scale = settings.key / (log_average + settings.delta);
  const size_t pixels = size_t(image.width) * size_t(image.height);
  for (size_t i = 0; i < pixels; ++i) {
    float* p = &image.rgb[3 * i];
    if (settings.per_channel) {
      for (size_t c = 0; c < 3; ++c) {
        const double x = scale * std::max(0.0f, p[c]);
        p[c] = static_cast<float>(x / (1 + x));
      }
      continue;
    }
    const double luminance = reinhard_luminance({p[0], p[1], p[2]});
    if (luminance <= 0) {
      p[0] = p[1] = p[2] = 0;
      continue;
    }
    const double x = scale * luminance;
    const double ratio = (x / (1 + x)) / luminance;
    for (size_t c = 0; c < 3; ++c) p[c] = static_cast<float>(std::min(1.0, std::max(0.0, ratio * p[c])));
  }
}

double AdaptiveLuminance::update(double log_average_now, double dt_s) {
  if (!started_) {
    value_ = log_average_now;
    started_ = true;
  } else {
    value_ += (log_average_now - value_) * (1 - std::pow(0.98, 60 * std::max(0.0, dt_s)));
  }
  return value_;
}

}  // namespace arpipe
