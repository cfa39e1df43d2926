// Recording reader (format v1). The metadata line commits a frame: a cut-off tail in any part is
// an interrupted append (warning, complete frames kept); damage anywhere else is an error.
#include "capture/recording/recording_reader.h"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <sstream>

#include "capture/recording/posix_file.h"
#include "capture/recording/recording_json.h"
#include "core/log.h"

namespace arpipe {

namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& path, const char* what) {
  if (!fs::exists(path))
    throw RecordingError(fmt::format("{}: missing (a recording must include its {})", path.string(), what));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw RecordingError(fmt::format("{}: cannot read", path.string()));
  return text.str();
}

// The records of a .jsonl file. A last line without its newline was cut off mid-append: it is
// kept if it still parses (only the newline was lost) and dropped with a warning otherwise.
template <typename Record, typename Decode>
std::vector<Record> parse_jsonl(const std::string& text, const fs::path& path, Decode decode,
                                std::vector<std::string>& warnings) {
  std::vector<Record> records;
  size_t begin = 0;
  for (size_t line_number = 1; begin < text.size(); ++line_number) {
    const size_t end = text.find('\n', begin);
    const std::string where = fmt::format("{} line {}", path.string(), line_number);
    if (end == std::string::npos) {
      const std::string line = text.substr(begin);
      try {
        records.push_back(decode(line, where));
        warnings.push_back(
            fmt::format("{}: no final newline (an interrupted append); the line is complete, kept", where));
      } catch (const RecordingError&) {
        warnings.push_back(
            fmt::format("{}: cut off after {} bytes (an interrupted append); ignored", where, line.size()));
      }
      break;
    }
    records.push_back(decode(text.substr(begin, end - begin), where));
    begin = end + 1;
  }
  return records;
}

}  // namespace

struct RecordingReader::Impl {
  fs::path dir;
  RecordingInfo info;
  recording_json::FileNames files;
  std::optional<CameraModel> model;
  size_t frame_bytes = 0;
  PosixFile frames;
  std::vector<recording_json::FrameRecord> records;
  std::vector<GroundTruthFrame> ground_truth;
  std::vector<std::string> warnings;

  void load_info() {
    const fs::path path = dir / kRecordingInfoFile;
    if (!fs::exists(path))
      throw RecordingError(fmt::format("{}: missing (not an arpipe recording directory?)", path.string()));
    recording_json::decode_info(read_text(path, "description"), path.string(), info, files);
    frame_bytes = image_bytes(info.pixel_format, info.width, info.height, info.bytes_per_line);
  }

  void load_camera_model() {
    const fs::path path = dir / files.camera_model;
    if (!fs::exists(path))
      throw RecordingError(fmt::format("{}: missing (a recording must include its camera model)", path.string()));
    try {
      model = CameraModel::load(path);
    } catch (const CameraModelError& e) {
      throw RecordingError(e.what());
    }
    if (model->width() != info.width || model->height() != info.height)
      throw RecordingError(fmt::format("{}: imager size {}x{} differs from the frame size {}x{} of {}", path.string(),
                                       model->width(), model->height(), info.width, info.height,
                                       (dir / kRecordingInfoFile).string()));
  }

  void load_frame_records() {
    const fs::path metadata_path = dir / files.metadata;
    const fs::path frames_path = dir / files.frames;
    const std::string text = read_text(metadata_path, "frame metadata");
    if (!fs::exists(frames_path))
      throw RecordingError(fmt::format("{}: missing (a recording must include its frames)", frames_path.string()));
    try {
      frames = PosixFile(frames_path, PosixFile::Mode::Read);
    } catch (const std::exception& e) {
      throw RecordingError(e.what());
    }
    records =
        parse_jsonl<recording_json::FrameRecord>(text, metadata_path, recording_json::decode_frame_record, warnings);
    uint64_t expected_offset = 0;
    for (size_t i = 0; i < records.size(); ++i) {
      const auto& r = records[i];
      const std::string where = fmt::format("{} line {}", metadata_path.string(), i + 1);
      if (r.index != i)
        throw RecordingError(
            fmt::format("{}: index {}, expected {} (lines count the frames from 0)", where, r.index, i));
      if (r.size != frame_bytes)
        throw RecordingError(fmt::format("{}: size {}, expected {} (one {}x{} {} image with {} bytes per line)", where,
                                         r.size, frame_bytes, info.width, info.height,
                                         pixel_format_name(info.pixel_format), info.bytes_per_line));
      if (r.offset != expected_offset)
        throw RecordingError(
            fmt::format("{}: offset {}, expected {} (payloads lie back to back)", where, r.offset, expected_offset));
      expected_offset += r.size;
    }
    const uint64_t frames_size = frames.size();
    auto first_missing =
        std::find_if(records.begin(), records.end(), [&](const auto& r) { return r.offset + r.size > frames_size; });
    if (first_missing != records.end()) {
      warnings.push_back(
          fmt::format("{}: ends at byte {} inside frame {} (bytes {} to {}): an interrupted append; "
                      "{} frame(s) dropped",
                      frames_path.string(), frames_size, first_missing->index, first_missing->offset,
                      first_missing->offset + first_missing->size, records.end() - first_missing));
      records.erase(first_missing, records.end());
    } else if (frames_size > expected_offset) {
      warnings.push_back(
          fmt::format("{}: {} bytes after the last complete frame (from byte {}): an interrupted "
                      "append; ignored",
                      frames_path.string(), frames_size - expected_offset, expected_offset));
    }
  }

