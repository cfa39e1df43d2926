// A recording made again in another pixel format, for tests and benchmarks that need a camera
// sending a format no capture was simulated in (a raw Bayer sensor, GREY, NV12).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "core/pixel_format.h"

namespace arpipe {

// Writes the first `frames` frames of the recording at `from` (all when it has fewer) as a new
// recording at `to` in `format`, through RGB24 (core/image/pixel_convert.h: a Bayer format gets each
// pixel's filter channel of its linear value), with their metadata, the camera model and the
// ground truth when `from` has it. `source` is the new recording's description.
void copy_recording_as(const std::filesystem::path& from, const std::filesystem::path& to, PixelFormat format,
                       size_t frames, const std::string& source);

}  // namespace arpipe
