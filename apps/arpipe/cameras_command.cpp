// arpipe cameras: every camera both backends see (V4L2 nodes, libcamera cameras), with formats,
// sizes, rates and controls, and the config keys that select each.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "capture/libcamera/libcamera_cameras.h"
#include "capture/v4l2/v4l2_cameras.h"

namespace arpipe {

namespace {

void print(const CameraDescription& camera) {
  const std::string key = camera.backend == SourceType::V4l2 ? "source.device" : "source.camera";
  fmt::print("{}: {}  ({} = \"{}\")\n", choice_name(kSourceTypeNames, camera.backend), camera.name.empty() ? "(unnamed)" : camera.name, key,
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

struct CamerasOptions {
  bool v4l2_only = false, libcamera_only = false;
  std::vector<std::string> paths;
};

int list_cameras(const CamerasOptions& options) {
  const bool v4l2 = !options.libcamera_only, libcamera = !options.v4l2_only;
  const std::vector<std::string>& paths = options.paths;
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

}  // namespace

void add_cameras_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand(
      "cameras", "every camera V4L2 and libcamera see: formats, sizes, rates, controls, and the config key that selects it");
  auto options = std::make_shared<CamerasOptions>();
  command->add_option("DEVICE", options->paths, "V4L2 device nodes to describe (default: every /dev/video*)");
  CLI::Option* v4l2 = command->add_flag("--v4l2-only", options->v4l2_only, "only V4L2 devices");
  CLI::Option* libcamera = command->add_flag("--libcamera-only", options->libcamera_only, "only libcamera cameras");
  v4l2->excludes(libcamera);
  cli::on_run(command, [options] { return list_cameras(*options); });
}

}  // namespace arpipe
