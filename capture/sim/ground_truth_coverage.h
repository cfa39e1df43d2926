// The ground-truth coverage of a simulated capture's virtual objects: per frame and pixel, the
// fraction of the pixel's samples (over its area and its row's exposure window: the samples the
// ground-truth composite is rendered from) whose first hit is a virtual object. Real objects in
// front hide a virtual object, so this is its visible coverage: what an occlusion-correct
// composite's virtual-layer alpha should be. Written by simulate() as the recording
// `ground_truth_coverage/` (GREY, 8 bits: round(coverage x 255)) beside the composite; read back
// here (docs/SIMULATOR.md "Output", docs/FORMATS.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/frame.h"

namespace arpipe::sim {

// The coverage recording, inside a capture's output directory.
inline constexpr const char* kGroundTruthCoverageDir = "ground_truth_coverage";

// round(coverage x 255), coverage clamped to [0, 1]; and back (byte / 255).
uint8_t coverage_to_byte(double coverage);
float coverage_from_byte(uint8_t byte);

// A coverage image: width x height values in [0, 1], row-major; 8-bit steps (1/255).
struct CoverageImage {
  int width = 0;
  int height = 0;
  std::vector<float> coverage;
  float at(int x, int y) const { return coverage[size_t(y) * size_t(width) + size_t(x)]; }
};

// The GREY frame simulate() appends for a coverage image (coverage: width x height, row-major).
Frame coverage_frame(const std::vector<float>& coverage, int width, int height, const FrameMetadata& meta);

// capture_dir: the directory `arpipe simulate --out` wrote (the one holding
// ground_truth_coverage/). The number of coverage frames (one per camera frame), and frame
// `index` of them. Throw RecordingError (naming the directory) when there is no coverage
// recording, it is not GREY, the index is out of range or the frame cannot be read.
size_t coverage_frame_count(const std::filesystem::path& capture_dir);
CoverageImage read_coverage_frame(const std::filesystem::path& capture_dir, size_t index);

}  // namespace arpipe::sim
