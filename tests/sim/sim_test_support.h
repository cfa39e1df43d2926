// Shared by the simulator's end-to-end tests: scratch directories, small scenes built in code
// (independent of the scene-file loader) and reading images back.
#pragma once

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "capture/sim/sim_scene.h"
#include "capture/sim/sim_scene_loader.h"

namespace arpipe::sim::test {

namespace fs = std::filesystem;

inline std::vector<uint8_t> file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The SceneError a scene text (as "scene.toml") gives; a test failure when it gives none.
inline std::string error_of(const std::string& text) {
  try {
    parse_sim_scene(text, "scene.toml", {});
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for:\n" << text;
  return "";
}

inline fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("arpipe-sim-test-{}-{}", getpid(), name);
  fs::remove_all(dir);
  return dir;
}

// A noise-free, linear-response camera with a pinhole lens; renders in RGB24.
inline SimCamera exact_camera(int width, int height, double focal_px) {
  SimCamera camera;
  camera.model = CameraModel::pinhole(focal_px, focal_px, (width - 1) / 2.0, (height - 1) / 2.0, width, height);
  camera.pixel_format = PixelFormat::RGB24;
  camera.sensor.noise = false;
  camera.sensor.response = CameraResponse::linear();
  return camera;
}

// A still camera at `position` looking at `look_at`, image up along world +y unless given.
inline SimTrajectory still(const Vec3& position, const Vec3& look_at, const Vec3& up = {0, 1, 0}) {
  SimTrajectory trajectory;
  trajectory.kind = SimTrajectory::Kind::Keyframes;
  trajectory.keyframes.push_back({0.0, position, look_at, up, 0.0});
  return trajectory;
}

// A plane on the world xy plane (face up, +z), centred at the origin.
inline SimObject ground_plane(const std::string& name, double width_m, double height_m, const SimTexture& texture = {}) {
  SimObject plane;
  plane.name = name;
  plane.shape = SimObject::Shape::Plane;
  plane.width_m = width_m;
  plane.height_m = height_m;
  plane.material.texture = texture;
  return plane;
}

// One overhead directional light of irradiance E and zero angular diameter, and no sky.
inline SimLight overhead_sun(double irradiance) {
  SimLight light;
  light.name = "overhead";
  light.kind = SimLight::Kind::Directional;
  light.direction_to_light = {0, 0, 1};
  light.irradiance = irradiance;
  return light;
}

// An 8 x 4 HDR sky with a distinct colour per pixel; returns the pixels as the file holds them
// (RGBE rounds them), RGB, row-major.
inline std::vector<Rgb> write_test_sky(const fs::path& path) {
  cv::Mat sky(4, 8, CV_32FC3);
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 8; ++col)
      sky.at<cv::Vec3f>(row, col) = {float(0.25 + col), float(1 + 2 * row), float(0.5 + row * col)};
  EXPECT_TRUE(cv::imwrite(path.string(), sky));
  const cv::Mat back = cv::imread(path.string(), cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR);
  std::vector<Rgb> pixels;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 8; ++col) {
      const cv::Vec3f bgr = back.at<cv::Vec3f>(row, col);
      pixels.push_back({bgr[2], bgr[1], bgr[0]});
    }
  return pixels;
}

// Reads a float RGB PFM written by the simulator (linear image), as OpenCV BGR.
inline cv::Mat read_linear(const fs::path& path) { return cv::imread(path.string(), cv::IMREAD_UNCHANGED); }

}  // namespace arpipe::sim::test
