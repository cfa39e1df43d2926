// Recording writer (format v1): payload first, then ground truth, then the metadata line that
// commits the frame, each at a tracked offset so that a failed append leaves nothing half-committed.
#include "capture/recording/recording_writer.h"

#include <fmt/format.h>
#include <zlib.h>

#include <ctime>
#include <system_error>

#include "capture/recording/posix_file.h"
#include "capture/recording/recording_json.h"
#include "core/log.h"

namespace arpipe {

namespace fs = std::filesystem;

namespace {

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

RecordingInfo completed_info(const fs::path& dir, RecordingInfo info, const CameraModel& model) {
  if (info.version != kRecordingFormatVersion)
    throw RecordingError(fmt::format("{}: this build writes recording format version {} only, not {}", dir.string(),
                                     kRecordingFormatVersion, info.version));
  if (auto problem = check_image_size(info.pixel_format, info.width, info.height))
    throw RecordingError(fmt::format("{}: {}", dir.string(), *problem));
  const size_t min_stride = min_bytes_per_line(info.pixel_format, info.width);
  if (info.bytes_per_line == 0) info.bytes_per_line = min_stride;
  if (info.bytes_per_line < min_stride)
    throw RecordingError(fmt::format("{}: bytes_per_line {} is below the {} that {} pixels of {} need", dir.string(),
                                     info.bytes_per_line, min_stride, info.width,
                                     pixel_format_name(info.pixel_format)));
  if (model.width() != info.width || model.height() != info.height)
    throw RecordingError(fmt::format("{}: the camera model's imager size {}x{} differs from the frame size {}x{}",
                                     dir.string(), model.width(), model.height(), info.width, info.height));
  if (info.created_utc.empty()) info.created_utc = utc_now_iso8601();
  return info;
}

}  // namespace

struct RecordingWriter::Impl {
  fs::path dir;
  RecordingInfo info;
  recording_json::FileNames files;
  size_t frame_bytes = 0;
  PosixFile frames;
  PosixFile metadata;
  PosixFile ground_truth;  // opened with the first frame that has ground truth
  bool has_ground_truth = false;
  uint64_t frames_written = 0;
  uint64_t frames_end = 0;  // committed lengths: a failed append is cut back to these
  uint64_t metadata_end = 0;
  uint64_t ground_truth_end = 0;
  bool unflushed = true;

  void write_info() {
    const fs::path final_path = dir / kRecordingInfoFile;
    const fs::path temp_path = dir / (std::string(kRecordingInfoFile) + ".tmp");
    const std::string text = recording_json::encode_info(info, files);
    {
      PosixFile temp(temp_path, PosixFile::Mode::CreateNew);
      temp.write_at(0, text.data(), text.size());
      temp.sync();
    }
    // Renamed into place last, so a directory with recording.json always has every other part.
    fs::rename(temp_path, final_path);
    PosixFile::sync_directory(dir);
  }

  void cut_back_after_failure() noexcept {
    try {
      frames.truncate(frames_end);
      metadata.truncate(metadata_end);
      if (ground_truth.is_open()) ground_truth.truncate(ground_truth_end);
    } catch (const std::exception& e) {
      log::warn("recording {}: could not cut back a failed append: {}", dir.string(), e.what());
    }
  }
};

RecordingWriter::RecordingWriter(const fs::path& dir, const RecordingInfo& info, const CameraModel& model)
    : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.dir = dir;
  w.info = completed_info(dir, info, model);
  w.frame_bytes = image_bytes(w.info.pixel_format, w.info.width, w.info.height, w.info.bytes_per_line);
  try {
    fs::create_directories(dir);
    if (fs::exists(dir / kRecordingInfoFile))
      throw RecordingError(fmt::format("{}: already holds a recording ({} exists); refusing to overwrite it",
                                       dir.string(), kRecordingInfoFile));
    for (const std::string& part : {w.files.camera_model, w.files.frames, w.files.metadata, w.files.ground_truth})
      if (fs::exists(dir / part))
        throw RecordingError(fmt::format("{}: exists already; refusing to overwrite it", (dir / part).string()));
    const fs::path model_path = dir / w.files.camera_model;
    model.save(model_path);
    w.frames = PosixFile(dir / w.files.frames, PosixFile::Mode::CreateNew);
    w.metadata = PosixFile(dir / w.files.metadata, PosixFile::Mode::CreateNew);
    w.write_info();
  } catch (const RecordingError&) {
    throw;
  } catch (const std::exception& e) {
    throw RecordingError(fmt::format("{}: cannot create the recording: {}", dir.string(), e.what()));
  }
}

