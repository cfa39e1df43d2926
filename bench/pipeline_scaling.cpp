// Benchmark: how the pipeline's cost grows with what is drawn and with the frame. The embedded
// default config (configs/arpipe.toml) with 1, 4, 16 and 64 cubes on the default capture, and with
// one cube on the default scene simulated at 640x480, 1280x720 and 1920x1080 (configs/sim/
// default.toml on a larger sensor behind the same lens, 1 sample per pixel: the cube covers the
// same pixels in every size). Each row also runs pass-through on the same capture. The render's
// cost should follow the pixels and triangles drawn (more cubes), not the frame.
// `arpipe bench scaling [--frames N] [--plot FILE.png] [--work DIR]` prints a markdown table and
// writes a plot of render ms against both.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "bench/pipeline_run.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/log.h"

namespace fs = std::filesystem;

namespace arpipe {
namespace {

struct ScalingOptions {
  int64_t frames = 200;
  std::string plot = "build/bench-scaling.png";
  std::string work = "build/bench-scaling";
};

struct Point {
  int width = 0, height = 0, objects = 0;
  double fps = 0, pass_fps = 0, track_ms = 0, render_ms = 0, composite_ms = 0;
};

// n cubes (n a square) in a grid 7 cm apart, centred on the tag.
std::string cube_grid(int n) {
  const int side = static_cast<int>(std::lround(std::sqrt(n)));
  std::string objects = "render.objects=[";
  for (int i = 0; i < n; ++i) {
    const double x = 0.07 * (i % side - (side - 1) / 2.0), y = 0.07 * (i / side - (side - 1) / 2.0);
    objects += fmt::format("{}{{mesh=\"builtin:cube\", position_m=[{}, {}, 0.0]}}", i ? ", " : "", x, y);
  }
  return objects + "]";
}

Config scaling_config(const fs::path& capture, int64_t frames, const std::string& objects) {
  return load_config("configs/arpipe.toml",
                     {fmt::format("source.path=\"{}\"", capture.string()), "source.pacing=\"fast\"", "source.loop=true",
                      "sinks.png.enabled=false", "sinks.y4m.enabled=false", "sinks.results.enabled=false",
                      "pipeline.log_level=\"warning\"", fmt::format("pipeline.max_frames={}", frames), objects});
}

Point measure(const fs::path& capture, int width, int height, int objects, int64_t frames) {
  const std::string grid = cube_grid(objects);
  run_pipeline(scaling_config(capture, 20, grid));  // warm-up: shader JIT, PRT cache
  const PipelineMetrics drawn = run_pipeline(scaling_config(capture, frames, grid));
  const PipelineMetrics pass = run_pipeline(scaling_config(capture, kPassThroughFramesFactor * frames, "render.objects=[]"));
  return {width,        height, objects, drawn.fps(), pass.fps(), mean_stage_ms(drawn, "track"),
          mean_stage_ms(drawn, "render"), mean_stage_ms(drawn, "composite")};
}

// The default scene on a larger sensor: the same lens (focal length and distortion) with the
// principal point kept at the same offset from the frame's centre, so the tag and the cube cover
// the same pixels while the frame sees more around them.
fs::path simulate_at(int width, int height, const fs::path& work) {
  const fs::path dir = work / fmt::format("default-{}x{}", width, height);
  if (fs::exists(dir / "frames.jsonl")) return dir;  // simulated by an earlier run
  fs::remove_all(dir);
  sim::SimScene scene = sim::load_sim_scene("configs/sim/default.toml");
  const CameraModel& m = scene.camera.model;
  std::vector<double> intrinsics = m.intrinsics();
  intrinsics[2] = m.cx() + 0.5 * (width - m.width());
  intrinsics[3] = m.cy() + 0.5 * (height - m.height());
  scene.camera.model = CameraModel(m.lensmodel(), intrinsics, width, height);
  scene.render.samples_per_pixel = 1;
  sim::SimulateOptions options;
  options.out_dir = dir;
  sim::simulate(scene, options);
  return dir;
}

// Render ms against the number of cubes (left) and against the frame's megapixels (right).
void write_plot(const std::vector<Point>& by_objects, const std::vector<Point>& by_size, const std::string& path) {
  constexpr int kPanel = 420, kHeight = 360, kMargin = 50;
  cv::Mat image(kHeight, 2 * kPanel, CV_8UC3, cv::Scalar(255, 255, 255));
  double top = 1;
  for (const auto* points : {&by_objects, &by_size})
    for (const Point& p : *points) top = std::max(top, p.render_ms);
  top *= 1.1;
  const auto panel = [&](int left, const std::vector<Point>& points, auto x_of, double x_max, const std::string& title) {
    const cv::Point origin(left + kMargin, kHeight - kMargin);
    const int w = kPanel - 2 * kMargin, h = kHeight - 2 * kMargin;
    cv::line(image, origin, origin + cv::Point(w, 0), cv::Scalar(0, 0, 0));
    cv::line(image, origin, origin - cv::Point(0, h), cv::Scalar(0, 0, 0));
    cv::putText(image, title, cv::Point(left + kMargin, 25), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0));
    cv::putText(image, fmt::format("{:.0f} ms", top), cv::Point(left + 2, kMargin), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0));
    cv::Point previous(-1, -1);
    for (const Point& p : points) {
      const cv::Point at(origin.x + static_cast<int>(w * x_of(p) / x_max),
                         origin.y - static_cast<int>(h * p.render_ms / top));
      if (previous.x >= 0) cv::line(image, previous, at, cv::Scalar(200, 80, 20), 2);
      cv::circle(image, at, 4, cv::Scalar(200, 80, 20), cv::FILLED);
      cv::putText(image, fmt::format("{:.1f}", p.render_ms), at + cv::Point(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                  cv::Scalar(0, 0, 0));
      previous = at;
    }
  };
  panel(0, by_objects, [](const Point& p) { return std::log2(double(p.objects)); }, 6.0,
        "render ms against log2(cubes)");
  panel(kPanel, by_size, [](const Point& p) { return p.width * p.height / 1e6; }, 2.1,
        "render ms against megapixels, 1 cube");
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write " + path);
}

void print_row(const Point& p) {
  fmt::print("| {}x{} | {} | {:.1f} | {:.2f} | {:.2f} | {:.2f} | {:.1f} |\n", p.width, p.height, p.objects, p.fps,
             p.track_ms, p.render_ms, p.composite_ms, p.pass_fps);
}

int run_scaling_benchmark(const ScalingOptions& options) {
  log::set_max_level(log::Level::Warning);
  fs::create_directories(options.work);
  fmt::print("| frame | cubes | frames/s | track ms | render ms | composite ms | pass-through frames/s |\n"
             "|---|---:|---:|---:|---:|---:|---:|\n");
  std::vector<Point> by_objects, by_size;
  const fs::path default_capture = "build/default-capture";
  for (int objects : {1, 4, 16, 64}) {
    by_objects.push_back(measure(default_capture, 640, 480, objects, options.frames));
    print_row(by_objects.back());
  }
  for (const auto& [width, height] : {std::pair{640, 480}, std::pair{1280, 720}, std::pair{1920, 1080}}) {
    by_size.push_back(measure(simulate_at(width, height, options.work), width, height, 1, options.frames));
    print_row(by_size.back());
  }
  write_plot(by_objects, by_size, options.plot);
  fmt::print("\nplot: {}\n", options.plot);
  return 0;
}

}  // namespace

void add_scaling_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "scaling", "pipeline cost against the number of objects (1 to 64) and the frame size (640x480 to 1920x1080)");
  auto options = std::make_shared<ScalingOptions>();
  command->add_option("--frames", options->frames, "frames per measured run")->check(CLI::PositiveNumber)->capture_default_str();
  command->add_option("--plot", options->plot, "where the plot goes (PNG)")->type_name("FILE")->capture_default_str();
  command->add_option("--work", options->work, "where the larger captures are simulated (kept for the next run)")
      ->type_name("DIR")
      ->capture_default_str();
  cli::on_run(command, [options] { return run_scaling_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
