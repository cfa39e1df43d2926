// Shared fixture of the stand-in tests: a temp dir with a config, raw open/ioctl/mmap/poll helpers,
// and the recordings the answers come from (the default capture; small synthetic ones).
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "v4l2_standin.h"

namespace arpipe::standin_test {

inline const std::filesystem::path kDefaultCapture = ARPIPE_BINARY_DIR "/default-capture";
inline constexpr const char* kDevice = "/dev/video42";

inline int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// What vb2 puts in v4l2_buffer.timestamp for a time in ns (whole microseconds).
inline int64_t buffer_time_us(const v4l2_buffer& b) { return int64_t(b.timestamp.tv_sec) * 1000000 + b.timestamp.tv_usec; }

class StandinTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static int counter = 0;
    dir_ = std::filesystem::temp_directory_path() / ("arpipe-standin-test-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    for (const auto& [p, n] : maps_) munmap(p, n);
    for (int fd : fds_) close(fd);
    arpipe_v4l2_standin_unload();
    std::filesystem::remove_all(dir_);
  }

  // Writes the config (device = kDevice, recording = `recording`, then `extra` lines) and loads it.
  void load(const std::string& extra, const std::filesystem::path& recording = kDefaultCapture) {
    const std::string text = "[[device]]\npath = \"" + std::string(kDevice) + "\"\nrecording = \"" + recording.string() + "\"\n" + extra;
    char error[512] = "";
    ASSERT_EQ(arpipe_v4l2_standin_load(write_config(text).c_str(), error, sizeof error), 0) << error;
  }
  std::filesystem::path write_config(const std::string& text) {
    const auto path = dir_ / "standin.toml";
    std::ofstream(path) << text;
    return path;
  }

  int open_device(int flags = O_RDWR | O_NONBLOCK, const char* path = kDevice) {
    const int fd = ::open(path, flags);
    if (fd >= 0) fds_.push_back(fd);
    return fd;
  }
  void close_device(int fd) {
    std::erase(fds_, fd);
    ::close(fd);
  }

  // REQBUFS(count), mmap each, QBUF each; returns the mappings (buffer index -> bytes).
  std::vector<uint8_t*> setup_buffers(int fd, uint32_t count) {
    v4l2_requestbuffers r{};
    r.count = count;
    r.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    r.memory = V4L2_MEMORY_MMAP;
    EXPECT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), 0) << strerror(errno);
    std::vector<uint8_t*> maps;
    for (uint32_t i = 0; i < r.count; ++i) {
      v4l2_buffer b{};
      b.index = i;
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      EXPECT_EQ(ioctl(fd, VIDIOC_QUERYBUF, &b), 0);
      void* p = mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, b.m.offset);
      EXPECT_NE(p, MAP_FAILED) << strerror(errno);
      maps_.push_back({p, b.length});
      maps.push_back(static_cast<uint8_t*>(p));
      EXPECT_EQ(ioctl(fd, VIDIOC_QBUF, &b), 0);
    }
    return maps;
  }
  std::vector<uint8_t*> start(int fd, uint32_t count) {
    auto maps = setup_buffers(fd, count);
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    EXPECT_EQ(ioctl(fd, VIDIOC_STREAMON, &type), 0) << strerror(errno);
    return maps;
  }
  static int dqbuf(int fd, v4l2_buffer& b) {
    b = {};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    return ioctl(fd, VIDIOC_DQBUF, &b);
  }
  static int qbuf(int fd, uint32_t index) {
    v4l2_buffer b{};
    b.index = index;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    return ioctl(fd, VIDIOC_QBUF, &b);
  }
  // Polls (up to timeout) and dequeues the next buffer; false when none came.
  static bool next_buffer(int fd, v4l2_buffer& b, int timeout_ms = 1000) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) != 1 || !(p.revents & POLLIN)) return false;
    return dqbuf(fd, b) == 0;
  }

  // A small recording whose frame i has exposure (i+1) ms and analogue gain 1 + i/4 (controls move).
  // 640x480: the size of the default capture's camera model, which it borrows.
  std::filesystem::path synthetic_recording(int frames, int width = 640, int height = 480) {
    const auto path = dir_ / "synthetic";
    RecordingReader base(kDefaultCapture);
    RecordingInfo info;
    info.pixel_format = PixelFormat::YUYV;
    info.width = width;
    info.height = height;
    info.source = "standin test";
    RecordingWriter writer(path, info, base.camera_model());
    for (int i = 0; i < frames; ++i) {
      Frame f = Frame::allocate(PixelFormat::YUYV, width, height);
      for (size_t k = 0; k < f.data.size(); ++k) f.data[k] = uint8_t(16 + (k * 7 + size_t(i) * 13) % 220);
      f.meta.sequence = uint64_t(i);
      f.meta.exposure_ns = int64_t(i + 1) * 1000000;
      f.meta.readout_ns = 2000000;
      f.meta.exposure_start_ns = 5000000000 + int64_t(i) * 40000000;
      f.meta.frame_duration_ns = 40000000;
      f.meta.analogue_gain = 1.0 + i / 4.0;
      f.meta.digital_gain = 1.0;
      writer.append(f);
    }
    return path;
  }

  std::filesystem::path dir_;
  std::vector<int> fds_;
  std::vector<std::pair<void*, size_t>> maps_;
};

}  // namespace arpipe::standin_test
