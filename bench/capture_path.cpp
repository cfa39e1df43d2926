// The V4L2 capture path's cost per frame against a plain memory copy of the same frame, and the
// latency from a frame's exposure end to its hand-off, measured through the V4L2 stand-in
// (tests/v4l2_standin) serving a recording. `arpipe bench capture-path [RECORDING] [--frames N]`.
// The stand-in must come before libc in the process: arpipe runs itself again with it preloaded.
//
// Per format the camera sends: the source's own work per frame, split into the buffer exchange
// (DQBUF + QBUF: a syscall pair on hardware; through the stand-in, a function call plus whatever
// frame it prepares then) and the copy or decode into the Frame with its metadata; the hand-off
// into the pipeline's queue; and a memcpy of the same bytes, timed in the same run.
#include <dlfcn.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "capture/live/live_source.h"
#include "capture/recording/recording_reader.h"
#include "capture/raw_colour_source.h"
#include "capture/recording/recording_copy.h"
#include "core/image/pixel_convert.h"
#include "core/system/frame_memory.h"
#include "core/log.h"
#include "core/pipeline/bounded_queue.h"
#include "core/pipeline/frame_pool.h"
#include "core/pipeline/monotonic_clock.h"
#include "tests/v4l2_standin/v4l2_standin.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDevice = "/dev/video-arpipe-bench";

// The stand-in's C API, found in the process once the library is preloaded (null until then).
struct Standin {
  decltype(&arpipe_v4l2_standin_load) load = nullptr;
  decltype(&arpipe_v4l2_standin_unload) unload = nullptr;
};
Standin g_standin;

bool find_standin() {
  g_standin.load = reinterpret_cast<decltype(&arpipe_v4l2_standin_load)>(dlsym(RTLD_DEFAULT, "arpipe_v4l2_standin_load"));
  g_standin.unload =
      reinterpret_cast<decltype(&arpipe_v4l2_standin_unload)>(dlsym(RTLD_DEFAULT, "arpipe_v4l2_standin_unload"));
  return g_standin.load != nullptr && g_standin.unload != nullptr;
}

void load_standin(const fs::path& dir, const fs::path& recording, const std::string& keys) {
  const fs::path config = dir / "standin.toml";
  std::ofstream(config) << "[[device]]\npath = \"" << kDevice << "\"\nrecording = \"" << recording.string() << "\"\n"
                        << keys << "\n";
  char error[512] = {};
  if (g_standin.load(config.c_str(), error, sizeof error) != 0)
    throw std::runtime_error(fmt::format("stand-in: {}", error));
}

SourceConfig source_config(CaptureFormat format) {
  SourceConfig c;
  c.type = SourceType::V4l2;
  c.device = kDevice;
  c.pixel_format = format;
  return c;
}

// A memcpy of a frame of `bytes` into a buffer of its own: ns per copy. The source rotates over
// four frames as the driver's four buffers do, so the copy, like the capture path's, does not
// find its frame already in the cache.
double memcpy_ns(size_t bytes, int repeats) {
  std::vector<std::vector<uint8_t>> from(4, std::vector<uint8_t>(bytes, 1));
  std::vector<uint8_t> to(bytes);
  for (auto& f : from) std::memcpy(to.data(), f.data(), bytes);  // fault every page in first
  const int64_t start = monotonic_now_ns();
  for (int i = 0; i < repeats; ++i) std::memcpy(to.data(), from[size_t(i) % 4].data(), bytes);
  const int64_t end = monotonic_now_ns();
  if (to[size_t(repeats) % bytes] == 42) std::puts("");  // keep the copies
  return double(end - start) / repeats;
}

struct Row {
  std::string format;
  size_t camera_bytes = 0, frame_bytes = 0;
  double dequeue_us = 0, convert_us = 0, handoff_us = 0, memcpy_us = 0;
  double page_faults = 0;  // minor page faults per frame, the whole process (stand-in included)
  double copies = 0, allocations = 0;  // per frame, as the source counts them
};

long minor_faults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// What the stand-in sends (its name for it, and its buffer type) and what the source asks for.
struct Served {
  std::string standin_format;
  std::string buffer_type;
  CaptureFormat asked;
};

