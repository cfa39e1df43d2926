// Radiance .hdr (RGBE) reading and writing. The reader checks every count against the bytes that
// are really there, so a corrupt file gives an AssetError that says where, never a crash.
#include "core/image/radiance_hdr.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string_view>

#include "core/config/regular_file.h"
#include "core/image/hdr_file.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

// Flat scanlines of the largest image (4 bytes a pixel) plus a generous header: a longer file holds
// bytes no valid image can use.
constexpr uint64_t kMaxFileBytes = uint64_t(kMaxHdrPixels) * 4 + (uint64_t{1} << 20);

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) text.remove_suffix(1);
  return text;
}

// Where the pixel data starts and how it is laid out, from the header and resolution line.
struct Layout {
  int width = 0, height = 0;
  bool y_major = true;      // scanlines are rows (the usual case) or columns ("+X W -Y H" forms)
  bool top_first = true;    // '-Y': Y decreases along its axis, so its first index is the top row
  bool left_first = true;   // '+X': X increases along its axis, so its first index is column 0
  double exposure = 1.0;    // product of the EXPOSURE= lines
  size_t data_offset = 0;
};

class HeaderParser {
 public:
  HeaderParser(std::span<const uint8_t> bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  Layout parse() {
    Layout layout;
    if (bytes_.size() < 2 || bytes_[0] != '#' || bytes_[1] != '?')
      throw AssetError(fmt::format("{}: byte 0: not a Radiance file: expected \"#?RADIANCE\" or \"#?RGBE\"", name_));
    const std::string_view magic = trimmed(next_line("the magic line"));
    if (!magic.starts_with("#?RADIANCE") && !magic.starts_with("#?RGBE"))
      throw AssetError(fmt::format("{}: header line 1: expected \"#?RADIANCE\" or \"#?RGBE\", found \"{}\"", name_,
                                   printable(magic)));
    for (;;) {
      const std::string_view line = next_line("the blank line that ends the header");
      if (trimmed(line).empty()) break;
      if (line.starts_with("FORMAT=")) check_format(trimmed(line.substr(7)));
      else if (line.starts_with("EXPOSURE=")) layout.exposure *= parse_exposure(trimmed(line.substr(9)));
      // Comments and other variables (SOFTWARE, GAMMA, PRIMARIES, COLORCORR, VIEW, ...) are ignored.
    }
    if (!(std::isfinite(layout.exposure) && layout.exposure > 0))
      throw AssetError(fmt::format("{}: header: the product of the EXPOSURE= values ({}) is not a positive finite number",
                                   name_, layout.exposure));
    parse_resolution(next_line("the resolution line (\"-Y height +X width\")"), layout);
    layout.data_offset = pos_;
    return layout;
  }

 private:
  std::string_view next_line(std::string_view expected) {
    const auto begin = bytes_.begin() + static_cast<std::ptrdiff_t>(pos_);
    const auto end = std::find(begin, bytes_.end(), uint8_t{'\n'});
    ++line_;
    if (end == bytes_.end())
      throw AssetError(fmt::format("{}: header line {} (byte {}): the file ends before {}", name_, line_, pos_, expected));
    const std::string_view line(reinterpret_cast<const char*>(&*begin), static_cast<size_t>(end - begin));
    pos_ += line.size() + 1;
    return line;
  }

  static std::string printable(std::string_view text) {
    std::string out;
    for (char c : text.substr(0, 60)) out += (c >= 32 && c < 127) ? c : '?';
    return out;
  }

  void check_format(std::string_view format) const {
    if (format == "32-bit_rle_rgbe") return;
    if (format == "32-bit_rle_xyze")
      throw AssetError(fmt::format("{}: header line {}: FORMAT=32-bit_rle_xyze (CIE XYZ pixels) is not supported; "
                                   "expected FORMAT=32-bit_rle_rgbe (convert with Radiance's ra_xyze -r)",
                                   name_, line_));
    throw AssetError(fmt::format("{}: header line {}: unknown FORMAT=\"{}\", expected FORMAT=32-bit_rle_rgbe", name_,
                                 line_, printable(format)));
  }

  double parse_exposure(std::string_view text) const {
    const std::string value(text);
    char* end = nullptr;
    errno = 0;
    const double exposure = std::strtod(value.c_str(), &end);
    if (value.empty() || end != value.c_str() + value.size() || errno != 0 || !std::isfinite(exposure) ||
        exposure <= 0)
      throw AssetError(fmt::format("{}: header line {}: EXPOSURE=\"{}\" is not a positive number", name_, line_,
                                   printable(text)));
    return exposure;
  }

  // One axis of the resolution line: sign and letter ("-Y"), then a size in 1..32768.
  int parse_size(std::string_view token, std::string_view axis) const {
    if (token.empty() || token.size() > 6 || !std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; }))
      throw AssetError(fmt::format("{}: resolution line (header line {}): expected a size for {}, found \"{}\"", name_,
                                   line_, axis, printable(token)));
    const int size = std::stoi(std::string(token));
    if (size < 1 || size > kMaxHdrSide)
      throw AssetError(fmt::format("{}: resolution line (header line {}): {} size {} is outside 1..{}", name_, line_,
                                   axis, size, kMaxHdrSide));
    return size;
  }

  void parse_resolution(std::string_view line, Layout& layout) const {
    std::array<std::string_view, 4> tokens;
    size_t count = 0;
    std::string_view rest = line;
    while (!rest.empty()) {
      const size_t start = rest.find_first_not_of(' ');
      if (start == std::string_view::npos) break;
      rest.remove_prefix(start);
      const size_t stop = std::min(rest.find(' '), rest.size());
      if (count == 4) { count = 5; break; }
      tokens[count++] = rest.substr(0, stop);
      rest.remove_prefix(stop);
    }
    const auto axis_ok = [](std::string_view t) { return t.size() == 2 && (t[0] == '-' || t[0] == '+') && (t[1] == 'X' || t[1] == 'Y'); };
    if (count != 4 || !axis_ok(tokens[0]) || !axis_ok(tokens[2]) || tokens[0][1] == tokens[2][1])
      throw AssetError(fmt::format("{}: resolution line (header line {}): expected \"-Y height +X width\" (or another "
                                   "orientation of the two axes), found \"{}\"",
                                   name_, line_, printable(trimmed(line))));
    layout.y_major = tokens[0][1] == 'Y';
    const std::string_view y_sign = layout.y_major ? tokens[0] : tokens[2];
    const std::string_view x_sign = layout.y_major ? tokens[2] : tokens[0];
    layout.top_first = y_sign[0] == '-';
    layout.left_first = x_sign[0] == '+';
    layout.height = parse_size(layout.y_major ? tokens[1] : tokens[3], "Y (height)");
    layout.width = parse_size(layout.y_major ? tokens[3] : tokens[1], "X (width)");
    if (int64_t{layout.width} * layout.height > kMaxHdrPixels)
      throw AssetError(fmt::format("{}: resolution line (header line {}): {} x {} pixels is more than the 2^28 allowed",
                                   name_, line_, layout.width, layout.height));
  }

  std::span<const uint8_t> bytes_;
  const std::string& name_;
  size_t pos_ = 0;
  int line_ = 0;
};

