// A simulated recording's frames as the files other tools read: a 360° H.264 MP4 with the
// spherical metadata of its layout (what source.panorama.file reads as a video), or one PNG a
// frame (a LENSMODEL_LONLAT camera's frame is a panorama still). Used by `arpipe simulate --video
// / --png` and `arpipe bench hybrid`.
#pragma once

#include <filesystem>

#include "capture/sim/sim_scene.h"

namespace arpipe::sim {

// The recording in `dir` as `file`, at the camera's frame rate, mono or its [camera.stereo]
// packing. Throws std::runtime_error naming the file on a failure.
void write_recording_as_video(const std::filesystem::path& dir, const std::filesystem::path& file,
                              const SimCamera& camera);

// Each frame of the recording in `dir` as dir/frame_NNNNNN.png (8-bit RGB), named as the PNG sink
// names them. Throws std::runtime_error naming the file on a failure.
void write_recording_as_pngs(const std::filesystem::path& dir);

}  // namespace arpipe::sim
