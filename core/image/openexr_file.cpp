// OpenEXR reading and writing. Rows are read in bands of 16 so that memory grows with the data
// the library really decodes, not with the size a (possibly corrupt) header declares.
#include "core/image/openexr_file.h"

#include <fmt/format.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <string_view>
#include <vector>

#include "core/config/regular_file.h"
#include "core/image/hdr_file.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

constexpr int kBand = 16;  // rows per readPixels call
// Header attributes: a light probe's are a few dozen bytes each (a preview image the most); a type
// OpenEXR does not know is kept as opaque bytes, which nothing here reads.
constexpr uint32_t kMaxAttributeBytes = uint32_t{1} << 24;        // 16 MiB (a 2048 x 2048 preview)
constexpr uint32_t kMaxUnknownAttributeBytes = uint32_t{1} << 16;  // 64 KiB

void check_size(const Imath::Box2i& window, const std::string& name) {
  const int64_t width = int64_t{window.max.x} - window.min.x + 1, height = int64_t{window.max.y} - window.min.y + 1;
  if (width < 1 || height < 1 || width > kMaxHdrSide || height > kMaxHdrSide || width * height > kMaxHdrPixels)
    throw AssetError(fmt::format("{}: data window ({}, {}) - ({}, {}) is {} x {} pixels; expected sides of 1..{} and "
                                 "at most 2^28 pixels",
                                 name, window.min.x, window.min.y, window.max.x, window.max.y, width, height, kMaxHdrSide));
}

// The library trusts the header: an attribute size, a channel list or a data window from a corrupt
// file makes it allocate gigabytes before it notices the file is short. So walk the header(s) first,
// the way the library will: every attribute's declared size against the bytes really there (and
// 16 MiB), no name twice, every value of a known type exactly that type's layout, unknown types at
// most 64 KiB; the data window against our limits, tile sizes (at most 2^24 pixels a tile), the
// channel count (light probes have a handful; at most 64) and the chunk offset tables against the
// bytes after the headers, before the library sees the file.
class ExrHeaderCheck {
 public:
  ExrHeaderCheck(const std::filesystem::path& path, const std::string& name) : in_(path, std::ios::binary), name_(name) {
    std::error_code ec;
    size_ = std::filesystem::file_size(path, ec);
    if (ec || !in_) throw AssetError(fmt::format("{}: cannot open: {}", name_, ec ? ec.message() : std::strerror(errno)));
  }

