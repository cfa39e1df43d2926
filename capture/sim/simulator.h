// `arpipe simulate`: renders a scene into a format-v1 recording with its ground truth, plus the
// ground-truth composite and the virtual objects' coverage when the scene has virtual objects
// (docs/SIMULATOR.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "capture/sim/sim_scene.h"

namespace arpipe::sim {

// The largest simulated frame: rendering holds about 80 bytes a pixel (radiance, linear image,
// exposed frames), so 2^24 pixels (4096 x 4096, or 5472 x 3072) is about 1.3 GB.
inline constexpr int64_t kMaxFrameSide = 8192;
inline constexpr int64_t kMaxFramePixels = int64_t{1} << 24;

// The ground-truth composite's recording, inside the output directory; beside it the coverage of
// the virtual objects, kGroundTruthCoverageDir (capture/sim/ground_truth_coverage.h).
inline constexpr const char* kGroundTruthCompositeDir = "ground_truth_composite";
// The scene file as simulated, copied into the output directory.
inline constexpr const char* kSceneCopyFile = "scene.toml";

struct SimulateOptions {
  std::filesystem::path out_dir;   // must not hold a recording
  int frames = 0;                  // 0: the scene's render.frames
  std::optional<uint64_t> seed;    // default: the scene's render.seed
  int threads = 0;                 // 0: one per core
  std::string source_description;  // recording.json "source"; default: "arpipe simulate <scene>"
  // Called after each frame is written: (frames done, frames in all).
  std::function<void(int, int)> on_frame;
};

struct SimulateSummary {
  int frames = 0;
  double seconds = 0;          // wall time in all
  // Of which loading assets, building the Embree scenes and the ray grid (a scene with moving
  // objects builds its scenes again for each frame after the first: not counted here).
  double setup_seconds = 0;
  bool wrote_composite = false;  // and the coverage beside it
};

// Objects with a pose track (SimObject::keyframes) stand, in each frame, where object_pose_at puts
// them at that frame's exposure start (trajectory time): frame k of a video at its fps at k / fps.
// Their motion within an exposure is not rendered (no motion blur of objects).
// Throws AssetError (a scene asset), RecordingError (writing), std::invalid_argument (options, or a
// frame over kMaxFrameSide / kMaxFramePixels).
// Frames written before an error stay readable.
SimulateSummary simulate(const SimScene& scene, const SimulateOptions& options);

}  // namespace arpipe::sim
