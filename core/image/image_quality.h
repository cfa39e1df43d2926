// Image error measures over a region of interest (a mask), for benchmarks that compare a rendered
// picture with a reference: PSNR on 8-bit RGB and SSIM (Wang, Bovik, Sheikh and Simoncelli 2004)
// on luma, both restricted to the pixels that matter (e.g. the virtual object's footprint).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace arpipe {

// Interleaved 8-bit RGB, tightly packed rows.
struct RgbView {
  std::span<const uint8_t> data;
  int width = 0;
  int height = 0;
};

// 10 log10(255^2 / MSE) over the masked pixels and all three channels; +infinity when they are
// identical there, NaN when the mask is empty. Throws std::invalid_argument on mismatched sizes.
double masked_psnr(const RgbView& a, const RgbView& b, std::span<const uint8_t> mask);

// Mean SSIM of the luma (BT.601 weights) over the windows centred on masked pixels: an 11x11
// Gaussian window of sigma 1.5, C1 = (0.01 x 255)^2, C2 = (0.03 x 255)^2 as in the paper; the
// window is cut at the image border. 1 when identical; NaN when the mask is empty.
double masked_ssim(const RgbView& a, const RgbView& b, std::span<const uint8_t> mask);

// The mask grown by `radius` pixels (square neighbourhood).
std::vector<uint8_t> dilate_mask(std::span<const uint8_t> mask, int width, int height, int radius);

}  // namespace arpipe