  void run() {
    const uint32_t magic = read_u32("the magic number");
    const uint32_t version = read_u32("the version field");
    if (magic != 20000630)
      throw AssetError(fmt::format("{}: byte 0: not an OpenEXR file (magic 76 2f 31 01 expected)", name_));
    multipart_ = (version & 0x1000) != 0;
    tiled_flag_ = !multipart_ && (version & 0x200) != 0;
    for (int part = 0;; ++part) {
      const bool empty = read_header();
      if (!multipart_) break;
      if (empty) break;  // multi-part: an empty header ends the list
      if (part > 64) fail("more than 64 parts");
    }
    if (chunks_ > (size_ - position_) / 8)
      fail(fmt::format("the header(s) declare {} chunks, whose offset table ({} bytes) is longer than the {} bytes "
                       "left in the file",
                       chunks_, chunks_ * 8, size_ - position_));
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { fail_at(position_, what); }
  [[noreturn]] void fail_at(uint64_t byte, const std::string& what) const {
    throw AssetError(fmt::format("{}: OpenEXR header (byte {}): {}", name_, byte, what));
  }
  void read_bytes(char* out, uint64_t count, std::string_view what) {
    if (size_ - position_ < count) fail(fmt::format("the file ends inside {}", what));
    in_.read(out, static_cast<std::streamsize>(count));
    if (!in_) fail(fmt::format("cannot read {}", what));
    position_ += count;
  }
  uint32_t read_u32(std::string_view what) {
    unsigned char b[4];
    read_bytes(reinterpret_cast<char*>(b), 4, what);
    return uint32_t{b[0]} | uint32_t{b[1]} << 8 | uint32_t{b[2]} << 16 | uint32_t{b[3]} << 24;
  }
  std::string read_name(std::string_view what) {
    std::string text;
    for (;;) {
      char c = 0;
      read_bytes(&c, 1, what);
      if (c == 0) return text;
      if (text.size() >= 255) fail(fmt::format("{} is longer than 255 bytes", what));
      text += c;
    }
  }

  // The attributes every header must have (OpenEXR's file layout), with their types and sizes (0:
  // any): the library fills a missing one with a default and sizes its buffers from it.
  void check_required(const std::map<std::string, std::pair<std::string, uint32_t>>& seen) const {
    struct Required {
      const char* name;
      const char* type;
      uint32_t size;
    };
    static constexpr Required kRequired[] = {
        {"channels", "chlist", 0},          {"compression", "compression", 1}, {"dataWindow", "box2i", 16},
        {"displayWindow", "box2i", 16},     {"lineOrder", "lineOrder", 1},     {"pixelAspectRatio", "float", 4},
        {"screenWindowCenter", "v2f", 8},   {"screenWindowWidth", "float", 4}};
    const auto check = [&](const Required& r) {
      const auto found = seen.find(r.name);
      if (found == seen.end()) fail(fmt::format("the required attribute \"{}\" ({}) is missing", r.name, r.type));
      if (found->second.first != r.type || (r.size != 0 && found->second.second != r.size))
        fail(fmt::format("attribute \"{}\" is a {} of {} bytes, expected a {}{}", r.name, found->second.first,
                         found->second.second, r.type, r.size != 0 ? fmt::format(" of {} bytes", r.size) : ""));
    };
    for (const Required& r : kRequired) check(r);
    if (tiled_flag_) check({"tiles", "tiledesc", 9});
  }

  // Returns true for an empty header (the end of a multi-part file's header list).
  bool read_header() {
    std::map<std::string, std::pair<std::string, uint32_t>> seen;  // name -> type, size
    std::map<std::string, uint64_t> offsets;                        // name -> byte where it starts
    for (int attributes = 0;; ++attributes) {
      const uint64_t start = position_;
      const std::string attribute = read_name("an attribute name");
      if (attribute.empty()) {
        if (attributes > 0) {
          check_required(seen);
          count_chunks(seen);
        }
        return attributes == 0;
      }
      if (attributes >= 10000) fail("more than 10000 attributes");
      const std::string type = read_name("an attribute type");
      const uint32_t size = read_u32("an attribute size");
      // The library keeps the last of two same-named attributes, and reads a predefined one into the
      // default it already holds: a repeated name is where it and this walk part ways.
      if (const auto first = offsets.find(attribute); first != offsets.end())
        fail_at(start, fmt::format("attribute \"{}\" appears a second time (first at byte {})", attribute, first->second));
      offsets[attribute] = start;
      seen[attribute] = {type, size};
      if (size > size_ - position_)
        fail(fmt::format("attribute \"{}\" declares {} bytes, but only {} follow", attribute, size,
                                   size_ - position_));
      if (size > kMaxAttributeBytes)
        fail(fmt::format("attribute \"{}\" declares {} bytes (at most {} an attribute)", attribute, size,
                                   kMaxAttributeBytes));
      const uint64_t value_start = position_;
      std::vector<char> value(size);
      read_bytes(value.data(), size, "an attribute value");
      check_value(value_start, attribute, type, value);
    }
  }

  // The library reads every attribute of a type it knows by that type's layout, not by the size the
  // file declares (a chlist up to its empty name, a box2i as 16 bytes, a preview as width x height
  // pixels), and allocates an unknown type's declared size. So each value must be exactly what its
  // type's layout reads, or this walk and the library disagree on where the next attribute starts.
  void check_value(uint64_t value_start, const std::string& attribute, const std::string& type,
                   const std::vector<char>& value) {
    const auto fail_here = [&](const std::string& what) {
      fail_at(value_start, fmt::format("attribute \"{}\" ({}, {} bytes): {}", attribute, type, value.size(), what));
    };
    const auto u32 = [&](size_t at) {
      uint32_t v = 0;
      for (int k = 3; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(value[at + static_cast<size_t>(k)]);
      return v;
    };
    const auto i32 = [&](size_t at) { return static_cast<int32_t>(u32(at)); };
    static const std::map<std::string, uint32_t, std::less<>> kFixedSizes = {
        {"box2i", 16},         {"box2f", 16},       {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
        {"double", 8},         {"envmap", 1},       {"float", 4},           {"int", 4},         {"keycode", 28},
        {"lineOrder", 1},      {"m33f", 36},        {"m33d", 72},           {"m44f", 64},       {"m44d", 128},
        {"rational", 8},       {"tiledesc", 9},     {"timecode", 8},        {"v2i", 8},         {"v2f", 8},
        {"v2d", 16},           {"v3i", 12},         {"v3f", 12},            {"v3d", 24}};
    if (const auto fixed = kFixedSizes.find(type); fixed != kFixedSizes.end()) {
      if (value.size() != fixed->second) fail_here(fmt::format("a {} is {} bytes", type, fixed->second));
    } else if (type == "chlist") {
      // Channels: name, NUL, pixel type, pLinear, 3 reserved bytes, x and y sampling; an empty name ends it.
      int channels = 0;
      size_t at = 0;
      for (;; ++channels) {
        if (at >= value.size()) fail_here("the channel list has no terminating empty name inside the value");
        if (value[at] == 0) break;
        const size_t name_start = at;
        while (at < value.size() && value[at] != 0) ++at;
        if (at >= value.size() || at - name_start > 255)
          fail_here(fmt::format("channel {}'s name is not NUL-terminated within 255 bytes", channels));
        const std::string channel(value.data() + name_start, at - name_start);
        ++at;
        if (value.size() - at < 16) fail_here(fmt::format("channel \"{}\" is cut off", channel));
        const uint32_t pixel_type = u32(at);
        const int32_t x_sampling = i32(at + 8), y_sampling = i32(at + 12);
        if (pixel_type > 2)
          fail_here(fmt::format("channel \"{}\" has pixel type {} (expected 0 UINT, 1 HALF or 2 FLOAT)", channel,
                                pixel_type));
        if (x_sampling < 1 || y_sampling < 1)
          fail_here(fmt::format("channel \"{}\" has sampling {} x {} (expected at least 1)", channel, x_sampling,
                                y_sampling));
        at += 16;
        if (channels >= 64) fail_here("more than 64 channels (a light probe needs a handful)");
      }
      if (at + 1 != value.size())
        fail_here(fmt::format("the channel list ends at byte {} of the value, not at its end", at + 1));
      if (channels == 0) fail_here("no channels (an image needs at least one)");
    } else if (type == "string") {
      // read as exactly its size
    } else if (type == "stringvector") {
      for (size_t at = 0; at < value.size();) {
        if (value.size() - at < 4) fail_here(fmt::format("a string's length at byte {} of the value is cut off", at));
        const uint32_t length = u32(at);
        at += 4;
        if (length > value.size() - at)
          fail_here(fmt::format("a string of {} bytes at byte {} of the value overruns it", length, at - 4));
        at += length;
      }
    } else if (type == "floatvector") {
      if (value.size() % 4 != 0) fail_here("a floatvector is a whole number of 4-byte floats");
    } else if (type == "preview") {
      if (value.size() < 8) fail_here("a preview starts with its width and height");
      const uint64_t width = u32(0), height = u32(4);
      if (8 + 4 * width * height != value.size())
        fail_here(fmt::format("a {} x {} preview is {} bytes", width, height, 8 + 4 * width * height));
    } else if (type == "idmanifest") {
      if (value.size() < 4) fail_here("an idmanifest starts with its 4-byte uncompressed size");
    } else if (value.size() > kMaxUnknownAttributeBytes) {
      fail_here(fmt::format("an attribute of a type OpenEXR does not know may hold at most {} bytes",
                            kMaxUnknownAttributeBytes));
    }

    if (attribute == "dataWindow" && type == "box2i") {
      Imath::Box2i window;
      window.min.x = i32(0), window.min.y = i32(4), window.max.x = i32(8), window.max.y = i32(12);
      check_size(window, name_);
      facts_.width = static_cast<uint64_t>(int64_t{window.max.x} - window.min.x + 1);
      facts_.height = static_cast<uint64_t>(int64_t{window.max.y} - window.min.y + 1);
    } else if (attribute == "tiles" && type == "tiledesc") {
      const uint64_t x = u32(0), y = u32(4);
      facts_.tile_x = x, facts_.tile_y = y;
      if (x < 1 || y < 1 || x * y > (uint64_t{1} << 24))
        fail_here(fmt::format("tiles of {} x {} pixels (at most 2^24 pixels a tile)", x, y));
      const unsigned mode = static_cast<unsigned char>(value[8]);
      if ((mode & 0x0f) > 2 || (mode >> 4) > 1)
        fail_here(fmt::format("level mode {} and rounding mode {} (expected 0..2 and 0..1)", mode & 0x0f, mode >> 4));
    } else if (attribute == "compression" && type == "compression") {
      if (static_cast<unsigned char>(value[0]) > 9)
        fail_here(fmt::format("compression {} (OpenEXR knows 0..9)", static_cast<unsigned char>(value[0])));
      facts_.compression = static_cast<unsigned char>(value[0]);
    } else if (attribute == "chunkCount" && type == "int") {
      if (i32(0) < 0) fail_here(fmt::format("a chunk count of {}", i32(0)));
      facts_.chunk_count = static_cast<uint32_t>(i32(0));
    }
  }

  // The library allocates one 8-byte offset per chunk (scanline block or tile) before it reads
  // any: the offset tables must fit in the bytes after the headers. Counted per part; a multi-part
  // file says its count ("chunkCount"), a single-part one follows from the data window,
  // compression and tile size (level 0 only: a lower bound for mipmaps).
  void count_chunks(const std::map<std::string, std::pair<std::string, uint32_t>>& seen) {
    uint64_t chunks = 0;
    if (multipart_) {
      if (!seen.contains("chunkCount")) fail("the required attribute \"chunkCount\" (int) of a multi-part file is missing");
      chunks = facts_.chunk_count;
    } else if (tiled_flag_) {
      chunks = ((facts_.width + facts_.tile_x - 1) / facts_.tile_x) * ((facts_.height + facts_.tile_y - 1) / facts_.tile_y);
    } else {
      static constexpr uint64_t kLinesPerChunk[10] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};  // NONE .. DWAB
      const uint64_t lines = kLinesPerChunk[facts_.compression];
      chunks = (facts_.height + lines - 1) / lines;
    }
    chunks_ += chunks;
    facts_ = {};
  }

  // What count_chunks needs from the header being walked (check_required has made sure each is set).
  struct HeaderFacts {
    uint64_t width = 1, height = 1, tile_x = 1, tile_y = 1, chunk_count = 0;
    unsigned compression = 0;
  };

  std::ifstream in_;
  const std::string& name_;
  uint64_t size_ = 0, position_ = 0;
  bool multipart_ = false;
  bool tiled_flag_ = false;  // single-part tiled file (version flag 0x200): its header needs "tiles"
  HeaderFacts facts_;
  uint64_t chunks_ = 0;  // offset-table entries of all parts so far
};

void append_band(HdrImage& image, int rows) {
  image.rgb.resize(image.rgb.size() + 3 * static_cast<size_t>(image.width) * static_cast<size_t>(rows));
}

HdrImage read_rgb_channels(Imf::InputFile& file) {
  const Imath::Box2i window = file.header().dataWindow();
  HdrImage image;
  image.width = window.max.x - window.min.x + 1;
  image.height = window.max.y - window.min.y + 1;
  for (int y0 = window.min.y; y0 <= window.max.y; y0 += kBand) {
    const int y1 = std::min(window.max.y, y0 + kBand - 1);
    const size_t first = image.rgb.size();
    append_band(image, y1 - y0 + 1);
    float* band = image.rgb.data() + first;
    Imf::FrameBuffer frame;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
      frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, band + c, Imath::V2i(window.min.x, y0), image.width,
                                              y1 - y0 + 1, 3 * sizeof(float), 3 * sizeof(float) * image.width));
    file.setFrameBuffer(frame);
    file.readPixels(y0, y1);
  }
  return image;
}

