// The picture the live outputs show while the camera is away: grey, with a line that says so,
// so a viewer never mistakes a frozen last frame for a live one.
#pragma once

#include <string_view>

#include "core/frame.h"

namespace arpipe {

// RGB24, width x height (each clamped to [64, 8192]), the text centred.
Frame placeholder_frame(int width, int height, std::string_view text);

}  // namespace arpipe
