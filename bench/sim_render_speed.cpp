// Benchmark: the simulator's run time against its Monte-Carlo error, per scene and samples per
// pixel. Error = RMS difference of the noise-free linear image from a high-sample reference of the
// same frame, both clipped at full scale as the sensor clips them (a light seen directly or in a
// mirror is thousands of times full scale and would otherwise swamp everything), relative to the
// reference's mean (so scenes of any brightness compare).
// `arpipe bench sim-render [--scenes DIR] [--samples 1,4,16] [--reference 256] [--frames N] [--threads N]`
// prints a markdown table for docs/BENCHMARKS.md.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "capture/recording/recording_reader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/log.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

struct Run {
  double seconds_per_frame = 0;  // rendering, sensor and writing, without the one-off setup
  double setup_seconds = 0;
  std::vector<cv::Mat> linear;  // per frame
};

Run render(sim::SimScene scene, int samples, int frames, int threads, const fs::path& dir) {
  fs::remove_all(dir);
  scene.render.samples_per_pixel = samples;
  scene.render.write_linear = true;
  sim::SimulateOptions options;
  options.out_dir = dir;
  options.frames = frames;
  options.threads = threads;
  const sim::SimulateSummary summary = sim::simulate(scene, options);
  Run run;
  run.seconds_per_frame = (summary.seconds - summary.setup_seconds) / frames;
  run.setup_seconds = summary.setup_seconds;
  const RecordingReader reader(dir);
  for (const GroundTruthFrame& truth : reader.ground_truth())
    run.linear.push_back(cv::imread((dir / truth.linear_image).string(), cv::IMREAD_UNCHANGED));
  fs::remove_all(dir);
  return run;
}

double relative_rms(const std::vector<cv::Mat>& images, const std::vector<cv::Mat>& references) {
  double squared = 0, mean = 0, count = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat image = cv::min(images[i], 1.0), reference = cv::min(references[i], 1.0);
    const cv::Mat difference = image - reference;
    const cv::Scalar squares = cv::sum(difference.mul(difference));
    squared += squares[0] + squares[1] + squares[2];
    const cv::Scalar sum = cv::sum(reference);
    mean += sum[0] + sum[1] + sum[2];
    count += double(reference.total()) * 3;
  }
  return std::sqrt(squared / count) / (mean / count);
}

struct SimRenderOptions {
  fs::path scenes_dir = "configs/sim";
  std::vector<int> samples{1, 4, 16};
  int reference_samples = 256, frames = 2, threads = 0;
};

int run_sim_render_benchmark(const SimRenderOptions& options) {
  const fs::path& scenes_dir = options.scenes_dir;
  const std::vector<int>& samples = options.samples;
  const int reference_samples = options.reference_samples, frames = options.frames, threads = options.threads;
  std::vector<fs::path> scene_files;
  for (const auto& entry : fs::directory_iterator(scenes_dir))
    if (entry.path().extension() == ".toml") scene_files.push_back(entry.path());
  std::sort(scene_files.begin(), scene_files.end());

  const fs::path scratch = fs::temp_directory_path() / fmt::format("arpipe-sim-bench-{}", getpid());
  fmt::print("| scene | size | samples/px | s/frame | setup s | rel. RMS error vs {} spp | speed-up vs 16 spp |\n",
             reference_samples);
  fmt::print("|---|---|---|---|---|---|---|\n");
  for (const fs::path& file : scene_files) {
    const sim::SimScene scene = sim::load_sim_scene(file);
    const Run reference = render(scene, reference_samples, frames, threads, scratch);
    std::vector<std::pair<int, Run>> runs;
    double sixteen = 0;
    for (int n : samples) {
      runs.emplace_back(n, render(scene, n, frames, threads, scratch));
      if (n == 16) sixteen = runs.back().second.seconds_per_frame;
    }
    for (const auto& [n, run] : runs)
      fmt::print("| {} | {}x{} | {} | {:.3f} | {:.2f} | {:.4f} | {} |\n", file.stem().string(), scene.camera.model.width(),
                 scene.camera.model.height(), n, run.seconds_per_frame, run.setup_seconds,
                 relative_rms(run.linear, reference.linear),
                 sixteen > 0 ? fmt::format("{:.2f}", sixteen / run.seconds_per_frame) : "–");
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

void add_sim_render_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "sim-render", "the simulator's seconds per frame against its Monte-Carlo error, per scene and samples per pixel");
  auto options = std::make_shared<SimRenderOptions>();
  command->add_option("--scenes", options->scenes_dir, "every .toml scene in DIR")->type_name("DIR");
  command->add_option("--samples", options->samples, "samples per pixel, a comma-separated list")
      ->type_name("N,N,...")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(CLI::PositiveNumber);
  command->add_option("--reference", options->reference_samples, "samples per pixel of the reference")
      ->check(CLI::PositiveNumber);
  command->add_option("--frames", options->frames, "frames per scene")->check(CLI::PositiveNumber);
  command->add_option("--threads", options->threads, "render threads (0: every core)")->check(CLI::NonNegativeNumber);
  cli::on_run(command, [options] { return run_sim_render_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