// Decodes the scanlines into RGBE quadruples, in file order. Memory grows with the data actually
// decoded, so a corrupt header cannot make it reserve gigabytes for a short file.
class ScanlineDecoder {
 public:
  ScanlineDecoder(std::span<const uint8_t> bytes, const std::string& name, const Layout& layout)
      : bytes_(bytes), name_(name), pos_(layout.data_offset),
        length_(layout.y_major ? layout.width : layout.height),
        count_(layout.y_major ? layout.height : layout.width) {}

  std::vector<uint8_t> decode() {
    std::vector<uint8_t> rgbe;
    for (scanline_ = 0; scanline_ < count_; ++scanline_) {
      const size_t start = rgbe.size();
      rgbe.resize(start + 4 * static_cast<size_t>(length_));
      uint8_t* line = rgbe.data() + start;
      if (length_ >= 8 && length_ <= 0x7fff && pos_ + 4 <= bytes_.size() && bytes_[pos_] == 2 &&
          bytes_[pos_ + 1] == 2 && (bytes_[pos_ + 2] & 0x80) == 0)
        decode_new_rle(line);
      else
        decode_flat_or_old_rle(line, start == 0 ? nullptr : line - 4);
    }
    return rgbe;
  }

 private:
  [[noreturn]] void fail(size_t byte, std::string_view what) const {
    throw AssetError(fmt::format("{}: scanline {} of {} (byte {}): {}", name_, scanline_ + 1, count_, byte, what));
  }
  uint8_t take(std::string_view expected) {
    if (pos_ >= bytes_.size()) fail(pos_, fmt::format("the file ends where {} was expected", expected));
    return bytes_[pos_++];
  }

