// The preview page served at "/": one self-contained HTML file (no external assets) that shows
// the live MJPEG stream and, beside it, the latest frame's state from /state, updated live.
#pragma once

#include <string_view>

namespace arpipe {

std::string_view preview_page_html();

}  // namespace arpipe
