// PNG and JPEG headers read by hand: two fixed layouts (PNG's IHDR is the first chunk; JPEG's
// SOFn segment comes after APPn/DQT/DHT segments, each with its length), no decoder needed.
#include "core/image/image_header.h"

#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include "core/config/regular_file.h"
#include "core/scene/asset_error.h"

namespace arpipe {

namespace {

class HeaderReader {
 public:
  explicit HeaderReader(const std::filesystem::path& path) : path_(path) {
    try {
      fd_ = open_regular_file(path, "image");
    } catch (const FileAccessError& e) {
      throw AssetError(e.what());
    }
  }
  ~HeaderReader() { ::close(fd_); }
  HeaderReader(const HeaderReader&) = delete;
  HeaderReader& operator=(const HeaderReader&) = delete;

  [[noreturn]] void fail(const std::string& what) const {
    throw AssetError(fmt::format("{}: byte {}: {}", path_.string(), offset_, what));
  }

  // Exactly n bytes at the current offset, or an error saying what was expected there.
  void read(uint8_t* out, size_t n, const char* expected) {
    size_t got = 0;
    while (got < n) {
      const ssize_t r = ::pread(fd_, out + got, n - got, off_t(offset_ + got));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) fail(fmt::format("cannot read {}: {}", expected, std::strerror(errno)));
      if (r == 0) fail(fmt::format("the file ends inside {}", expected));
      got += size_t(r);
    }
    offset_ += n;
  }
  void skip(uint64_t n) { offset_ += n; }
  uint64_t offset() const { return offset_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  uint64_t offset_ = 0;
};

uint32_t big_endian(const uint8_t* p, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

ImageHeader read_png(HeaderReader& in) {
  // Signature (8), then the IHDR chunk: length 13, "IHDR", width, height (big-endian).
  std::array<uint8_t, 16> chunk{};
  in.read(chunk.data(), chunk.size(), "the PNG IHDR chunk");
  if (big_endian(chunk.data(), 4) != 13 || std::memcmp(chunk.data() + 4, "IHDR", 4) != 0)
    in.fail("expected the IHDR chunk (length 13) first after the PNG signature");
  return ImageHeader{"PNG", big_endian(chunk.data() + 8, 4), big_endian(chunk.data() + 12, 4)};
}

ImageHeader read_jpeg(HeaderReader& in) {
  // Markers after SOI: FF xx, fill bytes FF allowed; every segment but RSTn/TEM carries a length.
  for (int segments = 0; segments < 10000; ++segments) {
    uint8_t marker = 0xff;
    while (marker == 0xff) in.read(&marker, 1, "a JPEG marker");
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) continue;  // no length
    if (marker == 0xd9 || marker == 0xda) in.fail("expected a JPEG frame header (SOFn) before the scan");
    std::array<uint8_t, 2> length_bytes{};
    in.read(length_bytes.data(), 2, "a JPEG segment length");
    const uint32_t length = big_endian(length_bytes.data(), 2);
    if (length < 2) in.fail(fmt::format("JPEG segment length {} (at least 2)", length));
    const bool frame_header = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (!frame_header) {
      in.skip(length - 2);
      continue;
    }
    std::array<uint8_t, 5> sof{};  // precision, height, width
    in.read(sof.data(), sof.size(), "the JPEG frame header");
    const ImageHeader header{"JPEG", big_endian(sof.data() + 3, 2), big_endian(sof.data() + 1, 2)};
    if (header.height == 0) in.fail("JPEG frame header with height 0 (given later by a DNL segment): not supported");
    return header;
  }
  in.fail("more than 10000 JPEG segments before the frame header");
}

}  // namespace

ImageHeader read_image_header(const std::filesystem::path& path) {
  HeaderReader in(path);
  std::array<uint8_t, 8> magic{};
  uint8_t first[2];
  in.read(first, 2, "the image signature");
  if (first[0] == 0xff && first[1] == 0xd8) return read_jpeg(in);
  magic[0] = first[0];
  magic[1] = first[1];
  constexpr std::array<uint8_t, 8> kPngSignature{0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (first[0] == kPngSignature[0] && first[1] == kPngSignature[1]) {
    in.read(magic.data() + 2, 6, "the PNG signature");
    if (magic == kPngSignature) return read_png(in);
  }
  throw AssetError(fmt::format("{}: expected a PNG or JPEG image (signature 89 50 4e 47 or ff d8), found bytes "
                               "{:02x} {:02x}",
                               path.string(), first[0], first[1]));
}

void check_image_limits(const ImageHeader& header, const std::filesystem::path& path, const std::string& what,
                        int64_t max_side, int64_t max_pixels) {
  if (header.width < 1 || header.height < 1)
    throw AssetError(fmt::format("{} \"{}\": the {} header declares {} x {} pixels", what, path.string(), header.format,
                                 header.width, header.height));
  if (header.width > max_side || header.height > max_side || header.width * header.height > max_pixels)
    throw AssetError(fmt::format("{} \"{}\": a {} x {} {} image exceeds the limit of {} pixels a side and {} pixels "
                                 "in all",
                                 what, path.string(), header.width, header.height, header.format, max_side,
                                 max_pixels));
}

}  // namespace arpipe
