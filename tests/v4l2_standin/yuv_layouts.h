// The YUV layouts the stand-in derives by reordering bytes, not by converting colour: UYVY and YVYU
// and NV16 from YUYV (4:2:2), NV21 and YU12 (I420) from NV12 (4:2:0). Tight strides throughout.
#pragma once

#include <cstddef>
#include <cstdint>

namespace arpipe::standin {

enum class DerivedLayout { Uyvy, Yvyu, Nv16, Nv21, Yu12 };

// Whether a layout is made from YUYV (else from NV12).
bool derived_from_yuyv(DerivedLayout layout);
// Bytes of a width x height image in the layout (width even; height even for the 4:2:0 ones).
size_t derived_bytes(DerivedLayout layout, int width, int height);
// Writes the layout into dst (derived_bytes long) from the source image: YUYV rows of
// `src_stride` bytes, or NV12 (a Y plane then a UV plane, both rows of `src_stride` bytes).
void derive_layout(DerivedLayout layout, const uint8_t* src, size_t src_stride, int width, int height, uint8_t* dst);

}  // namespace arpipe::standin
