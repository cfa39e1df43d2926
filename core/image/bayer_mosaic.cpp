#include "core/image/bayer_mosaic.h"

#include <fmt/format.h>

#include <stdexcept>

namespace arpipe {

int bayer_cell_position_at(BayerOrder order, int x, int y) {
  // Position in the RGGB cell of the pixel at (x, y): each order is RGGB shifted by a column and/or a row.
  int dx = 0, dy = 0;
  switch (order) {
    case BayerOrder::RGGB: break;
    case BayerOrder::GRBG: dx = 1; break;
    case BayerOrder::GBRG: dy = 1; break;
    case BayerOrder::BGGR: dx = 1; dy = 1; break;
  }
  return ((y + dy) & 1) * 2 + ((x + dx) & 1);
}

int bayer_channel_at(BayerOrder order, int x, int y) {
  constexpr int kChannelOfPosition[4] = {0, 1, 1, 2};
  return kChannelOfPosition[bayer_cell_position_at(order, x, y)];
}

int BayerMosaic::channel_at(int x, int y) const { return bayer_channel_at(order, x, y); }
int BayerMosaic::cell_position_at(int x, int y) const { return bayer_cell_position_at(order, x, y); }

void unpack_bayer(const Frame& frame, BayerMosaic& out) {
  const int bits = bayer_bit_depth(frame.format);
  const std::string_view name = pixel_format_name(frame.format);
  if (bits == 0) throw std::invalid_argument(fmt::format("unpack_bayer: {} is not a Bayer format", name));
  if (auto problem = check_image_size(frame.format, frame.width, frame.height))
    throw std::invalid_argument(fmt::format("unpack_bayer: {}", *problem));
  const size_t min_stride = min_bytes_per_line(frame.format, frame.width);
  if (frame.bytes_per_line < min_stride)
    throw std::invalid_argument(fmt::format("unpack_bayer: {} bytes per line is below the {} that {} pixels of {} need",
                                            frame.bytes_per_line, min_stride, frame.width, name));
  // The last row needs only its pixels, not the whole stride (V4L2 buffers may end there).
  if (frame.data.size() / frame.bytes_per_line < size_t(frame.height - 1) ||
      frame.data.size() - size_t(frame.height - 1) * frame.bytes_per_line < min_stride)
    throw std::invalid_argument(fmt::format("unpack_bayer: {} bytes hold fewer than {} rows of {} bytes",
                                            frame.data.size(), frame.height, frame.bytes_per_line));
  out.width = frame.width;
  out.height = frame.height;
  out.order = *bayer_order(frame.format);
  out.bit_depth = bits;
  out.values.resize(size_t(frame.width) * size_t(frame.height));
  const bool packed = is_mipi_packed(frame.format);
  const auto mask = uint16_t((1u << bits) - 1u);
  for (int y = 0; y < frame.height; ++y) {
    const uint8_t* row = frame.data.data() + size_t(y) * frame.bytes_per_line;
    uint16_t* dst = out.values.data() + size_t(y) * size_t(frame.width);
    if (bits == 8) {
      for (int x = 0; x < frame.width; ++x) dst[x] = row[x];
    } else if (!packed) {
      for (int x = 0; x < frame.width; ++x) dst[x] = uint16_t((row[2 * x] | (row[2 * x + 1] << 8)) & mask);
    } else if (bits == 10) {
      for (int x = 0; x < frame.width; x += 4) {
        const uint8_t* group = row + size_t(x / 4) * 5;
        for (int i = 0; i < 4; ++i) dst[x + i] = uint16_t((group[i] << 2) | ((group[4] >> (2 * i)) & 3));
      }
    } else {
      for (int x = 0; x < frame.width; x += 2) {
        const uint8_t* group = row + size_t(x / 2) * 3;
        dst[x] = uint16_t((group[0] << 4) | (group[2] & 15));
        dst[x + 1] = uint16_t((group[1] << 4) | (group[2] >> 4));
      }
    }
  }
}

Frame pack_bayer(const BayerMosaic& mosaic, PixelFormat format) {
  const int bits = bayer_bit_depth(format);
  if (bits == 0 || *bayer_order(format) != mosaic.order || bits != mosaic.bit_depth ||
      mosaic.values.size() != size_t(mosaic.width) * size_t(mosaic.height))
    throw std::invalid_argument(fmt::format("pack_bayer: a {}-bit {} mosaic of {} values cannot become {}", mosaic.bit_depth,
                                            bayer_order_name(mosaic.order), mosaic.values.size(), pixel_format_name(format)));
  Frame frame = Frame::allocate(format, mosaic.width, mosaic.height);
  const bool packed = is_mipi_packed(format);
  const auto mask = uint16_t((1u << bits) - 1u);
  for (int y = 0; y < mosaic.height; ++y) {
    uint8_t* row = frame.data.data() + size_t(y) * frame.bytes_per_line;
    const uint16_t* src = mosaic.values.data() + size_t(y) * size_t(mosaic.width);
    if (bits == 8) {
      for (int x = 0; x < mosaic.width; ++x) row[x] = uint8_t(src[x] & mask);
    } else if (!packed) {
      for (int x = 0; x < mosaic.width; ++x) {
        const uint16_t v = src[x] & mask;
        row[2 * x] = uint8_t(v & 0xff);
        row[2 * x + 1] = uint8_t(v >> 8);
      }
    } else if (bits == 10) {
      for (int x = 0; x < mosaic.width; x += 4) {
        uint8_t* group = row + size_t(x / 4) * 5;
        group[4] = 0;
        for (int i = 0; i < 4; ++i) {
          const uint16_t v = src[x + i] & mask;
          group[i] = uint8_t(v >> 2);
          group[4] = uint8_t(group[4] | ((v & 3) << (2 * i)));
        }
      }
    } else {
      for (int x = 0; x < mosaic.width; x += 2) {
        uint8_t* group = row + size_t(x / 2) * 3;
        const uint16_t a = src[x] & mask, b = src[x + 1] & mask;
        group[0] = uint8_t(a >> 4);
        group[1] = uint8_t(b >> 4);
        group[2] = uint8_t((a & 15) | ((b & 15) << 4));
      }
    }
  }
  return frame;
}

}  // namespace arpipe