Row measure(const fs::path& dir, const fs::path& recording, const Served& served, int frames) {
  load_standin(dir, recording,
               fmt::format("pacing = \"fast\"\nformats = [\"{}\"]\nbuffer_type = \"{}\"\nloop = true",
                           served.standin_format, served.buffer_type));
  auto source = make_live_source(source_config(served.asked));
  BoundedQueue<Frame> queue(4, OverflowPolicy::DropOldest);
  Row row;
  row.format = source->format().camera_format + (served.buffer_type == "mplane" ? " (multi-planar)" : "");
  for (int i = 0; i < 10; ++i) {  // warm-up: first buffers, allocator, decoder
    Frame frame;
    while (source->next(frame) != SourceStatus::Frame) {
    }
  }
  const StreamCounters before = source->counters().stream;
  const long faults_before = minor_faults();
  int64_t handoff = 0;
  FramePool pool;  // as the pipeline does: the memory of a frame the sinks are done with comes back
  for (int i = 0; i < frames; ++i) {
    Frame frame;
    frame.data = pool.take();
    while (source->next(frame) != SourceStatus::Frame) {
    }
    row.frame_bytes = frame.data.size();
    const int64_t t0 = monotonic_now_ns();
    queue.push(std::move(frame));  // what the capture thread does with it; the pop is the next thread's
    const int64_t t1 = monotonic_now_ns();
    handoff += t1 - t0;
    if (auto done = queue.pop()) pool.give(std::move(done->data));
  }
  const StreamCounters after = source->counters().stream;
  row.page_faults = double(minor_faults() - faults_before) / frames;
  row.dequeue_us = double(after.dequeue_ns - before.dequeue_ns) / frames * 1e-3;
  row.convert_us = double(after.convert_ns - before.convert_ns) / frames * 1e-3;
  row.handoff_us = double(handoff) / frames * 1e-3;
  row.copies = double(after.copies - before.copies) / frames;
  row.allocations = double(after.frame_allocations - before.frame_allocations) / frames;
  row.memcpy_us = memcpy_ns(row.frame_bytes, frames) * 1e-3;
  g_standin.unload();
  return row;
}

// Real-time pacing with live timestamps: each frame falls due at its exposure end, on this clock.
std::vector<double> latencies_ms(const fs::path& dir, const fs::path& recording, int frames) {
  load_standin(dir, recording, "pacing = \"realtime\"\ntimestamps = \"live\"\ntimestamp_source = \"eof\"\nloop = true");
  auto source = make_live_source(source_config(CaptureFormat::Auto));
  std::vector<double> ms;
  while (int(ms.size()) < frames) {
    Frame frame;
    if (source->next(frame) != SourceStatus::Frame) continue;
    const int64_t handed_off = monotonic_now_ns();
    const auto& m = frame.meta;
    ms.push_back(double(handed_off - (m.exposure_start_ns + m.exposure_ns + m.readout_ns)) * 1e-6);
  }
  g_standin.unload();
  std::sort(ms.begin(), ms.end());
  return ms;
}

// The recording's first frames in another format, so that the stand-in serves them as they are:
// converting them as it serves would run beside the copy being measured and share the caches with it.
fs::path format_copy(const fs::path& recording, const fs::path& dir, PixelFormat format, size_t frames) {
  const fs::path out = dir / std::string(pixel_format_name(format));
  fs::remove_all(out);
  copy_recording_as(recording, out, format, frames, "bench capture-path: a copy in another format");
  return out;
}

// ms to develop one raw frame into RGB24 (black level, white balance, demosaic, sRGB), the mean of `repeats`.
double develop_ms(const fs::path& bayer, int repeats) {
  const RecordingReader reader(bayer);
  Frame raw;
  reader.read(0, raw);
  std::vector<uint8_t> rgb;
  to_rgb24(raw, rgb);  // warm-up
  const int64_t start = monotonic_now_ns();
  for (int i = 0; i < repeats; ++i) to_rgb24(raw, rgb);
  return double(monotonic_now_ns() - start) * 1e-6 / repeats;
}

// ms to measure one raw frame's grey-world gains as it leaves the source (a camera that says none:
// capture/raw_colour_source.h), the mean of `repeats`.
double grey_world_ms(const fs::path& bayer, int repeats) {
  const RecordingReader reader(bayer);
  Frame raw;
  reader.read(0, raw);
  RawColourResolver resolver{RawColourConfig{}};
  raw.meta.raw = RawColour{};
  resolver.resolve(raw);  // warm-up (and its one log line)
  const int64_t start = monotonic_now_ns();
  for (int i = 0; i < repeats; ++i) {
    raw.meta.raw = RawColour{};
    resolver.resolve(raw);
  }
  return double(monotonic_now_ns() - start) * 1e-6 / repeats;
}

struct CapturePathOptions {
  fs::path recording = fs::path(ARPIPE_BINARY_DIR) / "default-capture";
  int frames = 300;
  fs::path standin = fs::path(ARPIPE_BINARY_DIR) / "tests" / "v4l2_standin" / "libarpipe-v4l2-standin.so";
};

// This arpipe again, the same benchmark, with the stand-in preloaded (LD_PRELOAD): its open, ioctl,
// mmap and poll then come before libc's. Returns only when that fails.
int run_again_with_standin(const CapturePathOptions& options) {
  if (std::getenv("ARPIPE_BENCH_STANDIN_PRELOADED") != nullptr) {
    fmt::print(stderr, "arpipe bench capture-path: {} was preloaded but its API is not in the process\n",
               options.standin.string());
    return 1;
  }
  if (!fs::exists(options.standin)) {
    fmt::print(stderr, "arpipe bench capture-path: no V4L2 stand-in at {} (it is built with the tests: "
               "cmake --build build --target arpipe_v4l2_standin; or pass --standin LIB)\n", options.standin.string());
    return 1;
  }
  const std::string preload = options.standin.string();
  const char* before = std::getenv("LD_PRELOAD");
  setenv("LD_PRELOAD", before && *before ? (preload + ":" + before).c_str() : preload.c_str(), 1);
  setenv("ARPIPE_BENCH_STANDIN_PRELOADED", "1", 1);
  const std::vector<std::string> args{"arpipe", "bench", "capture-path", options.recording.string(), "--frames",
                                      std::to_string(options.frames), "--standin", preload};
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv("/proc/self/exe", argv.data());
  fmt::print(stderr, "arpipe bench capture-path: cannot run arpipe again: {}\n", std::strerror(errno));
  return 1;
}