RecordingWriter::~RecordingWriter() {
  try {
    flush();
  } catch (const std::exception& e) {
    log::warn("recording {}: {}", impl_->dir.string(), e.what());
  }
}

void RecordingWriter::append(const Frame& frame, const std::optional<GroundTruthFrame>& truth) {
  Impl& w = *impl_;
  const RecordingInfo& info = w.info;
  const uint64_t index = w.frames_written;
  if (frame.format != info.pixel_format || frame.width != info.width || frame.height != info.height ||
      frame.bytes_per_line != info.bytes_per_line || frame.data.size() != w.frame_bytes)
    throw RecordingError(
        fmt::format("{}: frame {} is {}x{} {} with {} bytes per line and {} bytes, expected {}x{} {} with {} and {}",
                    w.dir.string(), index, frame.width, frame.height, pixel_format_name(frame.format),
                    frame.bytes_per_line, frame.data.size(), info.width, info.height,
                    pixel_format_name(info.pixel_format), info.bytes_per_line, w.frame_bytes));
  if (index == 0) w.has_ground_truth = truth.has_value();
  if (truth.has_value() != w.has_ground_truth)
    throw RecordingError(
        fmt::format("{}: frame {} {} ground truth, but the first frame {}: give it for every frame "
                    "or for none",
                    w.dir.string(), index, truth ? "has" : "has no", truth ? "had none" : "had it"));

  recording_json::FrameRecord record;
  record.index = index;
  record.offset = w.frames_end;
  record.size = frame.data.size();
  record.crc32 = uint32_t(crc32_z(crc32_z(0, nullptr, 0), frame.data.data(), frame.data.size()));
  record.meta = frame.meta;
  const std::string line = recording_json::encode_frame_record(record) + "\n";
  std::string truth_line;
  if (truth) truth_line = recording_json::encode_ground_truth({index, *truth}) + "\n";

  try {
    w.frames.write_at(w.frames_end, frame.data.data(), frame.data.size());
    if (truth) {
      if (!w.ground_truth.is_open())
        w.ground_truth = PosixFile(w.dir / w.files.ground_truth, PosixFile::Mode::CreateNew);
      w.ground_truth.write_at(w.ground_truth_end, truth_line.data(), truth_line.size());
    }
    // The metadata line commits the frame: readers ignore payload and truth without one.
    w.metadata.write_at(w.metadata_end, line.data(), line.size());
  } catch (const std::exception& e) {
    w.cut_back_after_failure();
    throw RecordingError(fmt::format("{}: cannot append frame {}: {}", w.dir.string(), index, e.what()));
  }
  w.frames_end += frame.data.size();
  w.metadata_end += line.size();
  w.ground_truth_end += truth_line.size();
  ++w.frames_written;
  w.unflushed = true;
}

void RecordingWriter::flush() {
  Impl& w = *impl_;
  if (!w.unflushed) return;
  try {
    w.frames.sync();
    if (w.ground_truth.is_open()) w.ground_truth.sync();
    w.metadata.sync();
    PosixFile::sync_directory(w.dir);
  } catch (const std::exception& e) {
    throw RecordingError(fmt::format("{}: cannot flush: {}", w.dir.string(), e.what()));
  }
  w.unflushed = false;
}

uint64_t RecordingWriter::frames_written() const { return impl_->frames_written; }
const RecordingInfo& RecordingWriter::info() const { return impl_->info; }
const fs::path& RecordingWriter::dir() const { return impl_->dir; }

}  // namespace arpipe
