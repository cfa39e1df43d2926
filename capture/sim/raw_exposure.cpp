#include "capture/sim/raw_exposure.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/image/bayer_mosaic.h"

namespace arpipe::sim {

uint16_t raw_code(double linear_value, int bit_depth, int black_level) {
  const double top = double((1 << bit_depth) - 1);
  if (std::isnan(linear_value)) return uint16_t(black_level);
  const double code = double(black_level) + linear_value * (top - double(black_level));
  return uint16_t(std::lround(std::clamp(code, 0.0, top)));
}

Frame expose_bayer(const RadianceImage& radiance, const SensorModel& sensor, const SensorExposure& exposure,
                   uint64_t seed, uint64_t frame_index, PixelFormat format, int black_level) {
  const int bits = bayer_bit_depth(format);
  if (bits == 0)
    throw std::invalid_argument(fmt::format("expose_bayer: {} is not a Bayer format", pixel_format_name(format)));
  BayerMosaic mosaic{radiance.width, radiance.height, *bayer_order(format), bits, {}};
  mosaic.values.resize(size_t(radiance.width) * size_t(radiance.height));
  for (int y = 0; y < radiance.height; ++y)
    for (int x = 0; x < radiance.width; ++x) {
      const size_t p = size_t(y) * size_t(radiance.width) + size_t(x);
      SampleRng rng(seed, sample_stream(frame_index, p, SampleStream::SensorNoise));
      const double linear = sensor.noisy_value(radiance.rgb[p * 3 + size_t(mosaic.channel_at(x, y))], exposure, rng);
      mosaic.values[p] = raw_code(linear, bits, black_level);
    }
  return pack_bayer(mosaic, format);
}

}  // namespace arpipe::sim
