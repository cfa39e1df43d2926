// libFuzzer target: mrcal .cameramodel text (core/geometry CameraModel::parse, the text behind
// CameraModel::load). Bad input must be a CameraModelError; a model that loads projects
// and unprojects a point, as every user of it does.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/geometry/camera_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const arpipe::CameraModel model = arpipe::CameraModel::parse(text, "fuzz.cameramodel");
    (void)model.project(arpipe::Vec3{0.1, -0.2, 1.0});
    (void)model.unproject(arpipe::Vec2{model.width() / 2.0, model.height() / 2.0});
  } catch (const arpipe::CameraModelError&) {
  }
  return 0;
}
