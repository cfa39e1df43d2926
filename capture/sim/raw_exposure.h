// The simulated sensor's raw output: a radiance image through the colour filter array, exposure,
// noise and gains, offset by the black level and quantised to a Bayer format's bit depth.
#pragma once

#include <cstdint>

#include "capture/sim/frame_renderer.h"
#include "capture/sim/sensor_model.h"
#include "core/frame.h"

namespace arpipe::sim {

// The raw code of a linear value (full scale 1.0): black + v * (2^bits - 1 - black), rounded and
// clamped to 0 .. 2^bits - 1 (noise below zero light stays below the black level, as on a real
// sensor; NaN is black). No response curve: raw values are linear.
uint16_t raw_code(double linear_value, int bit_depth, int black_level);

// Each pixel keeps only its CFA channel (from `format`'s order), drawn with that pixel's own noise
// stream exactly as the RGB path draws it, so noise-free frames are the linear image sampled.
// Metadata left default; `format` must be Bayer (std::invalid_argument otherwise).
Frame expose_bayer(const RadianceImage& radiance, const SensorModel& sensor, const SensorExposure& exposure,
                   uint64_t seed, uint64_t frame_index, PixelFormat format, int black_level);

}  // namespace arpipe::sim
