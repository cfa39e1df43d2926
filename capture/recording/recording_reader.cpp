// Recording reader (format v1). The metadata line commits a frame: a cut-off tail in any part is
// an interrupted append (warning, complete frames kept); damage anywhere else is an error.
#include "capture/recording/recording_reader.h"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>
#include <system_error>

#include "capture/recording/posix_file.h"
#include "capture/recording/recording_json.h"
#include "core/config/regular_file.h"
#include "core/log.h"

namespace arpipe {

namespace fs = std::filesystem;

namespace {

// Limits on what a recording may declare (docs/FORMATS.md): far above what the writer produces,
// low enough that a few bytes of hostile input cannot make the reader allocate gigabytes.
constexpr uint64_t kMaxInfoBytes = 1 << 20;               // recording.json: ~400 bytes written
constexpr size_t kMaxMetadataLineBytes = 64 << 10;        // frames.jsonl: ~400 bytes a line written
constexpr size_t kMaxGroundTruthLineBytes = 1 << 20;      // ground_truth.jsonl: row poses, ~200 KB at 16384 rows
constexpr uint64_t kMaxFrameBytes = uint64_t{1} << 30;    // one frame's payload: a 16384 x 16384 RGB24 frame is 805 MB

// "<path>: <reason>" of a std::filesystem query, or nullopt when it succeeded. ENOENT is an answer
// (no such file), not an error; anything else (a symlink loop, no permission) is reported.
std::optional<std::string> status_problem(const fs::path& path, fs::file_status& status) {
  std::error_code ec;
  status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) return fmt::format("{}: {}", path.string(), ec.message());
  return std::nullopt;
}

std::string read_text(const fs::path& path, const char* what, uint64_t max_bytes) {
  fs::file_status status;
  if (auto problem = status_problem(path, status)) throw RecordingError(*problem);
  if (!fs::exists(status))
    throw RecordingError(fmt::format("{}: missing (a recording must include its {})", path.string(), what));
  try {
    return read_regular_file(path, what, max_bytes);
  } catch (const FileAccessError& e) {
    throw RecordingError(e.what());
  }
}

// Lines of a .jsonl file read one at a time, each at most `max_line` bytes: a line longer than
// that is refused at the limit, before the whole of it is in memory.
class JsonlLines {
 public:
  JsonlLines(const fs::path& path, const char* what, size_t max_line) : path_(path), max_line_(max_line) {
    fs::file_status status;
    if (auto problem = status_problem(path, status)) throw RecordingError(*problem);
    if (!fs::exists(status))
      throw RecordingError(fmt::format("{}: missing (a recording must include its {})", path.string(), what));
    try {
      file_ = PosixFile(path, PosixFile::Mode::Read);
    } catch (const std::exception& e) {
      throw RecordingError(e.what());
    }
  }

  // The next line without its newline; `complete` is false for a last line without one. False at
  // the end of the file.
  bool next(std::string& line, bool& complete) {
    line.clear();
    ++line_number_;
    for (;;) {
      if (pos_ == end_ && !fill()) {
        complete = false;
        return !line.empty();
      }
      const char* begin = buffer_.data() + pos_;
      const char* newline = static_cast<const char*>(std::memchr(begin, '\n', end_ - pos_));
      const size_t take = newline != nullptr ? size_t(newline - begin) : end_ - pos_;
      if (line.size() + take > max_line_)
        throw RecordingError(fmt::format("{} line {}: longer than the limit of {} bytes for one line", path_.string(),
                                         line_number_, max_line_));
      line.append(begin, take);
      pos_ += take;
      if (newline != nullptr) {
        ++pos_;
        complete = true;
        return true;
      }
    }
  }
  size_t line_number() const { return line_number_; }

