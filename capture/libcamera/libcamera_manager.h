// The process's one libcamera CameraManager (libcamera allows one per process), started on first
// use and shared by the camera listing and the streams.
#pragma once

namespace libcamera {
class CameraManager;
}

namespace arpipe {

// Starts the manager on the first call; throws CameraError (Failed) when it cannot start, and
// again on every later call, so a transient failure is retried. Thread-safe.
libcamera::CameraManager& libcamera_manager();

// "libcamera 0.0.3" as compiled against.
const char* libcamera_compiled_version();

}  // namespace arpipe