int run_capture_path_benchmark(const CapturePathOptions& options) {
  if (!find_standin()) return run_again_with_standin(options);
  log::set_max_level(log::Level::Warning);
  const fs::path& recording = options.recording;
  const int frames = options.frames;
  try {
    const fs::path dir = fs::temp_directory_path() / fmt::format("arpipe-capture-path-{}", getpid());
    fs::create_directories(dir);
    const RecordingReader reader(recording);
    fmt::print("capture path through the V4L2 stand-in: {} ({}x{} {}), {} frames per format\n\n", recording.string(),
               reader.info().width, reader.info().height, pixel_format_name(reader.info().pixel_format), frames);
    fmt::print("| camera sends | frame bytes | DQBUF+QBUF µs | copy/decode µs | hand-off µs | memcpy µs | "
               "(copy/decode + hand-off) / memcpy | page faults/frame | copies/frame | allocations/frame |\n"
               "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const Served served[] = {{"YUYV", "single", CaptureFormat::YUYV},    {"GREY", "single", CaptureFormat::GREY},
                             {"RGB24", "single", CaptureFormat::RGB24},  {"NV12", "single", CaptureFormat::NV12},
                             {"NV12M", "mplane", CaptureFormat::NV12M},  {"UYVY", "single", CaptureFormat::UYVY},
                             {"NV21", "single", CaptureFormat::NV21},    {"YU12", "single", CaptureFormat::YUV420},
                             {"YUV420M", "mplane", CaptureFormat::YUV420M}, {"NV16", "single", CaptureFormat::NV16},
                             {"MJPG", "single", CaptureFormat::MJPG}};
    // The pipeline's own formats and Bayer served as recorded; the others reordered by the stand-in.
    std::vector<std::pair<Served, fs::path>> rows;
    for (const Served& format : served) {
      const auto own = frame_format(format.asked);
      if (own && format.buffer_type == "single" && *own != reader.info().pixel_format)
        rows.push_back({Served{"native", "single", format.asked}, format_copy(recording, dir, *own, 30)});
      else
        rows.push_back({format, recording});
    }
    const fs::path bayer = format_copy(recording, dir, PixelFormat::SGRBG10P, 30);
    rows.insert(rows.end() - 1, {Served{"native", "single", CaptureFormat::SGRBG10P}, bayer});
    for (const auto& [format, from] : rows) {
      const Row r = measure(dir, from, format, frames);
      fmt::print("| {} | {} | {:.1f} | {:.1f} | {:.2f} | {:.1f} | {:.2f} | {:.0f} | {:.2f} | {:.2f} |\n", r.format,
                 r.frame_bytes, r.dequeue_us, r.convert_us, r.handoff_us, r.memcpy_us,
                 (r.convert_us + r.handoff_us) / r.memcpy_us, r.page_faults, r.copies, r.allocations);
    }
    fmt::print("\nSGRBG10P developed to RGB24 where the pixels are read (black level, white balance, OpenCV's "
               "edge-aware demosaic, sRGB; core/image/bayer.h): {:.2f} ms a frame\n", develop_ms(bayer, 20));
    fmt::print("SGRBG10P grey-world gains measured as the frame leaves the source, for a camera that says none "
               "(capture/raw_colour_source.h): {:.2f} ms a frame\n", grey_world_ms(bayer, 20));
    const auto ms = latencies_ms(dir, recording, std::min(frames, 90));
    const auto at = [&](double q) { return ms[std::min(ms.size() - 1, size_t(q * double(ms.size())))]; };
    fmt::print("\nexposure end to hand-off (real-time pacing, {} frames): median {:.3f} ms, p90 {:.3f} ms, max {:.3f} ms\n",
               ms.size(), at(0.5), at(0.9), ms.back());
    fs::remove_all(dir);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bench capture-path: %s\n", e.what());
    return 1;
  }
}

}  // namespace

void add_capture_path_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "capture-path", "the V4L2 capture path's cost per frame against a memcpy, and its latency, through the stand-in");
  auto options = std::make_shared<CapturePathOptions>();
  command->add_option("RECORDING", options->recording, "the recording the stand-in serves");
  command->add_option("--frames", options->frames, "frames per format")->check(CLI::Range(10, 1000000));
  command->add_option("--standin", options->standin, "the V4L2 stand-in library (docs/V4L2_STANDIN.md)")->type_name("LIB");
  cli::on_run(command, [options] { return run_capture_path_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
