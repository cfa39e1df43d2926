// Camera-model files as hostile input: deep nesting is refused before it can exhaust the stack,
// the file size is capped, and only regular files are read (a FIFO used to block the open).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>

#include "core/geometry/camera_model.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

std::string parse_error(const std::string& text) {
  try {
    CameraModel::parse(text, "lens.cameramodel");
  } catch (const CameraModelError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(CameraModelLimits, DeepNestingIsRefusedAtTheLimit) {
  // Before: one recursion per '[': a 1 MB file of them overflowed the stack.
  const std::string text = "{ 'lensmodel': " + std::string(1'000'000, '[');
  const std::string message = parse_error(text);
  EXPECT_TRUE(contains(message, "lens.cameramodel:1:48: values nested more than 32 levels deep")) << message;
  // mrcal's own files nest 2 deep, which stays fine.
  EXPECT_EQ(parse_error("{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1, 1, 0, 0], 'extrinsics': [0, 0, 0, 0, "
                        "0, 0], 'imagersize': [2, 2], 'valid_intrinsics_region': [[0, 0], [1, 1]] }"),
            "");
}

TEST(CameraModelLimits, SplineConfigurationsMrcalAssertsOnAreRefused) {
  // tests/fuzz/regressions/fuzz_cameramodel/splined-ny3-mrcal-assert.cameramodel: mrcal aborted the
  // process ("Cubic splines: absolute minimum Nx, Ny is 4").
  const fs::path file = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "fuzz_cameramodel" /
                        "splined-ny3-mrcal-assert.cameramodel";
  try {
    CameraModel::load(file);
    ADD_FAILURE() << "expected a CameraModelError";
  } catch (const CameraModelError& e) {
    EXPECT_TRUE(contains(e.what(), "order-3 splines need Nx and Ny of at least 4, got Nx=4 Ny=3")) << e.what();
  }
  try {
    CameraModel("LENSMODEL_SPLINED_STEREOGRAPHIC_order=2_Nx=2_Ny=9_fov_x_deg=100", {}, 10, 10);
    ADD_FAILURE() << "expected a CameraModelError";
  } catch (const CameraModelError& e) {
    EXPECT_TRUE(contains(e.what(), "order-2 splines need Nx and Ny of at least 3, got Nx=2 Ny=9")) << e.what();
  }
}

TEST(CameraModelLimits, ACoreFarOutsideAnyLensIsRefused) {
  // tests/fuzz/regressions/fuzz_cameramodel/splined-cy-2.4e12-unproject-hang.cameramodel (found by
  // CI's mutation run): cy = 2.4e12 loaded, then mrcal's unprojection ran for minutes.
  const fs::path file = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "fuzz_cameramodel" /
                        "splined-cy-2.4e12-unproject-hang.cameramodel";
  try {
    CameraModel::load(file);
    ADD_FAILURE() << "expected a CameraModelError";
  } catch (const CameraModelError& e) {
    EXPECT_TRUE(contains(e.what(), "(320, 2429496729540) is more than 10 imager sizes outside the 640x480 image"))
        << e.what();
  }
  try {
    CameraModel("LENSMODEL_PINHOLE", {2e7, 500, 320, 240}, 640, 480);
    ADD_FAILURE() << "expected a CameraModelError";
  } catch (const CameraModelError& e) {
    EXPECT_TRUE(contains(e.what(), "must be at most 10000000 px, got fx=20000000 fy=500")) << e.what();
  }
  // The edges of the allowed range still load: a principal point ten image widths to the left.
  EXPECT_NO_THROW(CameraModel("LENSMODEL_PINHOLE", {500, 500, -6400, 240}, 640, 480));
}

TEST(CameraModelLimits, FilesAreRegularAndBounded) {
  const fs::path dir = fs::temp_directory_path() / ("arpipe_cameramodel_limits_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path fifo = dir / "camera.cameramodel";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto loading = std::async(std::launch::async, [&]() -> std::string {
    try {
      CameraModel::load(fifo);
    } catch (const CameraModelError& e) {
      return e.what();
    }
    return "";
  });
  if (loading.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    ADD_FAILURE() << "CameraModel::load blocked on a FIFO";
    loading.wait();
    if (writer >= 0) ::close(writer);
  } else {
    EXPECT_EQ(loading.get(),
              fifo.string() + ": cannot read camera model: it is a FIFO (named pipe), expected a regular file");
  }
  const fs::path big = dir / "big.cameramodel";
  std::ofstream(big) << "{ 'lensmodel': 'LENSMODEL_PINHOLE' }" << std::string(5 << 20, ' ');
  try {
    CameraModel::load(big);
    ADD_FAILURE() << "expected a CameraModelError";
  } catch (const CameraModelError& e) {
    EXPECT_EQ(std::string(e.what()),
              big.string() + ": cannot read camera model: it is larger than the limit of 4194304 bytes");
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arpipe
