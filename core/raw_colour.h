// How a raw Bayer frame's values become light: its black level, white level, white-balance gains
// and colour matrix, carried on the frame so that every stage develops it the same way
// (core/image/bayer.h). The camera fills in what it says (libcamera's SensorBlackLevels, ColourGains
// and ColourCorrectionMatrix; a recording's fields); [source.raw] overrides it
// (capture/raw_colour_source.h), which also measures grey-world gains when none are known, so a
// frame leaves the source with its gains decided.
#pragma once

#include <array>
#include <optional>

namespace arpipe {

struct RawColour {
  // Raw codes at the frame's bit depth, per CFA cell: R, Gr (green on red rows), Gb, B. Empty: 0.
  std::optional<std::array<double, 4>> black_level;
  // The raw code of full scale; 0: the top code of the bit depth.
  double white_level = 0;
  // Gains R, G, B applied after the black level. Empty: measured from the frame (grey world).
  std::optional<std::array<double, 3>> gains;
  // Row-major 3x3 from white-balanced camera RGB to linear output RGB (the sensor's CCM). Empty: none.
  std::optional<std::array<double, 9>> colour_matrix;

  bool operator==(const RawColour&) const = default;
};

}  // namespace arpipe