 private:
  bool fill() {
    try {
      end_ = file_.read_some(offset_, buffer_.data(), buffer_.size());
    } catch (const std::system_error& e) {
      throw RecordingError(fmt::format("{} line {}: {}", path_.string(), line_number_, e.what()));
    }
    offset_ += end_;
    pos_ = 0;
    return end_ > 0;
  }

  fs::path path_;
  size_t max_line_;
  PosixFile file_;
  std::array<char, 65536> buffer_{};
  uint64_t offset_ = 0;
  size_t pos_ = 0, end_ = 0;
  size_t line_number_ = 0;
};

// The records of a .jsonl file. A last line without its newline was cut off mid-append: it is
// kept if it still parses (only the newline was lost) and dropped with a warning otherwise.
template <typename Record, typename Decode>
std::vector<Record> parse_jsonl(JsonlLines lines, const fs::path& path, Decode decode,
                                std::vector<std::string>& warnings) {
  std::vector<Record> records;
  std::string line;
  bool complete = false;
  while (lines.next(line, complete)) {
    const std::string where = fmt::format("{} line {}", path.string(), lines.line_number());
    if (!complete) {
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
    records.push_back(decode(line, where));
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
    fs::file_status status;
    if (auto problem = status_problem(path, status)) throw RecordingError(*problem);
    if (!fs::exists(status))
      throw RecordingError(fmt::format("{}: missing (not an arpipe recording directory?)", path.string()));
    recording_json::decode_info(read_text(path, "description", kMaxInfoBytes), path.string(), info, files);
    // Checked: width, height and bytes_per_line are bounded by decode_info, but the product is what
    // every frame read allocates.
    uint64_t rows_bytes = 0;
    const uint64_t rows = info.pixel_format == PixelFormat::NV12 ? uint64_t(info.height) + uint64_t(info.height / 2)
                                                                 : uint64_t(info.height);
    if (__builtin_mul_overflow(uint64_t(info.bytes_per_line), rows, &rows_bytes) || rows_bytes > kMaxFrameBytes)
      throw RecordingError(fmt::format("{}: a {}x{} {} frame with {} bytes per line exceeds the limit of {} bytes per "
                                       "frame",
                                       path.string(), info.width, info.height, pixel_format_name(info.pixel_format),
                                       info.bytes_per_line, kMaxFrameBytes));
    frame_bytes = image_bytes(info.pixel_format, info.width, info.height, info.bytes_per_line);
  }

  void load_camera_model() {
    const fs::path path = dir / files.camera_model;
    fs::file_status status;
    if (auto problem = status_problem(path, status)) throw RecordingError(*problem);
    if (!fs::exists(status))
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
    JsonlLines lines(metadata_path, "frame metadata", kMaxMetadataLineBytes);
    fs::file_status status;
    if (auto problem = status_problem(frames_path, status)) throw RecordingError(*problem);
    if (!fs::exists(status))
      throw RecordingError(fmt::format("{}: missing (a recording must include its frames)", frames_path.string()));
    try {
      frames = PosixFile(frames_path, PosixFile::Mode::Read);
    } catch (const std::exception& e) {
      throw RecordingError(e.what());
    }
    records = parse_jsonl<recording_json::FrameRecord>(std::move(lines), metadata_path,
                                                       recording_json::decode_frame_record, warnings);
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
    fs::file_status status;
    if (auto problem = status_problem(path, status)) throw RecordingError(*problem);
    if (!fs::exists(status)) return;
    const auto truths =
        parse_jsonl<recording_json::GroundTruthRecord>(JsonlLines(path, "ground truth", kMaxGroundTruthLineBytes), path,
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
  if (dir.empty()) throw RecordingError("not a recording: the directory's path is empty");
  fs::file_status status;
  if (auto problem = status_problem(dir, status)) throw RecordingError(*problem + " (the recording directory)");
  if (!fs::is_directory(status))
    throw RecordingError(fmt::format("{}: not a recording ({})", dir.string(),
                                     fs::exists(status) ? "not a directory" : "no such directory"));
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
