#include "capture/sinks/recording_sink.h"

#include <fmt/format.h>

#include <stdexcept>

#include "capture/recording/recording_format.h"
#include "capture/recording/recording_writer.h"
#include "capture/sinks/output_path.h"
#include "core/log.h"

namespace arpipe {

namespace {

constexpr const char* kConfigKey = "sinks.recording.path";

// Setup fails here rather than at the first frame: a recording is never overwritten (nor appended
// to), and a daemon that starts must be able to record.
void check_holds_no_recording(const std::filesystem::path& dir) {
  std::error_code ec;
  const auto status = std::filesystem::status(dir, ec);
  if (!std::filesystem::exists(status)) return;
  if (!std::filesystem::is_directory(status))
    throw std::runtime_error(fmt::format("{} (config {}): exists and is not a directory", dir.string(), kConfigKey));
  for (const char* part : {kRecordingInfoFile, kRecordingCameraModelFile, kRecordingFramesFile, kRecordingMetadataFile,
                           kRecordingGroundTruthFile})
    if (std::filesystem::exists(dir / part, ec))
      throw std::runtime_error(fmt::format(
          "{} (config {}): already holds a recording ({} exists); a recording is never overwritten: move it away or "
          "set another path",
          dir.string(), kConfigKey, part));
}

}  // namespace

RecordingSink::RecordingSink(const RecordingSinkConfig& config)
    : config_(config), outage_(config.path.string(), "the recording ends at its last complete frame") {
  create_parent_directory(config_.path, kConfigKey);
  check_holds_no_recording(config_.path);
}

RecordingSink::~RecordingSink() { outage_.report_at_end(); }

std::string RecordingSink::describe() const { return "recording:" + config_.path.string(); }

void RecordingSink::consume(const FrameContext& ctx) noexcept {
  if (ctx.output.empty() || creation_failed_) return;
  if (!writer_) {
    try {
      // The lens of the output picture: the camera's, or its pinhole core when render.lens undistorts.
      const auto& model = ctx.output_camera_model ? ctx.output_camera_model : ctx.camera_model;
      if (!model) throw RecordingError("no camera model for the recording");
      RecordingInfo info;
      info.pixel_format = ctx.output.format;
      info.width = ctx.output.width;
      info.height = ctx.output.height;
      info.bytes_per_line = ctx.output.bytes_per_line;
      info.source = "arpiped composited output";
      writer_ = std::make_unique<RecordingWriter>(config_.path, info, *model);
    } catch (const std::exception& e) {
      creation_failed_ = true;
      log::error("{}: cannot create the recording at frame {}: {}; the run goes on without it", config_.path.string(),
                 ctx.input_index, e.what());
      return;
    }
  }
  // The writer cuts a failed append back to its last complete frame, so a later one may retry.
  try {
    Frame frame = ctx.output;
    frame.meta = ctx.camera.meta;
    writer_->append(frame);
  } catch (const std::exception& e) {
    outage_.failed(ctx.input_index, e.what());
    return;
  }
  outage_.succeeded(ctx.input_index);
}

void RecordingSink::flush() noexcept {
  try {
    if (writer_) writer_->flush();
  } catch (const std::exception& e) {
    log::error("{}: {}", config_.path.string(), e.what());
  }
}

}  // namespace arpipe