  // 0x02 0x02 hi lo, then each of the four channels: count > 128 is a run of count - 128 copies of
  // the next byte, otherwise count literal bytes follow.
  void decode_new_rle(uint8_t* line) {
    const size_t start = pos_;
    const int declared = bytes_[pos_ + 2] << 8 | bytes_[pos_ + 3];
    if (declared != length_)
      fail(start, fmt::format("run-length scanline declares {} pixels, expected the image's {}", declared, length_));
    pos_ += 4;
    for (int channel = 0; channel < 4; ++channel) {
      for (int i = 0; i < length_;) {
        const size_t at = pos_;
        const int code = take("a run-length count");
        const int n = code > 128 ? code - 128 : code;
        if (i + n > length_)
          fail(at, fmt::format("run-length data overruns the {}-pixel width (channel {}, pixel {}, count {})", length_,
                               channel, i, n));
        if (code > 128) {
          const uint8_t value = take("the byte of a run");
          for (int k = 0; k < n; ++k) line[4 * (i + k) + channel] = value;
        } else {
          if (bytes_.size() - pos_ < static_cast<size_t>(n))
            fail(pos_, fmt::format("the file ends inside a literal of {} bytes (channel {}, pixel {})", n, channel, i));
          for (int k = 0; k < n; ++k) line[4 * (i + k) + channel] = bytes_[pos_++];
        }
        i += n;
      }
    }
  }

  // Four bytes per pixel; in old-style run-length files (1, 1, 1, n) repeats the previous pixel
  // n << shift times, shift growing by 8 for each consecutive repeat (Radiance's oldreadcolrs).
  void decode_flat_or_old_rle(uint8_t* line, const uint8_t* previous_line_end) {
    int shift = 0;
    for (int i = 0; i < length_;) {
      if (bytes_.size() - pos_ < 4)
        fail(pos_, fmt::format("the file ends inside pixel {} of {} (4 bytes each)", i + 1, length_));
      const uint8_t* pixel = &bytes_[pos_];
      if (pixel[0] == 1 && pixel[1] == 1 && pixel[2] == 1) {
        const uint8_t* source = i > 0 ? line + 4 * (i - 1) : previous_line_end;
        if (source == nullptr) fail(pos_, "an old-style run-length repeat comes before any pixel");
        if (shift > 16) fail(pos_, "more than three consecutive old-style run-length repeats");
        const int64_t n = int64_t{pixel[3]} << shift;
        if (i + n > length_)
          fail(pos_, fmt::format("old-style run-length repeat of {} overruns the {}-pixel width at pixel {}", n,
                                 length_, i));
        std::array<uint8_t, 4> value;
        std::memcpy(value.data(), source, 4);
        for (int64_t k = 0; k < n; ++k) std::memcpy(line + 4 * (i + k), value.data(), 4);
        i += static_cast<int>(n);
        shift += 8;
      } else {
        std::memcpy(line + 4 * i, pixel, 4);
        ++i;
        shift = 0;
      }
      pos_ += 4;
    }
  }

  std::span<const uint8_t> bytes_;
  const std::string& name_;
  size_t pos_;
  int length_, count_, scanline_ = 0;
};

std::string errno_text() { return std::strerror(errno); }

// Ward's encoding: the largest channel v = f 2^e with f in [0.5, 1); each channel's byte is
// floor(c 2^(8 - e)) (exact in double, so the largest byte is in 128..255), exponent byte e + 128.
std::array<uint8_t, 4> encode_rgbe(double r, double g, double b) {
  const double v = std::max({r, g, b});
  if (v < 1e-32) return {0, 0, 0, 0};
  int e = 0;
  std::frexp(v, &e);
  const auto byte = [e](double c) { return static_cast<uint8_t>(std::floor(std::ldexp(c, 8 - e))); };
  return {byte(r), byte(g), byte(b), static_cast<uint8_t>(e + 128)};
}

// Ward's new-style run-length encoding of one channel: runs of 4 or more equal bytes (at most 127)
// as 128 + n, value; everything else as literals of at most 128 bytes.
void encode_channel_rle(const std::vector<uint8_t>& data, std::string& out) {
  const size_t n = data.size();
  size_t i = 0;
  while (i < n) {
    size_t literal_end = i;  // grow a literal until a run of >= 4 starts
    size_t run = 1;
    while (literal_end < n) {
      run = 1;
      while (literal_end + run < n && run < 127 && data[literal_end + run] == data[literal_end]) ++run;
      if (run >= 4) break;
      literal_end += run;
    }
    literal_end = std::min(literal_end, n);
    while (i < literal_end) {
      const size_t count = std::min<size_t>(128, literal_end - i);
      out += static_cast<char>(count);
      out.append(reinterpret_cast<const char*>(&data[i]), count);
      i += count;
    }
    if (i < n && run >= 4) {
      out += static_cast<char>(128 + run);
      out += static_cast<char>(data[i]);
      i += run;
    }
  }
}

}  // namespace

