// Helpers shared by the capture tests: scratch directories under the build tree, small synthetic
// frames and recordings, and file surgery for the damage tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "capture/recording/recording_format.h"
#include "capture/recording/recording_writer.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"

namespace arpipe::test {

namespace fs = std::filesystem;

// This process's scratch root in the build tree (large data stays out of the source tree); it is
// removed when the tests end (capture_test_support.cpp) unless ARPIPE_KEEP_SCRATCH is set.
inline fs::path scratch_root() {
  return fs::path(ARPIPE_BINARY_DIR) / "test-scratch" / "capture" / ("pid-" + std::to_string(getpid()));
}

// An empty scratch directory for one test.
inline fs::path scratch_dir(const std::string& name) {
  const fs::path dir = scratch_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline CameraModel small_camera(int width, int height) {
  return CameraModel::pinhole(0.8 * width, 0.8 * width, (width - 1) / 2.0, (height - 1) / 2.0, width, height);
}

// A frame of random bytes with recognisable metadata (every field differs from its default).
inline Frame random_frame(PixelFormat format, int width, int height, size_t bytes_per_line, uint64_t index) {
  Frame f;
  f.format = format;
  f.width = width;
  f.height = height;
  f.bytes_per_line = bytes_per_line;
  f.data.resize(image_bytes(format, width, height, bytes_per_line));
  std::mt19937_64 random(index + 17);
  for (auto& b : f.data) b = uint8_t(random());
  f.meta.sequence = 100 + index * 2;  // with gaps, as a real camera that dropped frames
  f.meta.exposure_start_ns = 5'000'000'000 + int64_t(index) * 33'366'700 + 11;
  f.meta.exposure_ns = 8'000'000 + int64_t(index);
  f.meta.readout_ns = 12'345'678;
  f.meta.frame_duration_ns = 33'366'700;
  f.meta.analogue_gain = 1.5 + 0.25 * double(index);
  f.meta.digital_gain = 1.0 / 3.0;
  f.meta.raw_timestamp_ns = f.meta.exposure_start_ns + 20'000'000;
  f.meta.raw_timestamp_meaning = TimestampMeaning::EndOfFrame;
  f.meta.timestamp_offset_ns = -1'234;
  // Every other frame says what the camera measured (libcamera's Lux and ColourTemperature).
  f.meta.lux = index % 2 ? 0.0 : 312.5 + double(index);
  f.meta.colour_temperature_k = index % 2 ? 0.0 : 4650.0;
  // Every third frame says how its raw values develop, in values no float round trip could keep
  // by accident (core/raw_colour.h).
  if (index % 3 == 0) {
    f.meta.raw.black_level = std::array<double, 4>{64.25, 63.5, 65, 64.125 + double(index)};
    f.meta.raw.white_level = 1000.5;
    f.meta.raw.gains = std::array<double, 3>{1.0 / 3.0, 1, 2.7182818284590451};
    f.meta.raw.colour_matrix = std::array<double, 9>{1.5, -0.25, -0.25, -0.1, 1.2, -0.1, 1e-17, -0.5, 1.5};
  }
  return f;
}

inline GroundTruthFrame truth_for(const Frame& f, uint64_t index) {
  const double k = double(index);
  GroundTruthFrame truth;
  truth.sequence = f.meta.sequence;
  truth.T_cam_world_start = SE3::from_rt({0.1 + 0.01 * k, -0.2, 0.3}, {0.01 * k, 0.02, 0.5});
  truth.T_cam_world_mid = SE3::from_rt({0.1 + 0.011 * k, -0.2, 0.3}, {0.011 * k, 0.02, 0.5});
  truth.T_cam_world_end = SE3::from_rt({0.1 + 0.012 * k, -0.2, 0.3}, {0.012 * k, 0.02, 0.5});
  return truth;
}

// Writes a recording of `count` random frames (with ground truth when asked) and returns its info.
inline RecordingInfo write_recording(const fs::path& dir, PixelFormat format, int width, int height, int count,
                                     bool with_truth = true, size_t bytes_per_line = 0) {
  RecordingInfo info;
  info.pixel_format = format;
  info.width = width;
  info.height = height;
  info.bytes_per_line = bytes_per_line;
  info.source = "unit test";
  RecordingWriter writer(dir, info, small_camera(width, height));
  for (int i = 0; i < count; ++i) {
    Frame f = random_frame(format, width, height, writer.info().bytes_per_line, uint64_t(i));
    if (with_truth)
      writer.append(f, truth_for(f, uint64_t(i)));
    else
      writer.append(f);
  }
  writer.flush();
  return writer.info();
}

inline std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// Runs fn, which must throw E; returns what() (empty, with a test failure, when it did not throw).
template <typename E = RecordingError>
std::string error_message(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception";
  return {};
}

}  // namespace arpipe::test
