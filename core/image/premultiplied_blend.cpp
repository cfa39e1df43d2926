#include "core/image/premultiplied_blend.h"

namespace arpipe {

void blend_premultiplied_over(const float* layer_rgba, const PixelRect& rect, const CameraResponse& decode,
                              const ResponseEncoder& encode, uint8_t* rgb, size_t bytes_per_line) {
  for (int row = 0; row < rect.height; ++row) {
    const float* layer = layer_rgba + size_t(row) * size_t(rect.width) * 4;
    uint8_t* out = rgb + size_t(rect.y + row) * bytes_per_line + size_t(rect.x) * 3;
    for (int column = 0; column < rect.width; ++column, layer += 4, out += 3) {
      const float alpha = layer[3];
      // Untouched pixels (nothing drawn, no shadow) keep their bytes: the round trip is exact anyway.
      if (alpha == 0.0f && layer[0] == 0.0f && layer[1] == 0.0f && layer[2] == 0.0f) continue;
      const float behind = 1.0f - alpha;
      for (int c = 0; c < 3; ++c) out[c] = encode.encode(layer[c] + behind * decode.decode8(out[c]));
    }
  }
}

}  // namespace arpipe