HdrImage decode_radiance_hdr(std::span<const uint8_t> bytes, const std::string& name) {
  const Layout layout = HeaderParser(bytes, name).parse();
  const std::vector<uint8_t> rgbe = ScanlineDecoder(bytes, name, layout).decode();

  HdrImage image;
  image.width = layout.width;
  image.height = layout.height;
  image.rgb.resize(3 * static_cast<size_t>(layout.width) * static_cast<size_t>(layout.height));
  // Walter's decode: E == 0 is black, otherwise byte * 2^(E - 136); then undo EXPOSURE.
  std::array<double, 256> factor{};
  for (int e = 1; e < 256; ++e) factor[e] = std::ldexp(1.0, e - 136) / layout.exposure;
  const int length = layout.y_major ? layout.width : layout.height;
  const size_t pixels = static_cast<size_t>(layout.width) * static_cast<size_t>(layout.height);
  for (size_t k = 0; k < pixels; ++k) {
    const int s = static_cast<int>(k / static_cast<size_t>(length)), i = static_cast<int>(k % static_cast<size_t>(length));
    const int along_y = layout.y_major ? s : i, along_x = layout.y_major ? i : s;
    const int y = layout.top_first ? along_y : layout.height - 1 - along_y;
    const int x = layout.left_first ? along_x : layout.width - 1 - along_x;
    const uint8_t* q = &rgbe[4 * k];
    float* out = &image.rgb[3 * (static_cast<size_t>(y) * static_cast<size_t>(layout.width) + static_cast<size_t>(x))];
    for (int c = 0; c < 3; ++c) {
      out[c] = static_cast<float>(q[c] * factor[q[3]]);
      if (!std::isfinite(out[c]))
        throw AssetError(fmt::format("{}: pixel ({}, {}): RGBE ({}, {}, {}, {}) divided by EXPOSURE {} overflows single "
                                     "precision",
                                     name, x, y, q[0], q[1], q[2], q[3], layout.exposure));
    }
  }
  return image;
}

HdrImage read_radiance_hdr(const std::filesystem::path& file) {
  std::string text;
  try {
    text = read_regular_file(file, "Radiance .hdr image", kMaxFileBytes);
  } catch (const FileAccessError& e) {
    throw AssetError(e.what());
  }
  const auto* bytes = reinterpret_cast<const uint8_t*>(text.data());
  return decode_radiance_hdr(std::span<const uint8_t>(bytes, text.size()), file.string());
}

void write_radiance_hdr(const std::filesystem::path& file, const HdrImage& image, bool run_length) {
  const std::string name = file.string();
  if (image.width < 1 || image.height < 1 || image.width > kMaxHdrSide || image.height > kMaxHdrSide)
    throw AssetError(fmt::format("{}: cannot write a {} x {} image (sides must be 1..{})", name, image.width,
                                 image.height, kMaxHdrSide));
  check_hdr_texels(image, name);

  std::string out = fmt::format("#?RADIANCE\nSOFTWARE=arpipe\nFORMAT=32-bit_rle_rgbe\n\n-Y {} +X {}\n", image.height,
                                image.width);
  const bool rle = run_length && image.width >= 8 && image.width <= 0x7fff;
  std::array<std::vector<uint8_t>, 4> channels;
  for (auto& channel : channels) channel.resize(static_cast<size_t>(image.width));
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Vec3 c = image.at(x, y);
      if (std::max({c[0], c[1], c[2]}) >= std::ldexp(1.0, 127))
        throw AssetError(fmt::format("{}: pixel ({}, {}): value {} is beyond RGBE's range (2^127)", name, x, y,
                                     std::max({c[0], c[1], c[2]})));
      const std::array<uint8_t, 4> rgbe = encode_rgbe(c[0], c[1], c[2]);
      if (rle)
        for (int k = 0; k < 4; ++k) channels[k][static_cast<size_t>(x)] = rgbe[k];
      else
        out.append(reinterpret_cast<const char*>(rgbe.data()), 4);
    }
    if (rle) {
      out += {char{2}, char{2}, static_cast<char>(image.width >> 8), static_cast<char>(image.width & 0xff)};
      for (const auto& channel : channels) encode_channel_rle(channel, out);
    }
  }

  const std::filesystem::path temporary = name + ".tmp";
  {
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    if (!stream) throw AssetError(fmt::format("{}: cannot write: {}", name, errno_text()));
    stream.write(out.data(), static_cast<std::streamsize>(out.size()));
    stream.close();
    if (!stream) {
      const std::string why = errno_text();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw AssetError(fmt::format("{}: cannot write: {}", name, why));
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw AssetError(fmt::format("{}: cannot write: {}", name, ec.message()));
  }
}

}  // namespace arpipe
