// A camera that sends JPEG (MJPEG webcams, phones): the simulated frame's 8-bit pixels encoded to
// JPEG and decoded back with libjpeg-turbo, so a recording holds JPEG's blocking and ringing while
// staying in its own pixel format.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace arpipe::sim {

// The JPEG encoding of width x height pixels rows bytes_per_line apart: channels 3 (packed RGB,
// 4:2:0 chroma subsampling, as camera MJPEG) or 1 (grey, a one-component JPEG), at quality
// 1..100, libjpeg-turbo's accurate integer DCT. Throws std::invalid_argument on bad arguments
// and std::runtime_error when libjpeg-turbo fails.
std::string jpeg_encode(const uint8_t* pixels, int width, int height, size_t bytes_per_line, int channels, int quality);

// Encodes the pixels as jpeg_encode does and decodes the JPEG back into them in place
// (libjpeg-turbo's accurate integer IDCT and its default, smooth chroma upsampling).
void jpeg_round_trip(uint8_t* pixels, int width, int height, size_t bytes_per_line, int channels, int quality);

}  // namespace arpipe::sim
