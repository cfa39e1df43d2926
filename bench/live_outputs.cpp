// Benchmark: what the live HTTP outputs cost and how late their frames are. The config (default:
// the embedded default) replayed as fast as it goes with 0, 1 and 8 MJPEG clients reading
// /stream.mjpg (frames/s against no client; JPEG encodes and their time, once per frame whatever
// the clients), the encoding alone on a composited 640x480 frame, and a real-time replay with one
// client: end-to-end latency from the end of each exposure (a replay: the frame's arrival) to the
// client's receipt of the frame's last byte, p50/p95/p99, against the frame interval.
// `arpipe bench latency [--config FILE] [--capture DIR] [--frames N]` prints markdown tables.
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "apps/cli/command_line.h"
#include "apps/common/pipeline_assembly.h"
#include "bench/benchmarks.h"
#include "bench/http_client.h"
#include "capture/sinks/http/jpeg_encoder.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace fs = std::filesystem;

namespace arpipe {
namespace {

struct LatencyOptions {
  std::string config = "configs/arpipe.toml";
  std::string capture;  // empty: the config's source
  int64_t frames = 300;
  std::string work = "build/bench-latency";
};

Config live_config(const LatencyOptions& options, const fs::path& socket, bool real_time, int64_t frames) {
  std::vector<std::string> overrides;
  if (!options.capture.empty()) overrides.push_back(fmt::format("source.path=\"{}\"", options.capture));
  for (const char* o : {"source.loop=true", "sinks.png.enabled=false", "sinks.y4m.enabled=false",
                        "sinks.recording.enabled=false", "sinks.results.enabled=false", "pipeline.log_level=\"warning\""})
    overrides.push_back(o);
  overrides.push_back(real_time ? "source.pacing=\"timestamps\"" : "source.pacing=\"fast\"");
  overrides.push_back(fmt::format("pipeline.max_frames={}", frames));
  overrides.push_back(fmt::format("sinks.http.listen=\"{}\"", socket.string()));
  return load_config(options.config, overrides);
}

// A client reading /stream.mjpg until the server ends it, keeping each camera frame's latency at
// its receipt (the daemon's CLOCK_MONOTONIC is this process's).
struct StreamReader {
  std::thread thread;
  std::vector<double> latency_ms;
  std::atomic<bool> connected{false};
};

void read_stream(const fs::path& socket, StreamReader& reader) {
  HttpConnection connection(socket.string(), std::chrono::seconds(30));
  if (!connection.send_all("GET /stream.mjpg HTTP/1.1\r\nHost: bench\r\n\r\n") || !connection.read_head()) return;
  reader.connected = true;
  while (std::optional<HttpResponse> part = connection.read_part()) {
    const auto origin = part->headers.find("x-arpipe-origin-ns");
    if (origin != part->headers.end()) reader.latency_ms.push_back(double(monotonic_now_ns() - std::stoll(origin->second)) * 1e-6);
  }
}

struct LiveRun {
  int clients = 0;
  double fps = 0;
  uint64_t encodes = 0;
  double encode_ms = 0;
  double to_sinks_ms = 0;  // the pipeline's own latency to the sinks, mean
  std::vector<double> latency_ms;  // every client's, together
};

LiveRun run_live(const LatencyOptions& options, int clients, bool real_time, int64_t frames) {
  const fs::path socket = fs::absolute(options.work) / "http.sock";
  fs::create_directories(socket.parent_path());
  std::unique_ptr<PipelineRunner> runner = assemble_pipeline(live_config(options, socket, real_time, frames));
  runner->start();  // the HTTP sink listens from here on
  std::vector<std::unique_ptr<StreamReader>> readers;
  for (int c = 0; c < clients; ++c) {
    readers.push_back(std::make_unique<StreamReader>());
    StreamReader& reader = *readers.back();
    reader.thread = std::thread([&socket, &reader] { read_stream(socket, reader); });
  }
  // The HTTP counters, read while the sink lives (it goes with the run's end).
  LiveRun run;
  run.clients = clients;
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    while (!done) {
      if (std::optional<HttpResponse> state = http_request(socket.string(), "/state")) {
        const auto j = nlohmann::json::parse(state->body, nullptr, false);
        if (!j.is_discarded()) {
          run.encodes = j["http"]["jpeg_encodes"].get<uint64_t>();
          run.encode_ms = j["http"]["jpeg_encode_ms_mean"].get<double>();
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  runner->wait();
  done = true;
  watcher.join();
  const PipelineMetrics metrics = runner->metrics();
  runner.reset();  // the HTTP sink goes, and with it the streams: the readers end
  for (auto& reader : readers) {
    reader->thread.join();
    run.latency_ms.insert(run.latency_ms.end(), reader->latency_ms.begin(), reader->latency_ms.end());
  }
  run.fps = metrics.fps();
  run.to_sinks_ms = metrics.latency_seconds.count() ? metrics.latency_seconds.sum() / double(metrics.latency_seconds.count()) * 1e3 : 0;
  return run;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(values.size() - 1, size_t(p / 100.0 * double(values.size())));
  return values[i];
}

// The encoding alone: a 640x480 picture of camera-like content (the default capture's composited
// frame would do; a smooth gradient with noise stands in, JPEG's cost barely depends on it).
double encode_alone_ms(int repeats) {
  Frame frame = Frame::allocate(PixelFormat::RGB24, 640, 480);
  uint32_t state = 12345;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x)
      for (int c = 0; c < 3; ++c) {
        state = state * 1664525u + 1013904223u;
        frame.data[size_t(y) * frame.bytes_per_line + size_t(x) * 3 + size_t(c)] = uint8_t((x / 3 + y / 4 + c * 40) % 200 + (state >> 29));
      }
  JpegEncoder encoder;
  encoder.encode(frame, 85);  // warm-up
  const int64_t start = monotonic_now_ns();
  for (int i = 0; i < repeats; ++i) encoder.encode(frame, 85);
  return double(monotonic_now_ns() - start) * 1e-6 / repeats;
}

int run_latency_benchmark(const LatencyOptions& options) {
  log::set_max_level(log::Level::Warning);
  const Config probe = live_config(options, fs::absolute(options.work) / "http.sock", false, 1);
  fmt::print("config {}, capture {}, {} frames per run; {:%Y-%m-%d %H:%M} UTC\n\n", options.config, probe.source.path.string(),
             options.frames, fmt::gmtime(std::time(nullptr)));

  // Three rounds, the client counts interleaved, each count's median frames/s: this machine's
  // run-to-run noise (10-15 % between two runs of the same config) is larger than the effect.
  fmt::print("| run | MJPEG clients | frames/s, median of 3 (each run) | against no client | JPEG encodes | encode ms/frame |\n"
             "|---|---:|---:|---:|---:|---:|\n");
  run_live(options, 0, /*real_time=*/false, 30);  // warm-up, not shown: shader JIT, PRT cache, page cache
  constexpr int kRounds = 3;
  const std::vector<int> client_counts{0, 1, 8};
  std::vector<std::vector<LiveRun>> runs(client_counts.size());
  for (int round = 0; round < kRounds; ++round)
    for (size_t c = 0; c < client_counts.size(); ++c) runs[c].push_back(run_live(options, client_counts[c], false, options.frames));
  const auto median_fps = [](std::vector<LiveRun> r) {
    std::sort(r.begin(), r.end(), [](const LiveRun& a, const LiveRun& b) { return a.fps < b.fps; });
    return r[r.size() / 2];
  };
  const double base_fps = median_fps(runs[0]).fps;
  for (size_t c = 0; c < client_counts.size(); ++c) {
    const LiveRun median = median_fps(runs[c]);
    std::string each;
    for (const LiveRun& r : runs[c]) each += fmt::format("{}{:.1f}", each.empty() ? "" : ", ", r.fps);
    fmt::print("| fast replay | {} | {:.1f} ({}) | {:.3f} | {} | {:.2f} |\n", client_counts[c], median.fps, each,
               base_fps > 0 ? median.fps / base_fps : 0.0, median.encodes, median.encode_ms);
  }
  fmt::print("\nJPEG encoding alone (libjpeg-turbo, 640x480, quality 85, 4:2:0): {:.2f} ms per frame on one core\n\n",
             encode_alone_ms(200));

  // The steady state: the first 30 frames of this run, while its new GL context compiles its
  // shaders, are left out of the percentiles (not of the mean to the sinks, from the metrics).
  LiveRun real_time = run_live(options, 1, /*real_time=*/true, options.frames + 30);
  if (real_time.latency_ms.size() > 30) real_time.latency_ms.erase(real_time.latency_ms.begin(), real_time.latency_ms.begin() + 30);
  const std::optional<int64_t> interval_ns = make_source(probe)->frame_interval_ns();
  const double interval_ms = interval_ns ? double(*interval_ns) * 1e-6 : 0;
  fmt::print("| real-time replay, 1 client | frames | p50 ms | p95 ms | p99 ms | to the sinks, mean ms | frame interval ms | encode ms |\n"
             "|---|---:|---:|---:|---:|---:|---:|---:|\n");
  fmt::print("| end of exposure (replay: arrival) to the client's last byte | {} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.2f} |\n",
             real_time.latency_ms.size(), percentile(real_time.latency_ms, 50), percentile(real_time.latency_ms, 95),
             percentile(real_time.latency_ms, 99), real_time.to_sinks_ms, interval_ms, real_time.encode_ms);
  return 0;
}

}  // namespace

void add_latency_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "latency", "live outputs: MJPEG cost against the number of clients, and end-to-end latency on a real-time replay");
  auto options = std::make_shared<LatencyOptions>();
  command->add_option("--config", options->config, "the config to run")->type_name("FILE")->capture_default_str();
  command->add_option("--capture", options->capture, "replay this capture instead of the config's source")->type_name("DIR");
  command->add_option("--frames", options->frames, "frames per run")->check(CLI::PositiveNumber)->capture_default_str();
  command->add_option("--work", options->work, "where the HTTP socket goes")->type_name("DIR")->capture_default_str();
  cli::on_run(command, [options] { return run_latency_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
