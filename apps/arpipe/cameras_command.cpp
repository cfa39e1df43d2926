// arpipe cameras: every camera both backends see (V4L2 nodes, libcamera cameras), with formats,
// sizes, rates and controls, and the config keys that select each.
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/arpipe/commands.h"
#include "capture/libcamera/libcamera_cameras.h"
#include "capture/v4l2/v4l2_cameras.h"

namespace arpipe {

namespace {

constexpr const char* kUsage = "usage: arpipe cameras [--v4l2-only | --libcamera-only] [DEVICE]...\n";

void print(const CameraDescription& camera) {
  const std::string key = camera.backend == "v4l2" ? "source.device" : "source.camera";
  fmt::print("{}: {}  ({} = \"{}\")\n", camera.backend, camera.name.empty() ? "(unnamed)" : camera.name, key,
             camera.id);
  if (!camera.location.empty()) fmt::print("  location: {}\n", camera.location);
  if (!camera.error.empty()) fmt::print("  note: {}\n", camera.error);
  if (!camera.modes.empty()) fmt::print("  formats:\n");
  for (const auto& mode : camera.modes) {
    std::string line = mode.width ? fmt::format("{} {}x{}", mode.format, mode.width, mode.height) : mode.format;
    if (!mode.fps.empty()) {
      std::vector<std::string> rates;
      for (const double fps : mode.fps) rates.push_back(fmt::format("{:.4g}", fps));
      line += fmt::format(" @ {} fps", fmt::join(rates, ", "));
    }
    if (!mode.note.empty()) line += fmt::format(" ({})", mode.note);
    fmt::print("    {}\n", line);
  }
  if (!camera.controls.empty()) fmt::print("  controls:\n");
  for (const auto& control : camera.controls) fmt::print("    {}: {}\n", control.name, control.range);
}

}  // namespace

int run_cameras(const Args& args) {
  bool v4l2 = true, libcamera = true;
  std::vector<std::string> paths;
  for (const auto& arg : args) {
    if (arg == "--v4l2-only") {
      libcamera = false;
    } else if (arg == "--libcamera-only") {
      v4l2 = false;
    } else if (!arg.starts_with("-")) {
      paths.push_back(arg);
    } else {
      std::fputs(kUsage, stderr);
      return 2;
    }
  }
  size_t count = 0;
  if (v4l2) {
    for (const auto& camera : list_v4l2_cameras(paths)) {
      print(camera);
      ++count;
    }
  }
  if (libcamera) {
    for (const auto& camera : list_libcamera_cameras()) {
      print(camera);
      ++count;
    }
  }
  if (count == 0) fmt::print("no cameras found (V4L2: /dev/video*; libcamera: its pipeline handlers)\n");
  std::fflush(stdout);
  return 0;
}

}  // namespace arpipe
