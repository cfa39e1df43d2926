// Shared by the board-detection and image-set tests: the calib-board capture and its truth,
// scenes simulated from text into scratch directories, and corner errors against the truth.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"
#include "calib/calibration_images.h"
#include "capture/recording/recording_reader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"

namespace arpipe::calib::test {

namespace fs = std::filesystem;

// Simulated at build time from configs/sim/calib-board.toml (tests/CMakeLists.txt, calib_capture).
inline fs::path calib_capture() { return fs::path(ARPIPE_BINARY_DIR) / "calib-capture"; }

// The calib-board scene's inner corners in the world: x = -0.12 + 0.02 i (i = 0..12),
// y = 0.08 - 0.02 j (j = 0..8), z = 0, in board-point order (row j, column i).
inline std::vector<Vec3> calib_capture_corners() {
  std::vector<Vec3> out;
  for (int j = 0; j < 9; ++j)
    for (int i = 0; i < 13; ++i) out.push_back({-0.12 + 0.02 * i, 0.08 - 0.02 * j, 0.0});
  return out;
}

// The calib scenes' surroundings in scene-file text: a table under the board, the key light and
// the sky, as configs/sim/calib-board.toml has them.
inline constexpr const char* kTableLightAndSky = R"(
[[object]]
name = "table"
position = [0.0, 0.0, -0.0005]
width_m = 2.0
height_m = 2.0
albedo = [0.35, 0.30, 0.25]

[[light]]
direction = [0.3, -0.4, 1.0]
irradiance = 4.0

[environment]
radiance = [0.30, 0.30, 0.33]
)";

// An empty scratch directory for one test, in the build tree.
inline fs::path scratch_dir(const std::string& name) {
  const fs::path dir =
      fs::path(ARPIPE_BINARY_DIR) / "test-scratch" / "calib" / ("pid-" + std::to_string(getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Removes a scratch directory, and this process's scratch root once it is empty.
inline void remove_scratch(const fs::path& dir) {
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::remove(dir.parent_path(), ec);  // fails, harmlessly, while other tests' directories remain
}

// Renders a scene given as scene-file text (docs/SIMULATOR.md) into dir/recording.
inline fs::path simulate_text(const std::string& scene_text, const fs::path& dir) {
  const sim::SimScene scene = sim::parse_sim_scene(scene_text, (dir / "scene.toml").string(), dir);
  sim::SimulateOptions options;
  options.out_dir = dir / "recording";
  options.threads = 2;
  sim::simulate(scene, options);
  return options.out_dir;
}

// Where the true points land in frame `index` of a simulated recording: world points through the
// exposure-middle pose and the recording's camera model.
inline std::vector<Vec2> true_pixels(const RecordingReader& reader, size_t index, const std::vector<Vec3>& world) {
  const SE3& T_cam_world = reader.ground_truth().at(index).T_cam_world_mid;
  std::vector<Vec2> out;
  for (const Vec3& p : world) {
    const auto pixel = reader.camera_model().project(T_cam_world * p);
    out.push_back(pixel ? *pixel : Vec2{NAN, NAN});
  }
  return out;
}

// The same grid read backwards (a 180-degree turn of the board).
inline std::vector<Vec2> turned(const std::vector<Vec2>& points) { return {points.rbegin(), points.rend()}; }

// The detector's promised order (calib/board_detector.cpp, canonical_order): the board seen from
// its printed side, rows running left to right in the image. The truth grid is given row by row
// with x along a row, so it is that order itself or, when its rows run right to left, turned.
inline std::vector<Vec2> in_detector_order(const std::vector<Vec2>& truth, int cols) {
  double dx = 0;
  for (size_t i = 0; i + 1 < truth.size(); ++i)
    if ((i + 1) % cols != 0) dx += truth[i + 1][0] - truth[i][0];
  return dx >= 0 ? truth : turned(truth);
}

// The message parse_board throws for `text` (named "b.toml"), or "" when it parses.
inline std::string board_error_of(const std::string& text) {
  try {
    parse_board(text, "b.toml");
  } catch (const BoardError& e) {
    return e.what();
  }
  return "";
}

struct CornerErrors {
  double rms_px = 0;  // per point: sqrt(mean |detected - true|^2) over the seen points
  double max_px = 0;
  int seen = 0;
};

inline CornerErrors corner_errors(const BoardObservation& observed, const std::vector<Vec2>& truth) {
  CornerErrors out;
  double sum2 = 0;
  for (size_t i = 0; i < truth.size() && i < observed.pixels.size(); ++i) {
    if (observed.weights[i] <= 0) continue;
    const double e = std::hypot(observed.pixels[i][0] - truth[i][0], observed.pixels[i][1] - truth[i][1]);
    sum2 += e * e;
    out.max_px = std::max(out.max_px, e);
    ++out.seen;
  }
  out.rms_px = out.seen > 0 ? std::sqrt(sum2 / out.seen) : 0;
  return out;
}

// Accumulates errors over several frames.
struct ErrorTally {
  double sum2 = 0;
  double max_px = 0;
  int points = 0;
  void add(const CornerErrors& e) {
    sum2 += e.rms_px * e.rms_px * e.seen;
    max_px = std::max(max_px, e.max_px);
    points += e.seen;
  }
  double rms_px() const { return points > 0 ? std::sqrt(sum2 / points) : 0; }
};

}  // namespace arpipe::calib::test
