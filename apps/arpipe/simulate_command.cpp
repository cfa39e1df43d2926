// arpipe simulate: renders a simulator scene (configs/sim/*.toml) into a recording with ground truth.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "apps/cli/progress_bar.h"
#include "capture/sim/recording_files.h"
#include "capture/sim/scene_export.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sinks/output_path.h"
#include "capture/sim/simulator.h"
#include "core/log.h"

namespace arpipe {

namespace {

struct SimulateOptions {
  std::string scene_path;
  sim::SimulateOptions simulate;
  int samples = 0;  // 0: the scene's render.samples_per_pixel
  bool png = false;  // also each frame as DIR/frame_NNNNNN.png
  std::string export_glb;  // also the real objects and lights as this .glb
  std::vector<std::string> export_leave_out;  // objects (by name) the .glb leaves out
  std::string video;       // also the frames as this 360° MP4 (a LENSMODEL_LONLAT camera's)
};

int run_simulate(SimulateOptions& command) {
  const std::string& scene_path = command.scene_path;
  sim::SimulateOptions& options = command.simulate;
  const int samples = command.samples;
  sim::SimScene scene;
  try {
    scene = sim::load_sim_scene(scene_path);
  } catch (const std::bad_alloc&) {  // the loaders cap what they allocate; this names the file if one did not
    log::error("{}: out of memory while loading the scene and its assets", scene_path);
    return 2;
  } catch (const std::length_error& e) {
    log::error("{}: a size in the scene or its assets is too large ({})", scene_path, e.what());
    return 2;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 2;
  }
  if (samples > 0) scene.render.samples_per_pixel = samples;
  if (!command.video.empty() && scene.camera.model.lensmodel() != "LENSMODEL_LONLAT") {
    log::error("{}: --video writes 360° videos: the camera must be LENSMODEL_LONLAT, not {}", scene_path,
               scene.camera.model.lensmodel());
    return 2;
  }
  if (!command.export_glb.empty()) {  // before the frames: a scene it cannot export fails fast
    try {
      sim::SimScene exported = scene;
      for (const std::string& name : command.export_leave_out) {
        const auto named = [&](const sim::SimObject& o) { return o.name == name; };
        if (std::find_if(exported.objects.begin(), exported.objects.end(), named) == exported.objects.end())
          throw std::invalid_argument(fmt::format("--export-leave-out {}: the scene has no object of that name", name));
        std::erase_if(exported.objects, named);
      }
      const std::vector<uint8_t> glb = sim::export_scene_glb(exported);
      // Its folder is made as --out's is (the usual place is inside --out, not written yet).
      const std::filesystem::path parent = std::filesystem::path(command.export_glb).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
      if (const int error = replace_file(command.export_glb, glb))
        throw std::runtime_error(fmt::format("{}: {}", command.export_glb, std::strerror(error)));
      log::info("wrote the real objects and {} lights to {}", scene.lights.size(), command.export_glb);
    } catch (const std::exception& e) {
      log::error("{}: cannot export the scene: {}", scene_path, e.what());
      return 1;
    }
  }
  sim::SimulateSummary summary;
  try {
    ProgressBar progress("frames");  // its line ends when it goes, before an error is logged
    options.on_frame = [&progress](int done, int total) { progress.update(done, total); };
    summary = sim::simulate(scene, options);
  } catch (const std::bad_alloc&) {
    log::error("{}: out of memory while simulating into {}", scene_path, options.out_dir.string());
    return 1;
  }
  if (command.png) {
    try {
      sim::write_recording_as_pngs(options.out_dir);
    } catch (const std::exception& e) {
      log::error("writing the frames as PNG: {}", e.what());
      return 1;
    }
  }
  if (!command.video.empty()) {
    try {
      sim::write_recording_as_video(options.out_dir, command.video, scene.camera);
      log::info("wrote the frames as {}", command.video);
    } catch (const std::exception& e) {
      log::error("writing the frames as a video: {}", e.what());
      return 1;
    }
  }
  log::info("wrote {} frames to {} in {:.1f} s ({:.1f} s setup, {:.2f} s per frame{})", summary.frames,
            options.out_dir.string(), summary.seconds, summary.setup_seconds,
            (summary.seconds - summary.setup_seconds) / summary.frames,
            summary.wrote_composite ? ", with the ground-truth composite and coverage" : "");
  return 0;
}

}  // namespace

void add_simulate_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand(
      "simulate", "render a simulator scene (configs/sim/, docs/SIMULATOR.md) into a recording with exact ground truth");
  command->footer(
      "DIR must not hold a recording; DIR/ground_truth_composite and DIR/ground_truth_coverage (the virtual objects'\n"
      "visible coverage per pixel) are written when the scene has virtual objects.");
  auto options = std::make_shared<SimulateOptions>();
  command->add_option("--scene", options->scene_path, "the simulator scene")->type_name("FILE")->required();
  command->add_option("--out", options->simulate.out_dir, "where the recording goes")->type_name("DIR")->required();
  command->add_option("--frames", options->simulate.frames, "render only the first N frames")
      ->check(CLI::PositiveNumber)
      ->default_str("all");
  command->add_option_function<uint64_t>(
             "--seed", [options](const uint64_t& seed) { options->simulate.seed = seed; }, "the noise's random seed")
      ->default_str("the scene's render.seed");
  command->add_option("--threads", options->simulate.threads, "render threads")
      ->check(CLI::PositiveNumber)
      ->default_str("every core");
  command->add_option("--samples", options->samples, "override the scene's render.samples_per_pixel (a square number)")
      ->check(cli::accepted_by([](const std::string& text) {
        try {
          return sim::samples_per_axis(std::stoi(text)) > 0;
        } catch (const std::exception&) {
          return false;
        }
      }, "a square number"))
      ->default_str("the scene's");
  command->add_flag("--png", options->png, "also write each frame as DIR/frame_NNNNNN.png (a LENSMODEL_LONLAT camera's: a panorama)");
  command->add_option("--export-glb", options->export_glb,
                      "also write the real objects (one mesh in the world frame, for render.proxies) and the lights "
                      "(KHR_lights_punctual, for light.panorama.lights_file) as a binary glTF")
      ->type_name("FILE");
  command->add_option("--export-leave-out", options->export_leave_out,
                      "leave this object (by its name in the scene) out of --export-glb: the real ground, which "
                      "render.shadows' ground catcher stands for; repeatable")
      ->type_name("NAME");
  command->add_option("--video", options->video,
                      "also write the frames as a 360° H.264 MP4 with spherical metadata (a LENSMODEL_LONLAT camera's, "
                      "mono or its [camera.stereo] pair)")
      ->type_name("FILE");
  cli::on_run(command, [options] { return run_simulate(*options); }, cli::Failure{.status = 1});
}

}  // namespace arpipe
