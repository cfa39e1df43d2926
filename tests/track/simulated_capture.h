// Test helpers for the track tests: a scene from configs/sim simulated into a scratch directory
// under the build tree (at a chosen sample count and frame count), removed afterwards; and the two
// pose errors the simulator comparisons report.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/geometry/se3.h"

namespace arpipe::test {

// The rotation between two camera poses, in degrees, and the distance between their camera centres,
// in mm.
inline double angle_deg(const SE3& a, const SE3& b) { return rotation_angle_between(a, b) * 180.0 / std::numbers::pi; }
inline double centre_mm(const SE3& a, const SE3& b) {
  return 1e3 * norm(a.inverse().translation() - b.inverse().translation());
}

class SimulatedCapture {
 public:
  // frames = 0: the scene's own frame count. `scratch` names the folder under test-scratch/.
  SimulatedCapture(const std::string& scene_file, int samples_per_pixel, int frames = 0,
                   const std::string& scratch = "motion")
      : dir_(std::filesystem::path(ARPIPE_BINARY_DIR) / "test-scratch" / scratch /
             fmt::format("{}-{}", std::filesystem::path(scene_file).stem().string(), getpid())) {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_.parent_path());
    scene_ = sim::load_sim_scene(std::filesystem::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / scene_file);
    scene_.render.samples_per_pixel = samples_per_pixel;
    sim::SimulateOptions options;
    options.out_dir = dir_;
    options.frames = frames;
    sim::simulate(scene_, options);
  }
  ~SimulatedCapture() { std::filesystem::remove_all(dir_); }
  SimulatedCapture(const SimulatedCapture&) = delete;
  SimulatedCapture& operator=(const SimulatedCapture&) = delete;
  const std::filesystem::path& dir() const { return dir_; }
  const sim::SimScene& scene() const { return scene_; }

 private:
  std::filesystem::path dir_;
  sim::SimScene scene_;
};

}  // namespace arpipe::test
