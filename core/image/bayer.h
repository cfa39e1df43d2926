// Raw Bayer frames developed into scene-linear RGB: black level, white balance (given gains or a
// grey-world estimate), OpenCV's edge-aware demosaicing, an optional colour matrix; and sRGB RGB24.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/frame.h"
#include "core/image/bayer_mosaic.h"
#include "core/raw_colour.h"

namespace arpipe {

// How to turn a raw mosaic into linear RGB. The defaults suit a sensor whose raw values are
// already neutral (the simulator's): no black level, full scale at the top code, unit gains.
struct BayerDevelopment {
  // Per CFA cell position, in raw code values: R, Gr (green on the red rows), Gb, B.
  std::array<double, 4> black_level{0, 0, 0, 0};
  // The raw code of full scale; 0 means 2^bit_depth - 1.
  double white_level = 0;
  // Per-channel gains R, G, B applied after the black level; ignored when grey_world is set.
  std::array<double, 3> white_balance{1, 1, 1};
  // Estimate the gains from the frame instead (grey_world_gains).
  bool grey_world = false;
  // Row-major 3x3 from white-balanced camera RGB to output RGB (e.g. a sensor's CCM), when known.
  std::optional<std::array<double, 9>> colour_matrix;
};

// The development a frame's RawColour asks for: its black and white levels, its gains (grey world
// when it has none), its colour matrix.
BayerDevelopment bayer_development(const RawColour& raw);

// Why `raw` cannot develop a frame of `format` (a black level not below the white level, a gain
// that is not a positive finite number, a matrix entry that is not finite); empty when it can.
std::string raw_colour_problem(const RawColour& raw, PixelFormat format);

// One value a pixel, (raw - black) / (white - black): 0 is black, 1 is the white level. Not
// clipped, so read noise below black stays negative and its mean unbiased.
void normalise_bayer(const BayerMosaic& mosaic, const BayerDevelopment& development, std::vector<float>& out);

// Grey-world white balance: gains (R, G, B, with G = 1) that make the mean red, green and blue of
// the normalised mosaic equal. Robust to highlights: 2x2 cells with any sample at or above
// `clip_level` are left out (a clipped channel is not the scene's colour). Unit gains when
// nothing usable is left or a channel's mean is not positive.
std::array<double, 3> grey_world_gains(const std::vector<float>& normalised, int width, int height, BayerOrder order,
                                       double clip_level = 0.98);

// Demosaics a normalised mosaic after multiplying each channel by its gain, with OpenCV's
// edge-aware 16-bit demosaicing (COLOR_Bayer*2RGB_EA): packed float RGB, rows width*3 apart.
// Negative values become 0 and values above max(gains) are clipped (the 16-bit range holds 0
// .. max gain); a flat region of one colour comes back exactly that colour, within 1/65535.
void demosaic_bayer(const std::vector<float>& normalised, int width, int height, BayerOrder order,
                    const std::array<double, 3>& gains, std::vector<float>& rgb);

// rgb = matrix * rgb for every pixel of packed float RGB.
void apply_colour_matrix(const std::array<double, 9>& matrix, std::vector<float>& rgb);

// The whole chain: unpack, black level, white balance, demosaic, colour matrix. Scene-linear RGB
// normalised so the white level is 1 (before gains), packed, width*height*3 floats.
// Throws std::invalid_argument as unpack_bayer does, or for a white level not above the black level.
void develop_bayer(const Frame& frame, const BayerDevelopment& development, std::vector<float>& linear_rgb);

// develop_bayer, clipped to [0, 1] and sRGB-encoded into RGB24 (width*height*3 bytes, no stride).
void bayer_to_rgb24(const Frame& frame, const BayerDevelopment& development, std::vector<uint8_t>& out);

}  // namespace arpipe
