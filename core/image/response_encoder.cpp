#include "core/image/response_encoder.h"

namespace arpipe {

ResponseEncoder::ResponseEncoder(const CameraResponse& response) {
  begins_[0] = 0.0f;
  for (int k = 1; k < 256; ++k) begins_[size_t(k)] = static_cast<float>(response.decode((k - 0.5) / 255.0));
  // The bin's least value is i / kBins; its code is the last k whose beginning lies at or below it.
  int code = 0;
  for (int i = 0; i <= kBins; ++i) {
    const float least = static_cast<float>(i) / kBins;
    while (code < 255 && least >= begins_[size_t(code) + 1]) ++code;
    bin_start_[size_t(i)] = static_cast<uint8_t>(code);
  }
}

}  // namespace arpipe
