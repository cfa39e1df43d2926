#include "loopback_spool.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>

namespace arpipe::standin {

namespace {

// Every spool file starts with this header (native byte order: both ends run on one machine);
// a frame file continues with bytes_used bytes of pixels and nothing else.
struct SpoolFileHeader {
  char magic[8];
  uint32_t fourcc, width, height, bytes_per_line, size_image, bytes_used;
  uint32_t interval_num, interval_den, sequence, flags;
  int64_t timestamp_ns;
  uint8_t reserved[8];
};
static_assert(sizeof(SpoolFileHeader) == 64);

constexpr char kSpoolMagic[8] = {'A', 'R', 'P', 'L', 'O', 'O', 'P', '1'};
constexpr uint32_t kSpoolTimestampCopied = 1;
constexpr uint32_t kSpoolMaxBytesPerLine = 65536;  // above any stride of kMaxSpoolDimension pixels
constexpr const char* kSpoolFrameSuffix = ".frame";

// The index of a frame file's name ("0000000042.frame"), or nullopt for any other name.
std::optional<uint64_t> spool_frame_index(const std::string& name) {
  const size_t digits = 10;
  if (name.size() != digits + std::strlen(kSpoolFrameSuffix) || !name.ends_with(kSpoolFrameSuffix)) return std::nullopt;
  uint64_t value = 0;
  for (size_t i = 0; i < digits; ++i) {
    if (name[i] < '0' || name[i] > '9') return std::nullopt;
    value = value * 10 + uint64_t(name[i] - '0');
  }
  return value;
}

bool write_all_to(int fd, const void* data, size_t size) {
  const auto* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
  }
  return true;
}

bool read_all_from(int fd, void* data, size_t size, off_t offset) {
  auto* p = static_cast<uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::pread(fd, p, size, offset);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
    offset += n;
  }
  return true;
}

SpoolFileHeader make_spool_header(const SpoolFormat& f) {
  SpoolFileHeader h{};
  std::memcpy(h.magic, kSpoolMagic, sizeof h.magic);
  h.fourcc = pixel_format_fourcc(f.format);
  h.width = f.width;
  h.height = f.height;
  h.bytes_per_line = f.bytes_per_line;
  h.size_image = f.size_image;
  h.interval_num = f.interval_num;
  h.interval_den = f.interval_den;
  return h;
}

// Writes a whole file under a temporary name in `dir`; the caller gives it its name. "" or why not.
std::string write_spool_temporary(const std::filesystem::path& dir, const SpoolFileHeader& header, const uint8_t* bytes,
                                  size_t size, std::filesystem::path& temporary) {
  static std::atomic<uint64_t> counter{0};
  temporary = dir / fmt::format(".tmp-{}-{}", ::getpid(), counter.fetch_add(1));
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return fmt::format("{}: {}", temporary.string(), std::strerror(errno));
  const bool ok = write_all_to(fd, &header, sizeof header) && (size == 0 || write_all_to(fd, bytes, size));
  const int saved = errno;
  if (::close(fd) != 0 || !ok) {
    ::unlink(temporary.c_str());
    return fmt::format("{}: {}", temporary.string(), std::strerror(ok ? errno : saved));
  }
  return "";
}

