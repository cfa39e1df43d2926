// Benchmark: per-stage time and frames per second of any config, of the same config with the
// render's costly features off, and of pass-through (the same capture with no virtual object), in
// one run; resident memory over a looped replay (soak).
// `arpipe bench pipeline [--config FILE] [--capture DIR] [--frames N] [--set KEY=VALUE]...
// [--soak-seconds S]` prints a markdown table for docs/BENCHMARKS.md. Timings depend on the
// machine; compare the rows of one run with each other, not with another machine's.
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <sys/utsname.h>

#include <chrono>
#include <ctime>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "apps/cli/command_line.h"
#include "apps/common/pipeline_assembly.h"
#include "bench/benchmarks.h"
#include "bench/pipeline_run.h"
#include "core/system/frame_memory.h"
#include "core/log.h"

namespace arpipe {
namespace {

struct PipelineOptions {
  std::string config = "configs/arpipe.toml";
  std::string capture;  // empty: the config's source
  int64_t frames = 300;
  std::vector<std::string> overrides;
  int soak_seconds = 0;
};

// The config as the user runs it, with the sinks off (this measures the pipeline, not the disk), a
// fast looped replay of `frames` frames, and `extra` overrides on top of the user's.
Config bench_config(const PipelineOptions& options, int64_t frames, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> overrides = options.overrides;
  if (!options.capture.empty()) overrides.push_back(fmt::format("source.path=\"{}\"", options.capture));
  for (const char* o : {"source.pacing=\"fast\"", "source.loop=true", "sinks.png.enabled=false",
                               "sinks.y4m.enabled=false", "sinks.recording.enabled=false", "sinks.results.enabled=false",
                               "pipeline.log_level=\"warning\""})
    overrides.push_back(o);
  overrides.push_back(fmt::format("pipeline.max_frames={}", frames));
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return load_config(options.config, overrides);
}

// "2.31", with the skips that went into the mean ("2.31 (12 skipped)"); "-" when it never ran.
std::string stage_cell(const PipelineMetrics& m, const std::string& stage) {
  const auto it = m.stages.find(stage);
  if (it == m.stages.end() || it->second.runs == 0) return "-";
  uint64_t skipped = 0;
  for (const auto& [reason, count] : it->second.skips) skipped += count;
  return fmt::format("{:.2f}{}", mean_stage_ms(m, stage), skipped ? fmt::format(" ({} skipped)", skipped) : "");
}

// The stages in pipeline order; "shadow" is part of "render" (its shadow map).
const std::vector<std::string> kStages{"track", "motion", "light", "render", "shadow", "composite"};

void print_row(const std::string& name, const PipelineMetrics& m) {
  std::string cells;
  for (const std::string& stage : kStages) cells += " " + stage_cell(m, stage) + " |";
  fmt::print("| {} | {} | {:.1f} |{}\n", name, m.frames_out, m.fps(), cells);
}

struct CpuRow {
  std::string name;
  const CpuPerFrame& cpu;
};

// Where each run's CPU went per frame, and what the runs' CPU allows with every core busy: a run
// whose frames need C ms of CPU cannot pass N cores / C frames/s however its work is spread.
void print_cpu_table(const std::vector<CpuRow>& rows) {
  const std::vector<std::pair<std::string, std::string>> parts{
      {"processing", "processing"}, {"helper", "helper"}, {"gl", "GL rasteriser"}, {"capture", "capture"},
      {"sinks", "sinks"}, {"other", "other"}};
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  fmt::print("\nCPU per frame by thread (ms; from the last warm-up frame to the {}th before the last):\n\n| run |",
             kCpuTailFrames);
  for (const auto& [part, title] : parts) fmt::print(" {} |", title);
  std::string rule = "|---|";
  for (size_t i = 0; i < parts.size() + 3; ++i) rule += "---:|";
  fmt::print(" all | cores busy | frames/s with all {} cores busy |\n{}\n", cores, rule);

  for (const CpuRow& row : rows) {
    if (row.cpu.frames == 0) {
      fmt::print("| {} | not measured (a run of {} frames or fewer, or no /proc) |\n", row.name, kCpuTailFrames);
      continue;
    }
    fmt::print("| {} |", row.name);
    for (const auto& [part, title] : parts) {
      const auto it = row.cpu.ms_by_part.find(part);
      fmt::print(" {:.2f} |", it == row.cpu.ms_by_part.end() ? 0.0 : it->second);
    }
    fmt::print(" {:.2f} | {:.2f} | {:.1f} |\n", row.cpu.total_ms, row.cpu.cores_busy,
               row.cpu.total_ms > 0 ? 1e3 * cores / row.cpu.total_ms : 0.0);
  }
}

int run_pipeline_benchmark(const PipelineOptions& options) {
  log::set_max_level(log::Level::Warning);
  utsname u{};
  uname(&u);
  // Parsed once up front, so that a bad config or --set fails before any measuring.
  const Config config = bench_config(options, options.frames);
  fmt::print("config {}{}, capture {}, {} frames per run after {} warm-up frames; {} {}, {} hardware threads; {}\n\n",
             options.config,
             options.overrides.empty() ? "" : " with --set " + fmt::format("{}", fmt::join(options.overrides, " ")),
             config.source.path.string(), options.frames, kWarmupFrames, u.sysname, u.machine,
             std::thread::hardware_concurrency(),
             fmt::format("{:%Y-%m-%d %H:%M} UTC", fmt::gmtime(std::time(nullptr))));
  std::string header = "| run | frames | frames/s |", rule = "|---|---:|---:|";
  for (const std::string& stage : kStages) {
    header += fmt::format(" {} ms |", stage);
    rule += "---:|";
  }
  fmt::print("{}\n{}\n", header, rule);
  // Warm-up (shader JIT, the PRT cache, the page cache), then the measured runs.
  run_pipeline(bench_config(options, 30));
  double setup_seconds = 0;
  CpuPerFrame full_cpu, cheap_cpu, pass_cpu;
  const PipelineMetrics full = run_pipeline(config, &setup_seconds, &full_cpu);
  // What the issue of record compares against: the same objects without the three features whose
  // cost is per pixel of the canvas rather than per pixel drawn.
  const PipelineMetrics cheap = run_pipeline(bench_config(
      options, options.frames, {"render.shadows.method=\"off\"", "render.msaa_samples=1", "render.lens=\"vertex\""}),
      nullptr, &cheap_cpu);
  const PipelineMetrics pass = run_pipeline(
      bench_config(options, kPassThroughFramesFactor * options.frames, {"render.objects=[]"}), nullptr, &pass_cpu);
  print_row("the config", full);
  print_row("shadows off, MSAA off, render.lens = vertex", cheap);
  print_row("pass-through (no virtual object)", pass);
  const double full_render = mean_stage_ms(full, "render"), cheap_render = mean_stage_ms(cheap, "render");
  fmt::print("\nframes/s against pass-through: {:.3f}; render ms against the cheap render: {}\n",
             pass.fps() > 0 ? full.fps() / pass.fps() : 0,
             cheap_render > 0 ? fmt::format("{:.2f}", full_render / cheap_render) : std::string("-"));
  fmt::print("the config's start, from building the pipeline to its first frame: {:.0f} ms (not in the rows)\n",
             setup_seconds * 1e3);
  print_cpu_table({{"the config", full_cpu}, {"shadows off, MSAA off, render.lens = vertex", cheap_cpu},
                   {"pass-through (no virtual object)", pass_cpu}});

  if (options.soak_seconds > 0) {
    const Config soak = bench_config(options, 0);
    PipelineRunner runner(make_source(soak), make_stage_factory(), {}, soak);
    runner.start();
    const auto start = std::chrono::steady_clock::now();
    long first = -1, peak = 0, last = 0;
    fmt::print("\nsoak: {} s looped replay of the config\n\n| t (s) | frames | RSS (MiB) |\n|---:|---:|---:|\n",
               options.soak_seconds);
    const int step = std::max(1, options.soak_seconds / 10);
    for (int t = 0; t <= options.soak_seconds; ++t) {
      std::this_thread::sleep_until(start + std::chrono::seconds(t));
      last = resident_memory_kib();
      peak = std::max(peak, last);
      if (t == std::min(10, options.soak_seconds)) first = last;  // after warm-up
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
      "pipeline",
      "per-stage time and frames/s of a config, of it with shadows, MSAA and the lens map off, and of pass-through");
  auto options = std::make_shared<PipelineOptions>();
  command->add_option("--config", options->config, "the config to measure (its sinks are turned off)")
      ->type_name("FILE")
      ->capture_default_str();
  command->add_option("--capture", options->capture, "the recording to replay (default: the config's source.path)")
      ->type_name("DIR");
  command->add_option("--frames", options->frames, "frames per measured run (the replay loops)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--set", options->overrides, "override one config key (VALUE in TOML syntax); repeatable")
      ->type_name("KEY=VALUE");
  command->add_option("--soak-seconds", options->soak_seconds, "then a looped replay this long, its memory every step (0: none)")
      ->type_name("S")
      ->check(CLI::NonNegativeNumber);
  cli::on_run(command, [options] { return run_pipeline_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
