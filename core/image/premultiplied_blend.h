// The composite's arithmetic on the CPU: a premultiplied linear layer over an 8-bit picture,
// out = encode(L.rgb + (1 - L.a) * decode(picture)), in place, inside a rectangle.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/image/camera_response.h"
#include "core/image/pixel_rect.h"
#include "core/image/response_encoder.h"

namespace arpipe {

// layer_rgba: rect.width * rect.height RGBA floats, row r being image row rect.y + r. rgb: the
// picture's RGB24 rows, bytes_per_line apart, holding rect. decode and encode are the camera's
// response both ways.
void blend_premultiplied_over(const float* layer_rgba, const PixelRect& rect, const CameraResponse& decode,
                              const ResponseEncoder& encode, uint8_t* rgb, size_t bytes_per_line);

}  // namespace arpipe
