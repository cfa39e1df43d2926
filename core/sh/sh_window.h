// Windowing (ringing reduction) of SH coefficients: band l scaled by a factor h_l that falls from
// 1 at l = 0, so the negative lobes opposite small bright sources shrink (Sloan 2008).
#pragma once

#include <optional>
#include <string_view>

#include "core/config/choice_names.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

enum class ShWindow { None, Hanning, Lanczos };
inline constexpr ChoiceName<ShWindow> kShWindowNames[] = {
    {"none", ShWindow::None}, {"hanning", ShWindow::Hanning}, {"lanczos", ShWindow::Lanczos}};

// The window's name in kShWindowNames; parse returns nullopt for a name not in it.
inline std::string_view sh_window_name(ShWindow window) { return choice_name<ShWindow>(kShWindowNames, window); }
inline std::optional<ShWindow> parse_sh_window(std::string_view name) {
  return choice_value<ShWindow>(kShWindowNames, name);
}

// h_l for a vector of `bands` bands, with the window width w = bands (so the window's first zero
// is at l = bands, one past the highest band used: no used band is zeroed):
//   None: 1;  Hanning: (1 + cos(pi l / w)) / 2;  Lanczos: sinc(pi l / w) = sin(x) / x (1 at l = 0).
// 0 for l outside [0, bands).
double sh_window_factor(ShWindow window, int l, int bands);
// Scales every band of `sh` by sh_window_factor(window, l, sh.bands).
void apply_sh_window(ShRgb& sh, ShWindow window);

}  // namespace arpipe
