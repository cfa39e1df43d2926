// Test support for the V4L2 source: a small recording with known metadata, and the stand-in
// (tests/v4l2_standin, linked into this test) serving it as /dev/video-arpipe-test.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "core/geometry/camera_model.h"
#include "v4l2_standin.h"

namespace arpipe::test {

namespace fs = std::filesystem;

inline constexpr const char* kStandinDevice = "/dev/video-arpipe-test";

inline fs::path v4l2_scratch(const std::string& name) {
  const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test-scratch" / "v4l2" / ("pid-" + std::to_string(getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A YUYV 64x48 recording of `frames` frames at 30 fps whose exposure and gains change like an
// auto-exposure's (1.0, 1.0, 2.5, 2.5, 7.0, ... ms; all whole 100 µs units, the V4L2 control's
// resolution), a 5 ms rolling-shutter readout, and a different picture per frame.
inline fs::path write_auto_exposure_recording(const fs::path& dir, int frames) {
  RecordingInfo info;
  info.pixel_format = PixelFormat::YUYV;
  info.width = 64;
  info.height = 48;
  info.source = "tests/v4l2 synthetic auto-exposure recording";
  const auto model = CameraModel::pinhole(60, 60, 31.5, 23.5, 64, 48);
  RecordingWriter writer(dir, info, model);
  const int64_t exposures_us[] = {1000, 1000, 2500, 2500, 7000, 7000, 7000, 3300, 1200, 1200};
  const double gains[] = {1.0, 1.0, 1.0, 2.0, 2.0, 4.0, 4.0, 1.5, 1.0, 1.0};
  for (int i = 0; i < frames; ++i) {
    Frame frame = Frame::allocate(PixelFormat::YUYV, 64, 48);
    for (size_t b = 0; b < frame.data.size(); ++b) frame.data[b] = uint8_t((b * 7 + size_t(i) * 31) % 220 + 16);
    FrameMetadata& m = frame.meta;
    m.sequence = uint64_t(i);
    m.exposure_ns = exposures_us[i % 10] * 1000;
    m.readout_ns = 5'000'000;
    m.frame_duration_ns = 33'333'333;
    m.exposure_start_ns = 2'000'000'000 + int64_t(i) * 33'333'333;
    m.analogue_gain = gains[i % 10];
    m.digital_gain = i % 10 == 6 ? 1.25 : 1.0;
    m.raw_timestamp_ns = m.exposure_start_ns;
    writer.append(frame);
  }
  writer.flush();
  return dir;
}

// Loads a stand-in config serving `recording` as kStandinDevice; `extra` is appended inside the
// [[device]] table (keys, then [[device.fault]] tables). Unloads when destroyed.
class StandinDevice {
 public:
  StandinDevice(const fs::path& dir, const fs::path& recording, const std::string& extra) {
    const fs::path config = dir / "standin.toml";
    std::ofstream(config) << "[[device]]\npath = \"" << kStandinDevice << "\"\nrecording = \"" << recording.string()
                          << "\"\n" << extra << "\n";
    char error[512] = {};
    loaded_ = arpipe_v4l2_standin_load(config.c_str(), error, sizeof error) == 0;
    EXPECT_TRUE(loaded_) << error;
  }
  ~StandinDevice() { arpipe_v4l2_standin_unload(); }
  bool loaded() const { return loaded_; }
  struct arpipe_v4l2_standin_stats stats() const {
    struct arpipe_v4l2_standin_stats s{};
    arpipe_v4l2_standin_stats(kStandinDevice, &s);
    return s;
  }

 private:
  bool loaded_ = false;
};

}  // namespace arpipe::test
