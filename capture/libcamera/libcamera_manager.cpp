#include "capture/libcamera/libcamera_manager.h"

#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>

#include <fmt/format.h>
#include <libcamera/camera_manager.h>
#include <libcamera/version.h>

#include "capture/live/camera_stream.h"

namespace arpipe {

namespace {

std::mutex g_mutex;
// Destroyed at exit, before libcamera's own statics (they were constructed first, at load).
std::unique_ptr<libcamera::CameraManager> g_manager;

}  // namespace

libcamera::CameraManager& libcamera_manager() {
  std::lock_guard lock(g_mutex);
  if (g_manager) return *g_manager;
  // libcamera logs INFO and WARN lines (its version, "No IPA found") to stderr at start-up; only
  // errors matter to arpipe's users. A LIBCAMERA_LOG_LEVELS set by the user wins.
  setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0);
  auto manager = std::make_unique<libcamera::CameraManager>();
  int ret = manager->start();
  if (ret < 0)
    throw CameraError(CameraError::Kind::Failed,
                      fmt::format("libcamera: the camera manager did not start: {}", std::strerror(-ret)));
  g_manager = std::move(manager);
  return *g_manager;
}

const char* libcamera_compiled_version() {
#define ARPIPE_STR2(x) #x
#define ARPIPE_STR(x) ARPIPE_STR2(x)
  return "libcamera " ARPIPE_STR(LIBCAMERA_VERSION_MAJOR) "." ARPIPE_STR(LIBCAMERA_VERSION_MINOR) "." ARPIPE_STR(
      LIBCAMERA_VERSION_PATCH);
#undef ARPIPE_STR
#undef ARPIPE_STR2
}

}  // namespace arpipe