// Luminance or luminance/chroma files: the library converts them to RGB (half precision).
HdrImage read_through_rgba(Imf::RgbaInputFile& file) {
  const Imath::Box2i window = file.dataWindow();
  HdrImage image;
  image.width = window.max.x - window.min.x + 1;
  image.height = window.max.y - window.min.y + 1;
  std::vector<Imf::Rgba> band(static_cast<size_t>(image.width) * kBand);
  for (int y0 = window.min.y; y0 <= window.max.y; y0 += kBand) {
    const int y1 = std::min(window.max.y, y0 + kBand - 1);
    // The library addresses pixel (x, y) at base + x + y * width; shift with integers so that no
    // out-of-range pointer is ever formed.
    const auto base = reinterpret_cast<uintptr_t>(band.data()) -
                      (static_cast<uintptr_t>(static_cast<intptr_t>(window.min.x)) +
                       static_cast<uintptr_t>(static_cast<intptr_t>(y0)) * static_cast<uintptr_t>(image.width)) *
                          sizeof(Imf::Rgba);
    file.setFrameBuffer(reinterpret_cast<Imf::Rgba*>(base), 1, static_cast<size_t>(image.width));
    file.readPixels(y0, y1);
    const size_t first = image.rgb.size();
    append_band(image, y1 - y0 + 1);
    for (size_t i = 0; i < static_cast<size_t>(image.width) * static_cast<size_t>(y1 - y0 + 1); ++i) {
      image.rgb[first + 3 * i] = band[i].r;
      image.rgb[first + 3 * i + 1] = band[i].g;
      image.rgb[first + 3 * i + 2] = band[i].b;
    }
  }
  return image;
}

}  // namespace

