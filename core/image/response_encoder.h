// Linear light back to a camera's 8-bit values through its response (light.response), rounded
// to the nearest code as a GPU's float-to-8-bit conversion of the encoded value rounds it.
#pragma once

#include <array>
#include <cstdint>

#include "core/image/camera_response.h"

namespace arpipe {

class ResponseEncoder {
 public:
  explicit ResponseEncoder(const CameraResponse& response = CameraResponse::srgb());

  // round(255 * encode(clamp(linear, 0, 1))); NaN gives 0. The code is found from the linear values
  // at which each code begins (decode((k - 0.5) / 255)), so it is exact to the response's own decode,
  // not to a table's spacing.
  uint8_t encode(float linear) const {
    if (!(linear > 0.0f)) return 0;
    if (linear >= 1.0f) return 255;
    int code = bin_start_[static_cast<size_t>(linear * kBins)];
    while (code < 255 && linear >= begins_[static_cast<size_t>(code) + 1]) ++code;
    return static_cast<uint8_t>(code);
  }

 private:
  static constexpr int kBins = 4096;
  std::array<float, 256> begins_{};  // begins_[k]: the least linear value that encodes to k (k >= 1)
  std::array<uint8_t, kBins + 1> bin_start_{};  // the code of each bin's least value
};

}  // namespace arpipe