  void load_ground_truth() {
    const fs::path path = dir / files.ground_truth;
    if (!fs::exists(path)) return;
    const auto truths = parse_jsonl<recording_json::GroundTruthRecord>(read_text(path, "ground truth"), path,
                                                                       recording_json::decode_ground_truth, warnings);
    for (size_t i = 0; i < truths.size(); ++i) {
      const std::string where = fmt::format("{} line {}", path.string(), i + 1);
      if (truths[i].index != i)
        throw RecordingError(fmt::format("{}: index {}, expected {}", where, truths[i].index, i));
      if (i < records.size() && truths[i].truth.sequence != records[i].meta.sequence)
        throw RecordingError(fmt::format("{}: sequence {} differs from frame {}'s sequence {} in {}", where,
                                         truths[i].truth.sequence, i, records[i].meta.sequence,
                                         (dir / files.metadata).string()));
    }
    if (truths.size() < records.size()) {
      warnings.push_back(
          fmt::format("{}: ends after frame {} of {}: an interrupted append; the frames without "
                      "ground truth are dropped",
                      path.string(), truths.size(), records.size()));
      records.resize(truths.size());
    } else if (truths.size() > records.size()) {
      // Ground truth is written before the metadata line that commits its frame.
      warnings.push_back(fmt::format("{}: {} line(s) after the last committed frame: an interrupted append; ignored",
                                     path.string(), truths.size() - records.size()));
    }
    ground_truth.reserve(records.size());
    for (size_t i = 0; i < records.size(); ++i) ground_truth.push_back(truths[i].truth);
  }
};

RecordingReader::RecordingReader(const fs::path& dir) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.dir = dir;
  if (!fs::is_directory(dir))
    throw RecordingError(fmt::format("{}: not a recording (no such directory)", dir.string()));
  r.load_info();
  r.load_camera_model();
  r.load_frame_records();
  r.load_ground_truth();
  for (const auto& warning : r.warnings) log::warn("{}", warning);
}

RecordingReader::~RecordingReader() = default;

const RecordingInfo& RecordingReader::info() const { return impl_->info; }
const CameraModel& RecordingReader::camera_model() const { return *impl_->model; }
size_t RecordingReader::frame_count() const { return impl_->records.size(); }
const std::vector<GroundTruthFrame>& RecordingReader::ground_truth() const { return impl_->ground_truth; }
const std::vector<std::string>& RecordingReader::warnings() const { return impl_->warnings; }
const fs::path& RecordingReader::dir() const { return impl_->dir; }

const FrameMetadata& RecordingReader::metadata(size_t index) const { return impl_->records.at(index).meta; }

void RecordingReader::read(size_t index, Frame& frame) const {
  const Impl& r = *impl_;
  const auto& record = r.records.at(index);
  const fs::path frames_path = r.dir / r.files.frames;
  const std::string place =
      fmt::format("{}: frame {} (bytes {} to {}, {} line {})", frames_path.string(), index, record.offset,
                  record.offset + record.size, (r.dir / r.files.metadata).string(), index + 1);
  frame.meta = record.meta;
  frame.format = r.info.pixel_format;
  frame.width = r.info.width;
  frame.height = r.info.height;
  frame.bytes_per_line = r.info.bytes_per_line;
  frame.data.resize(record.size);
  try {
    if (!r.frames.read_at(record.offset, frame.data.data(), frame.data.size()))
      throw RecordingError(fmt::format("{}: the file ends inside the frame (it shrank after opening)", place));
  } catch (const std::system_error& e) {
    throw RecordingError(fmt::format("{}: {}", place, e.what()));
  }
  const auto crc = uint32_t(crc32_z(crc32_z(0, nullptr, 0), frame.data.data(), frame.data.size()));
  if (crc != record.crc32)
    throw RecordingError(
        fmt::format("{}: CRC-32 {:08x} does not match the recorded {:08x} (damaged pixels)", place, crc, record.crc32));
}

}  // namespace arpipe