// Checks a header against the format's rules and the file's size; "" or what was expected.
std::string check_spool_header(const SpoolFileHeader& h, uint64_t file_size, bool frame, SpoolFrame& out) {
  if (std::memcmp(h.magic, kSpoolMagic, sizeof h.magic) != 0) return "expected a spool file (magic \"ARPLOOP1\")";
  const auto format = pixel_format_from_fourcc(h.fourcc);
  if (!format) return fmt::format("pixel format 0x{:08x}: expected one of YUYV, RGB24, GREY, NV12", h.fourcc);
  if (h.width < 1 || h.width > kMaxSpoolDimension || h.height < 1 || h.height > kMaxSpoolDimension)
    return fmt::format("size {}x{}: expected 1..{} each", h.width, h.height, kMaxSpoolDimension);
  if (const auto bad = check_image_size(*format, int(h.width), int(h.height))) return *bad;
  const size_t min_stride = min_bytes_per_line(*format, int(h.width));
  if (h.bytes_per_line < min_stride || h.bytes_per_line > kSpoolMaxBytesPerLine)
    return fmt::format("bytes per line {}: expected {}..{}", h.bytes_per_line, min_stride, kSpoolMaxBytesPerLine);
  const size_t image = image_bytes(*format, int(h.width), int(h.height), h.bytes_per_line);
  if (h.size_image != image) return fmt::format("image size {}: expected {}", h.size_image, image);
  if (h.interval_num == 0 || h.interval_den == 0)
    return fmt::format("frame interval {}/{}: expected both above 0", h.interval_num, h.interval_den);
  if ((h.flags & ~kSpoolTimestampCopied) != 0) return fmt::format("flags 0x{:x}: expected 0 or 1", h.flags);
  if (frame && (h.bytes_used == 0 || h.bytes_used > h.size_image))
    return fmt::format("bytes used {}: expected 1..{}", h.bytes_used, h.size_image);
  if (!frame && h.bytes_used != 0) return fmt::format("bytes used {}: expected 0 in the format file", h.bytes_used);
  if (file_size != sizeof h + h.bytes_used)
    return fmt::format("file of {} bytes: expected {} (header and bytes used)", file_size, sizeof h + h.bytes_used);
  out.format = SpoolFormat{*format, h.width, h.height, h.bytes_per_line, h.size_image, h.interval_num, h.interval_den};
  out.bytes_used = h.bytes_used;
  out.sequence = h.sequence;
  out.timestamp_ns = h.timestamp_ns;
  out.timestamp_copied = (h.flags & kSpoolTimestampCopied) != 0;
  return "";
}

// Opens and checks a spool file; fd < 0 and error empty when it does not exist.
int open_spool_file(const std::filesystem::path& path, bool frame, SpoolFrame& out, std::string& error) {
  error.clear();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) {
    if (errno != ENOENT) error = fmt::format("{}: {}", path.string(), std::strerror(errno));
    return -1;
  }
  struct stat st {};
  SpoolFileHeader h{};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    error = fmt::format("{}: expected a regular file", path.string());
  else if (uint64_t(st.st_size) < sizeof h || !read_all_from(fd, &h, sizeof h, 0))
    error = fmt::format("{}: expected a header of {} bytes", path.string(), sizeof h);
  else if (const std::string why = check_spool_header(h, uint64_t(st.st_size), frame, out); !why.empty())
    error = fmt::format("{}: {}", path.string(), why);
  if (error.empty()) return fd;
  ::close(fd);
  return -1;
}

}  // namespace

SpoolFormat spool_format(PixelFormat format, uint32_t width, uint32_t height) {
  SpoolFormat f;
  f.format = format;
  f.width = width;
  f.height = height;
  f.bytes_per_line = uint32_t(min_bytes_per_line(format, int(width)));
  f.size_image = uint32_t(image_bytes(format, int(width), int(height), f.bytes_per_line));
  return f;
}

std::string SpoolWriter::write_format(const SpoolFormat& format) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  std::filesystem::path temporary;
  if (std::string why = write_spool_temporary(dir_, make_spool_header(format), nullptr, 0, temporary); !why.empty())
    return why;
  const std::filesystem::path target = dir_ / "format";
  if (::rename(temporary.c_str(), target.c_str()) != 0) {
    const int saved = errno;
    ::unlink(temporary.c_str());
    return fmt::format("{}: {}", target.string(), std::strerror(saved));
  }
  return "";
}

