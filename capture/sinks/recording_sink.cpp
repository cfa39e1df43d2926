#include "capture/sinks/recording_sink.h"

#include "capture/recording/recording_writer.h"
#include "capture/sinks/output_path.h"
#include "core/log.h"

namespace arpipe {

RecordingSink::RecordingSink(const RecordingSinkConfig& config) : config_(config) {
  create_parent_directory(config_.path, "sinks.recording.path");
}

RecordingSink::~RecordingSink() = default;

std::string RecordingSink::describe() const { return "recording:" + config_.path.string(); }

void RecordingSink::consume(const FrameContext& ctx) noexcept {
  if (ctx.output.empty() || failures_ > 0) return;  // a failed recording stays stopped, the rest goes on
  try {
    if (!writer_) {
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
    }
    Frame frame = ctx.output;
    frame.meta = ctx.camera.meta;
    writer_->append(frame);
  } catch (const std::exception& e) {
    ++failures_;
    log::error("{}: recording stopped at frame {}: {}", config_.path.string(), ctx.input_index, e.what());
  }
}

void RecordingSink::flush() noexcept {
  try {
    if (writer_) writer_->flush();
  } catch (const std::exception& e) {
    log::error("{}: {}", config_.path.string(), e.what());
  }
}

}  // namespace arpipe
