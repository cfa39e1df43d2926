// arpipe record: a live camera's frames, as the camera sends them (MJPEG decoded), with their full
// metadata, into a format-v1 recording that replays in place of the camera.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "capture/live/live_source.h"
#include "capture/recording/recording_writer.h"
#include "core/config/config.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// The --camera argument as config overrides.
bool camera_overrides(const std::string& camera, std::vector<std::string>& overrides) {
  if (camera.starts_with("libcamera:")) {
    overrides.push_back("source.type=" +
                        toml_string(std::string(choice_name(kSourceTypeNames, SourceType::Libcamera))));
    overrides.push_back("source.camera=" + toml_string(camera.substr(10)));
    return true;
  }
  const std::string path = camera.starts_with("v4l2:") ? camera.substr(5) : camera;
  if (path.empty()) return false;
  overrides.push_back("source.type=" + toml_string(std::string(choice_name(kSourceTypeNames, SourceType::V4l2))));
  overrides.push_back("source.device=" + toml_string(path));
  return true;
}

// A camera without a calibration still records: a nominal pinhole (about 53° across) stands in,
// and recording.json says so. `arpipe calib --recording DIR` replaces it.
CameraModel nominal_model(int width, int height) {
  return CameraModel::pinhole(width, width, (width - 1) / 2.0, (height - 1) / 2.0, width, height);
}

struct RecordOptions {
  std::string camera, out, config_path, model_path;
  int64_t frames = 0;
  double seconds = 0;
  std::vector<std::string> source_overrides;  // --width, --fps, ...
  std::vector<std::string> overrides;         // --set
};

int record(RecordOptions options) {
  const std::string& camera = options.camera;
  const std::string& out = options.out;
  const std::string& config_path = options.config_path;
  const std::string& model_path = options.model_path;
  const int64_t frames = options.frames;
  const double seconds = options.seconds;
  std::vector<std::string> overrides = options.source_overrides;
  overrides.insert(overrides.end(), options.overrides.begin(), options.overrides.end());
  if (!camera_overrides(camera, overrides)) cli::usage_error("--camera: expected /dev/videoN, v4l2:PATH or libcamera:ID");
  if (!model_path.empty()) overrides.push_back("source.camera_model=" + toml_string(model_path));

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
}

}  // namespace

void add_record_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand("record", "record a live camera with its exposure metadata");
  auto options = std::make_shared<RecordOptions>();
  command->add_option("--camera", options->camera,
                      "/dev/videoN, a /dev/v4l/by-id link, v4l2:PATH, or libcamera:ID|INDEX")
      ->type_name("CAMERA")
      ->required();
  command->add_option("--out", options->out, "where the recording goes")->type_name("DIR")->required();
  CLI::Option* frames = command->add_option("--frames", options->frames, "stop after N frames")
                            ->check(CLI::NonNegativeNumber)
                            ->default_str("until stopped");
  CLI::Option* seconds = command->add_option("--seconds", options->seconds, "stop after S seconds")
                             ->type_name("S")
                             ->check(CLI::NonNegativeNumber)
                             ->default_str("until stopped");
  frames->excludes(seconds);
  command->add_option("--config", options->config_path, "the config whose [source] section to start from")
      ->type_name("FILE");
  command->add_option("--camera-model", options->model_path, "the camera's calibration (default: a nominal pinhole)")
      ->type_name("FILE");
  // The camera settings become overrides of [source], in this order; --set comes after them.
  const auto source_key = [command, options](const char* option, const char* key, const char* help, bool quoted) {
    return command->add_option_function<std::string>(
        option,
        [options, key, quoted](const std::string& value) {
          options->source_overrides.push_back(fmt::format("source.{}={}", key, quoted ? toml_string(value) : value));
        },
        help);
  };
  source_key("--width", "width", "frame width", false)->type_name("W")->check(CLI::PositiveNumber);
  source_key("--height", "height", "frame height", false)->type_name("H")->check(CLI::PositiveNumber);
  source_key("--fps", "fps", "frame rate", false)->type_name("F")->check(CLI::PositiveNumber);
  source_key("--format", "pixel_format", "YUYV, NV12, RGB24, GREY or MJPG", true)->type_name("F");
  source_key("--exposure-us", "exposure_us", "a fixed exposure in microseconds", false)
      ->type_name("US")
      ->check(CLI::PositiveNumber);
  source_key("--gain", "gain", "a fixed analogue gain", false)->type_name("G")->check(CLI::PositiveNumber);
  command->add_option("--set", options->overrides, "override one config key (VALUE in TOML syntax); repeatable")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  cli::on_run(command, [options] { return record(*options); }, cli::Failure{.status = 2});
}

}  // namespace arpipe
