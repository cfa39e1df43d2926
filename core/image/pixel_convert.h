// Conversions from any supported pixel format to the two that the pipeline works in:
// 8-bit grey (tracking) and packed RGB24 (rendering, sinks), and RGB24 to the YUV formats (sinks).
#pragma once

#include <cstdint>
#include <vector>

#include "core/frame.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

// Writes width*height bytes of luma (no stride) into out: the Y plane as it is for YUV formats
// (limited range, 16..235), full-range BT.601 luma for RGB24 and GREY (0..255), and for Bayer
// formats the full-range luma of their RGB24 (below).
void to_grey(const Frame& frame, std::vector<uint8_t>& out);
// The same for the pixels of `rect` alone (clipped to the frame), at their places in out, which
// is sized width*height (its other bytes keep what they held).
void to_grey(const Frame& frame, const PixelRect& rect, std::vector<uint8_t>& out);
// Writes width*height*3 bytes of RGB (no stride) into out. BT.601 limited range for YUV formats;
// GREY is full range (R = G = B = the grey value). Bayer formats are developed by
// core/image/bayer.h as their meta.raw says (core/raw_colour.h: black level, gains, colour matrix;
// grey-world gains when it has none) and sRGB-encoded.
void to_rgb24(const Frame& frame, std::vector<uint8_t>& out);
// Converts a packed RGB24 image (no stride) to the given format, into a new Frame (metadata left
// default but for a Bayer format's meta.raw). A Bayer format gets each pixel's CFA channel,
// sRGB-decoded to linear at the format's depth, with black level 0 and unit gains in meta.raw:
// to_rgb24 gives a flat region back exactly.
Frame from_rgb24(const uint8_t* rgb, int width, int height, PixelFormat format);
// Planar 4:2:0 (I420, as Y4M wants it) from packed RGB24 whose rows are rgb_width pixels long:
// the top-left width x height pixels (both even) become a Y plane, a U plane and a V plane.
void rgb24_to_i420(const uint8_t* rgb, int rgb_width, int width, int height, std::vector<uint8_t>& out);
// Packed YUYV 4:2:2 (BT.601 limited range, as every YUV conversion here; the same bytes as
// from_rgb24(..., YUYV)) from RGB24 rows rgb_bytes_per_line apart: the top-left width x height
// pixels (width even) become rows out_bytes_per_line apart in out. Each pair's chroma is the mean of its two pixels.
void rgb24_to_yuyv(const uint8_t* rgb, size_t rgb_bytes_per_line, int width, int height, uint8_t* out,
                   size_t out_bytes_per_line);

}  // namespace arpipe
