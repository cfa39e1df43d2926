// libcamera's manager runs here with no cameras: listing gives no cameras and opening one fails
// with CameraError::Missing naming what exists, without crashing. Modes come from StreamFormats.
#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>

#include <libcamera/formats.h>
#include <libcamera/stream.h>

#include "capture/libcamera/libcamera_cameras.h"
#include "capture/libcamera/libcamera_stream.h"

namespace arpipe {
namespace {

TEST(LibcameraCameras, ListingNamesEveryCameraByIdAndNeverFails) {
  const auto cameras = list_libcamera_cameras();
  for (const auto& c : cameras) {
    EXPECT_EQ(c.backend, SourceType::Libcamera);
    EXPECT_TRUE(!c.id.empty() || !c.error.empty());
  }
  // A second listing reuses the one manager (libcamera allows one per process).
  EXPECT_EQ(list_libcamera_cameras().size(), cameras.size());
}

CameraError open_error(const std::string& camera) {
  SourceConfig config;
  config.type = SourceType::Libcamera;
  config.camera = camera;
  try {
    open_libcamera_stream(config);
  } catch (const CameraError& e) {
    return e;
  }
  ADD_FAILURE() << "opening libcamera camera '" << camera << "' did not fail";
  return CameraError(CameraError::Kind::Failed, "");
}

TEST(LibcameraCameras, MissingCameraIsMissingAndNamesWhatExists) {
  const auto cameras = list_libcamera_cameras();
  for (const std::string wanted : {"/base/no/such/camera@10", "99"}) {
    const auto e = open_error(wanted);
    EXPECT_EQ(e.kind(), CameraError::Kind::Missing) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(wanted), std::string::npos) << what;
    if (cameras.empty()) {
      EXPECT_NE(what.find("no cameras present"), std::string::npos) << what;
    }
    for (const auto& c : cameras) EXPECT_NE(what.find(c.id), std::string::npos) << what;
  }
  if (cameras.empty()) {
    EXPECT_EQ(open_error("").kind(), CameraError::Kind::Missing);
  }
}

TEST(LibcameraCameras, ModesFromStreamFormats) {
  namespace f = libcamera::formats;
  std::map<libcamera::PixelFormat, std::vector<libcamera::SizeRange>> formats;
  formats[f::BGR888] = {libcamera::SizeRange(libcamera::Size(640, 480)), libcamera::SizeRange(libcamera::Size(1280, 720))};
  formats[f::YUV420] = {libcamera::SizeRange(libcamera::Size(1920, 1080))};
  const auto modes = libcamera_modes(libcamera::StreamFormats(formats));
  // One mode per discrete size; the order is libcamera's (its map orders fourccs as numbers).
  std::vector<std::tuple<std::string, int, int>> got;
  for (const auto& m : modes) got.emplace_back(m.format, m.width, m.height);
  std::sort(got.begin(), got.end());
  const std::vector<std::tuple<std::string, int, int>> want{
      {"RGB24", 640, 480}, {"RGB24", 1280, 720}, {"YUV420", 1920, 1080}};  // YUV420: libcamera's name
  EXPECT_EQ(got, want);
}

}  // namespace
}  // namespace arpipe