std::string SpoolWriter::append(const SpoolFrame& frame, const uint8_t* bytes) {
  const int64_t size = int64_t(sizeof(SpoolFileHeader)) + frame.bytes_used;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!next_index_) {  // the newest frame of any writer, and the spool's size
      std::error_code ec;
      std::filesystem::create_directories(dir_, ec);
      uint64_t next = 0;
      bytes_ = 0;
      for (auto it = std::filesystem::directory_iterator(dir_, ec); !ec && it != std::filesystem::directory_iterator();
           it.increment(ec)) {
        const auto index = spool_frame_index(it->path().filename().string());
        if (!index) continue;
        next = std::max(next, *index + 1);
        std::error_code size_ec;
        const auto file_size = it->file_size(size_ec);
        if (!size_ec) bytes_ += int64_t(file_size);
      }
      if (ec) return fmt::format("{}: {}", dir_.string(), ec.message());
      next_index_ = next;
    }
    if (bytes_ + size > max_bytes_)
      return fmt::format("{}: the spool holds {} bytes; another frame would pass max_spool_mib", dir_.string(), bytes_);
    SpoolFileHeader h = make_spool_header(frame.format);
    h.bytes_used = frame.bytes_used;
    h.sequence = frame.sequence;
    h.flags = frame.timestamp_copied ? kSpoolTimestampCopied : 0;
    h.timestamp_ns = frame.timestamp_ns;
    std::filesystem::path temporary;
    if (std::string why = write_spool_temporary(dir_, h, bytes, frame.bytes_used, temporary); !why.empty()) return why;
    // link() never replaces: a frame another writer added meanwhile is kept, and this one goes after it.
    const std::filesystem::path target = dir_ / fmt::format("{:010d}{}", *next_index_, kSpoolFrameSuffix);
    const int linked = ::link(temporary.c_str(), target.c_str());
    const int saved = errno;
    ::unlink(temporary.c_str());
    if (linked == 0) {
      ++*next_index_;
      bytes_ += size;
      return "";
    }
    if (saved != EEXIST) return fmt::format("{}: {}", target.string(), std::strerror(saved));
    next_index_.reset();
  }
  return fmt::format("{}: another writer keeps taking the next frame's name", dir_.string());
}

std::optional<SpoolFormat> SpoolReader::read_format(std::string& error) const {
  SpoolFrame f;
  const int fd = open_spool_file(dir_ / "format", false, f, error);
  if (fd < 0) return std::nullopt;
  ::close(fd);
  return f.format;
}

uint64_t SpoolReader::first_index() const {
  std::error_code ec;
  std::optional<uint64_t> first;
  for (auto it = std::filesystem::directory_iterator(dir_, ec); !ec && it != std::filesystem::directory_iterator();
       it.increment(ec))
    if (const auto index = spool_frame_index(it->path().filename().string()))
      first = first ? std::min(*first, *index) : *index;
  return first.value_or(0);
}

std::filesystem::path SpoolReader::frame_path(uint64_t index) const {
  return dir_ / fmt::format("{:010d}{}", index, kSpoolFrameSuffix);
}

SpoolReader::Result SpoolReader::read_frame(uint64_t index, SpoolFrame& frame, uint8_t* dst, size_t capacity,
                                            std::string& error) const {
  const std::filesystem::path path = frame_path(index);
  const int fd = open_spool_file(path, true, frame, error);
  if (fd < 0) return error.empty() ? Result::Absent : Result::Bad;
  Result result = Result::Ok;
  if (frame.bytes_used > capacity) {
    error = fmt::format("{}: a frame of {} bytes does not fit the reader's buffers of {} bytes", path.string(),
                        frame.bytes_used, capacity);
    result = Result::Bad;
  } else if (!read_all_from(fd, dst, frame.bytes_used, off_t(sizeof(SpoolFileHeader)))) {
    error = fmt::format("{}: cannot read its {} bytes", path.string(), frame.bytes_used);
    result = Result::Bad;
  }
  ::close(fd);
  return result;
}

}  // namespace arpipe::standin
