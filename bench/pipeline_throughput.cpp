// Benchmark: per-stage time and frames per second of the embedded default scene and of
// pass-through (no virtual object), and resident memory over a looped replay (soak).
// `arpipe bench pipeline [--capture DIR] [--frames N] [--soak-seconds S]` prints a markdown table
// for docs/BENCHMARKS.md. Timings depend on the machine; compare the
// rows of one run with each other, not with another machine's.
#include <fmt/format.h>
#include <sys/utsname.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include "apps/common/pipeline_assembly.h"
#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "core/log.h"

namespace arpipe {
namespace {

long resident_kib() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

Config bench_config(const std::string& capture, int64_t frames, bool with_object, const std::string& lens = "map") {
  std::vector<std::string> overrides{
      fmt::format("source.path=\"{}\"", capture), "source.pacing=\"fast\"", "source.loop=true",
      fmt::format("pipeline.max_frames={}", frames), "sinks.png.enabled=false", "sinks.y4m.enabled=false",
      "sinks.results.enabled=false", "pipeline.log_level=\"warning\""};
  // The default scene's cube, as configs/arpipe.toml names it (a config without objects draws none).
  if (with_object) overrides.push_back("render.objects=[{mesh=\"builtin:cube\"}]");
  overrides.push_back(fmt::format("render.lens=\"{}\"", lens));
  return parse_config("", "(benchmark)", overrides);
}

PipelineMetrics run(const Config& config) {
  // Sinks are off: this measures the pipeline, not the disk.
  PipelineRunner runner(make_source(config), make_stage_factory(), {}, config);
  runner.start();
  runner.wait();
  return runner.metrics();
}

void print_row(const std::string& name, const PipelineMetrics& m) {
  auto stage_ms = [&](const std::string& stage) {
    auto it = m.stages.find(stage);
    if (it == m.stages.end() || it->second.runs == 0) return std::string("-");
    uint64_t skipped = 0;
    for (const auto& [reason, count] : it->second.skips) skipped += count;
    return fmt::format("{:.2f}{}", it->second.total_ms / double(it->second.runs),
                       skipped ? fmt::format(" ({} skipped)", skipped) : "");
  };
  fmt::print("| {} | {} | {:.1f} | {} | {} | {} |\n", name, m.frames_out, m.fps(), stage_ms("track"),
             stage_ms("render"), stage_ms("composite"));
}

struct PipelineOptions {
  std::string capture = "build/default-capture";
  int64_t frames = 600;
  int soak_seconds = 0;
};

int run_pipeline_benchmark(const PipelineOptions& options) {
  const std::string& capture = options.capture;
  const int64_t frames = options.frames;
  const int soak_seconds = options.soak_seconds;
  log::set_max_level(log::Level::Warning);
  utsname u{};
  uname(&u);
  fmt::print("machine: {} {}, {} hardware threads\n\n", u.sysname, u.machine, std::thread::hardware_concurrency());
  fmt::print("| run | frames | frames/s | track ms | render ms | composite ms |\n|---|---:|---:|---:|---:|---:|\n");
  // Warm-up (shader JIT, page cache), then the measured runs.
  run(bench_config(capture, 30, true));
  print_row("default scene (cube on tag), render.lens = map (default)", run(bench_config(capture, frames, true)));
  print_row("default scene, render.lens = vertex", run(bench_config(capture, frames, true, "vertex")));
  print_row("default scene, render.lens = undistort", run(bench_config(capture, frames, true, "undistort")));
  print_row("pass-through (no virtual object)", run(bench_config(capture, frames, false)));

  if (soak_seconds > 0) {
    const Config config = bench_config(capture, 0, true);
    PipelineRunner runner(make_source(config), make_stage_factory(), {}, config);
    runner.start();
    const auto start = std::chrono::steady_clock::now();
    long first = -1, peak = 0, last = 0;
    fmt::print("\nsoak: {} s looped replay of the default scene\n\n| t (s) | frames | RSS (MiB) |\n|---:|---:|---:|\n",
               soak_seconds);
    const int step = std::max(1, soak_seconds / 10);
    for (int t = 0; t <= soak_seconds; ++t) {
      std::this_thread::sleep_until(start + std::chrono::seconds(t));
      last = resident_kib();
      peak = std::max(peak, last);
      if (t == std::min(10, soak_seconds)) first = last;  // after warm-up
      if (t % step == 0) fmt::print("| {} | {} | {:.1f} |\n", t, runner.metrics().frames_out, last / 1024.0);
    }
    runner.stop();
    runner.wait();
    fmt::print("\nRSS after warm-up {:.1f} MiB, at the end {:.1f} MiB, peak {:.1f} MiB\n", first / 1024.0,
               last / 1024.0, peak / 1024.0);
  }
  return 0;
}

}  // namespace

void add_pipeline_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "pipeline", "per-stage time and frames/s of the default scene and of pass-through; memory over a looped replay");
  auto options = std::make_shared<PipelineOptions>();
  command->add_option("--capture", options->capture, "the recording to replay")->type_name("DIR");
  command->add_option("--frames", options->frames, "frames per measured run")->check(CLI::PositiveNumber);
  command->add_option("--soak-seconds", options->soak_seconds, "then a looped replay this long, its memory every step (0: none)")
      ->type_name("S")
      ->check(CLI::NonNegativeNumber);
  cli::on_run(command, [options] { return run_pipeline_benchmark(*options); });
}

}  // namespace arpipe
