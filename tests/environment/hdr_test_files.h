// Helpers for the HDR tests: a scratch directory per test, bytes in and out of files, and the
// message check used by the error tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/vec.h"
#include "core/scene/asset_error.h"

namespace arpipe::hdr_test {

// The angle between two directions (atan2: accurate near 0 and pi).
inline double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(norm(cross(a, b)), dot(a, b)); }

// A direction uniform on the sphere.
inline Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const Vec3 v{g(rng), g(rng), g(rng)};
    if (norm(v) > 1e-6) return normalized(v);
  }
}

// A fresh directory under the build tree named after the running test (tests run in parallel).
inline std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(ARPIPE_BINARY_DIR) / "test-hdr-scratch" / (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::vector<uint8_t> bytes_of(std::string_view text) { return {text.begin(), text.end()}; }

inline void append(std::vector<uint8_t>& bytes, std::initializer_list<int> values) {
  for (int v : values) bytes.push_back(static_cast<uint8_t>(v));
}

inline std::vector<uint8_t> read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Removes the file first: truncating a file that holds data makes ext4 flush it (milliseconds),
// a new file costs microseconds, which matters for the loops over thousands of inputs.
inline void write_bytes(const std::filesystem::path& file, const std::vector<uint8_t>& bytes) {
  std::filesystem::remove(file);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// Runs `action`, expects an AssetError, and returns its message ("" and a failure otherwise).
inline std::string asset_error_message(const std::function<void()>& action) {
  try {
    action();
  } catch (const AssetError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an AssetError";
  return "";
}

}  // namespace arpipe::hdr_test