HdrImage read_openexr(const std::filesystem::path& path) {
  const std::string name = path.string();
  try {
    ::close(open_regular_file(path, "OpenEXR image"));  // before any stream opens it: a FIFO would block
  } catch (const FileAccessError& e) {
    throw AssetError(e.what());
  }
  ExrHeaderCheck(path, name).run();
  try {
    bool rgb = false;
    {
      Imf::InputFile file(path.c_str());
      check_size(file.header().dataWindow(), name);
      const Imf::ChannelList& channels = file.header().channels();
      rgb = channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B");
      if (rgb) return read_rgb_channels(file);
    }
    Imf::RgbaInputFile file(path.c_str());
    check_size(file.dataWindow(), name);
    return read_through_rgba(file);
  } catch (const AssetError&) {
    throw;
  } catch (const std::exception& e) {
    throw AssetError(fmt::format("{}: OpenEXR: {}", name, e.what()));
  }
}

void write_openexr(const std::filesystem::path& path, const HdrImage& image) {
  const std::string name = path.string();
  if (image.width < 1 || image.height < 1 || image.width > kMaxHdrSide || image.height > kMaxHdrSide)
    throw AssetError(fmt::format("{}: cannot write a {} x {} image (sides must be 1..{})", name, image.width,
                                 image.height, kMaxHdrSide));
  check_hdr_texels(image, name);
  constexpr float kHalfMax = 65504.0f;
  std::vector<Imf::Rgba> pixels(static_cast<size_t>(image.width) * static_cast<size_t>(image.height));
  for (size_t i = 0; i < pixels.size(); ++i) {
    const float* c = &image.rgb[3 * i];
    const float largest = std::max({c[0], c[1], c[2]});
    if (largest > kHalfMax)
      throw AssetError(fmt::format("{}: pixel ({}, {}): value {} is above half precision's maximum {}; write a "
                                   "Radiance .hdr instead",
                                   name, i % static_cast<size_t>(image.width), i / static_cast<size_t>(image.width),
                                   largest, kHalfMax));
    pixels[i] = Imf::Rgba(c[0], c[1], c[2], 1.0f);
  }
  const std::filesystem::path temporary = name + ".tmp";
  try {
    Imf::RgbaOutputFile file(temporary.c_str(), image.width, image.height, Imf::WRITE_RGB);
    file.setFrameBuffer(pixels.data(), 1, static_cast<size_t>(image.width));
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw AssetError(fmt::format("{}: cannot write: OpenEXR: {}", name, e.what()));
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw AssetError(fmt::format("{}: cannot write: {}", name, ec.message()));
  }
}

}  // namespace arpipe
