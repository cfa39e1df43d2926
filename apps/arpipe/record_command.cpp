// arpipe record: a live camera's frames, as the camera sends them (MJPEG decoded), with their full
// metadata, into a format-v1 recording that replays in place of the camera.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "apps/arpipe/commands.h"
#include "capture/live/live_source.h"
#include "capture/recording/recording_writer.h"
#include "core/config/config.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

constexpr const char* kUsage =
    "usage: arpipe record --camera CAMERA --out DIR [--frames N | --seconds S] [--config FILE]\n"
    "                     [--width W --height H] [--fps F] [--format YUYV|NV12|RGB24|GREY|MJPG]\n"
    "                     [--exposure-us US] [--gain G] [--camera-model FILE] [--set KEY=VALUE]...\n"
    "  CAMERA: /dev/videoN, a /dev/v4l/by-id link, v4l2:PATH, or libcamera:ID|INDEX\n";

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// The --camera argument as config overrides.
bool camera_overrides(const std::string& camera, std::vector<std::string>& overrides) {
  if (camera.starts_with("libcamera:")) {
    overrides.push_back("source.type=\"libcamera\"");
    overrides.push_back("source.camera=" + toml_string(camera.substr(10)));
    return true;
  }
  const std::string path = camera.starts_with("v4l2:") ? camera.substr(5) : camera;
  if (path.empty()) return false;
  overrides.push_back("source.type=\"v4l2\"");
  overrides.push_back("source.device=" + toml_string(path));
  return true;
}

// A camera without a calibration still records: a nominal pinhole (about 53° across) stands in,
// and recording.json says so. `arpipe calib --recording DIR` replaces it.
CameraModel nominal_model(int width, int height) {
  return CameraModel::pinhole(width, width, (width - 1) / 2.0, (height - 1) / 2.0, width, height);
}

}  // namespace

int run_record(const Args& args) {
  std::string camera, out, config_path, model_path;
  int64_t frames = 0;
  double seconds = 0;
  std::vector<std::string> overrides;
  for (size_t i = 0; i < args.size(); ++i) {
    const bool has_value = i + 1 < args.size();
    const std::string& a = args[i];
    try {
      if (a == "--camera" && has_value) camera = args[++i];
      else if (a == "--out" && has_value) out = args[++i];
      else if (a == "--frames" && has_value) frames = std::stoll(args[++i]);
      else if (a == "--seconds" && has_value) seconds = std::stod(args[++i]);
      else if (a == "--config" && has_value) config_path = args[++i];
      else if (a == "--camera-model" && has_value) model_path = args[++i];
      else if (a == "--width" && has_value) overrides.push_back("source.width=" + std::to_string(std::stoi(args[++i])));
      else if (a == "--height" && has_value) overrides.push_back("source.height=" + std::to_string(std::stoi(args[++i])));
      else if (a == "--fps" && has_value) overrides.push_back(fmt::format("source.fps={}", std::stod(args[++i])));
      else if (a == "--format" && has_value) overrides.push_back("source.pixel_format=" + toml_string(args[++i]));
      else if (a == "--exposure-us" && has_value) overrides.push_back("source.exposure_us=" + std::to_string(std::stoll(args[++i])));
      else if (a == "--gain" && has_value) overrides.push_back(fmt::format("source.gain={}", std::stod(args[++i])));
      else if (a == "--set" && has_value) overrides.push_back(args[++i]);
      else {
        std::fputs(kUsage, stderr);
        return 2;
      }
    } catch (const std::exception&) {
      std::fprintf(stderr, "arpipe record: %s needs a number, got '%s'\n%s", a.c_str(), args[i].c_str(), kUsage);
      return 2;
    }
  }
  if (camera.empty() || out.empty() || (frames > 0 && seconds > 0) || frames < 0 || seconds < 0 ||
      !camera_overrides(camera, overrides)) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  if (!model_path.empty()) overrides.push_back("source.camera_model=" + toml_string(model_path));

  try {
    const Config config = config_path.empty() ? parse_config("", "(defaults)", overrides)
                                              : load_config(config_path, overrides);
    auto source = make_live_source(config.source);
    const StreamFormat& format = source->format();
    const CameraModel model = source->camera_model() ? *source->camera_model() : nominal_model(format.width, format.height);
    RecordingInfo info;
    info.pixel_format = format.format;
    info.width = format.width;
    info.height = format.height;
    info.source = fmt::format("arpipe record {} ({}{}); camera model: {}", source->describe(), format.camera_format,
                              format.camera_format == std::string(pixel_format_name(format.format)) ? "" : ", decoded",
                              source->camera_model() ? model_path : "nominal pinhole, not calibrated");
    RecordingWriter writer(out, info, model);

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const int64_t start = monotonic_now_ns();
    const int64_t end = seconds > 0 ? start + int64_t(seconds * 1e9) : 0;
    Frame frame;
    while (!g_stop) {
      if (frames > 0 && int64_t(writer.frames_written()) >= frames) break;
      if (end > 0 && monotonic_now_ns() >= end) break;
      if (source->next(frame) != SourceStatus::Frame) continue;
      if (frame.bytes_per_line != writer.info().bytes_per_line) {  // a driver with padded lines: repack
        Frame packed = Frame::allocate(frame.format, frame.width, frame.height);
        const size_t rows = image_bytes(frame.format, frame.width, frame.height, frame.bytes_per_line) / frame.bytes_per_line;
        for (size_t r = 0; r < rows; ++r)
          std::copy_n(frame.data.data() + r * frame.bytes_per_line, packed.bytes_per_line,
                      packed.data.data() + r * packed.bytes_per_line);
        packed.meta = frame.meta;
        frame = std::move(packed);
      }
      writer.append(frame);
    }
    writer.flush();
    const LiveCounters counters = source->counters();
    fmt::print("recorded {} frames to {} ({:.1f} s); {}\n", writer.frames_written(), out,
               double(monotonic_now_ns() - start) * 1e-9, LiveSource::describe(counters));
    return 0;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 2;
  }
}

}  // namespace arpipe
