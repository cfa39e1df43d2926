// [source.raw]: how a raw Bayer camera's values become light (core/raw_colour.h). Each key either
// overrides what the camera says about its frames or, left at its default, keeps it; a raw camera
// that says nothing about white balance (a V4L2 sensor) gets grey-world gains measured per frame.
#pragma once

#include <vector>

#include "core/config/choice_names.h"
#include "core/config/config_rules.h"
#include "core/geometry/vec.h"

namespace arpipe {

// source.raw.white_balance. Auto: the camera's gains when it gives them (libcamera's ColourGains, a
// recording's), else grey world; grey-world: measured from each frame; fixed: source.raw.gains.
enum class WhiteBalanceMode { Auto, GreyWorld, Fixed };
inline constexpr ChoiceName<WhiteBalanceMode> kWhiteBalanceModeNames[] = {
    {"auto", WhiteBalanceMode::Auto}, {"grey-world", WhiteBalanceMode::GreyWorld}, {"fixed", WhiteBalanceMode::Fixed}};

struct RawColourConfig {
  std::vector<double> black_level;    // [] : the camera's (else 0); one code for all cells, or R, Gr, Gb, B
  double white_level = 0;             // 0: the camera's, else the top code of the bit depth
  WhiteBalanceMode white_balance = WhiteBalanceMode::Auto;
  Vec3 gains{1, 1, 1};                // white_balance = "fixed": R, G, B
  std::vector<double> colour_matrix;  // [] : the camera's (else none); 9 numbers, row-major

  bool operator==(const RawColourConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, RawColourConfig& s) {
  // 65535: the top code of the deepest format (16-bit); the frame's own depth is checked per frame.
  v.key("black_level", s.black_level, NumberCount{{0, 1, 4}, NumberRange::closed(0, 65535), "[], 1 or 4 raw codes"},
        "the code of no light: [] = the camera's (else 0); one for all cells, or R, Gr, Gb, B");
  v.key("white_level", s.white_level, NumberRange::closed(0, 65535),
        "the code of full scale; 0 = the camera's, else the top code of the bit depth");
  v.key("white_balance", s.white_balance, kWhiteBalanceModeNames,
        "auto: the camera's gains, else grey world per frame; fixed: gains");
  v.key("gains", s.gains, NumberRange::closed(1.0 / 64, 64), "white_balance = \"fixed\": R, G, B gains");
  v.key("colour_matrix", s.colour_matrix, NumberCount{{0, 9}, NumberRange::closed(-16, 16), "[] or 9 numbers"},
        "camera RGB to linear output RGB, row-major: [] = the camera's (else none)");
}

}  // namespace arpipe
