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

constexpr int kMaxSide = 32768;
constexpr int64_t kMaxPixels = int64_t{1} << 28;
constexpr int kBand = 16;  // rows per readPixels call

void check_size(const Imath::Box2i& window, const std::string& name) {
  const int64_t width = int64_t{window.max.x} - window.min.x + 1, height = int64_t{window.max.y} - window.min.y + 1;
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide || width * height > kMaxPixels)
    throw AssetError(fmt::format("{}: data window ({}, {}) - ({}, {}) is {} x {} pixels; expected sides of 1..{} and "
                                 "at most 2^28 pixels",
                                 name, window.min.x, window.min.y, window.max.x, window.max.y, width, height, kMaxSide));
}

// The library trusts the header: an attribute size or a data window from a corrupt file makes it
// allocate gigabytes before it notices the file is short. So walk the header(s) first and check
// every attribute size against the bytes really there, the data window against our limits, tile
// sizes (at most 2^24 pixels a tile) and the channel count (light probes have a handful; at most
// 64), before the library sees the file.
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
    const bool multipart = (version & 0x1000) != 0;
    tiled_flag_ = !multipart && (version & 0x200) != 0;
    for (int part = 0;; ++part) {
      const bool empty = read_header();
      if (!multipart) break;
      if (empty) break;  // multi-part: an empty header ends the list
      if (part > 64) fail("more than 64 parts");
    }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw AssetError(fmt::format("{}: OpenEXR header (byte {}): {}", name_, position_, what));
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
    for (int attributes = 0;; ++attributes) {
      const std::string attribute = read_name("an attribute name");
      if (attribute.empty()) {
        if (attributes > 0) check_required(seen);
        return attributes == 0;
      }
      const std::string type = read_name("an attribute type");
      const uint32_t size = read_u32("an attribute size");
      seen[attribute] = {type, size};
      if (size > size_ - position_)
        fail(fmt::format("attribute \"{}\" declares {} bytes, but only {} follow", attribute, size, size_ - position_));
      std::vector<char> value(size);
      read_bytes(value.data(), size, "an attribute value");
      const auto i32 = [&](size_t at) {
        uint32_t v = 0;
        for (int k = 3; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(value[at + static_cast<size_t>(k)]);
        return static_cast<int32_t>(v);
      };
      if (attribute == "dataWindow" && type == "box2i" && size == 16) {
        Imath::Box2i window;
        window.min.x = i32(0), window.min.y = i32(4), window.max.x = i32(8), window.max.y = i32(12);
        check_size(window, name_);
      } else if (attribute == "tiles" && type == "tiledesc" && size == 9) {
        const uint64_t x = static_cast<uint32_t>(i32(0)), y = static_cast<uint32_t>(i32(4));
        if (x < 1 || y < 1 || x * y > (uint64_t{1} << 24))
          fail(fmt::format("tiles of {} x {} pixels (at most 2^24 pixels a tile)", x, y));
      } else if (attribute == "channels" && type == "chlist") {
        int channels = 0;
        for (size_t at = 0; at < value.size() && value[at] != 0; ++channels) {
          while (at < value.size() && value[at] != 0) ++at;  // the channel's name
          at += 1 + 16;                                      // its terminator, type, pLinear, reserved, sampling
        }
        if (channels > 64) fail(fmt::format("{} channels (a light probe needs a handful; at most 64)", channels));
        if (channels == 0) fail("no channels (an image needs at least one)");
      }
      if (attributes > 10000) fail("more than 10000 attributes");
    }
  }

  std::ifstream in_;
  const std::string& name_;
  uint64_t size_ = 0, position_ = 0;
  bool tiled_flag_ = false;  // single-part tiled file (version flag 0x200): its header needs "tiles"
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
  if (image.width < 1 || image.height < 1 || image.width > kMaxSide || image.height > kMaxSide)
    throw AssetError(fmt::format("{}: cannot write a {} x {} image (sides must be 1..{})", name, image.width,
                                 image.height, kMaxSide));
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
