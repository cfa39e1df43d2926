// A raw Bayer frame's samples as one 16-bit value a pixel, and the unpacking of every Bayer pixel
// format (8/10/12/16-bit, unpacked or MIPI CSI-2 packed) into it and back.
#pragma once

#include <cstdint>
#include <vector>

#include "core/frame.h"

namespace arpipe {

struct BayerMosaic {
  int width = 0;
  int height = 0;
  BayerOrder order = BayerOrder::RGGB;
  int bit_depth = 8;             // values lie in 0 .. 2^bit_depth - 1
  std::vector<uint16_t> values;  // raw code values, rows `width` apart

  // The colour at (x, y): 0 red, 1 green, 2 blue.
  int channel_at(int x, int y) const;
  // The CFA cell position of (x, y), as black levels are given: 0 R, 1 Gr (green on red rows), 2 Gb, 3 B.
  int cell_position_at(int x, int y) const;
};

// The colour (0 R, 1 G, 2 B) and the cell position (0 R, 1 Gr, 2 Gb, 3 B) at (x, y) for a CFA order.
int bayer_channel_at(BayerOrder order, int x, int y);
int bayer_cell_position_at(BayerOrder order, int x, int y);

// Unpacks a Bayer frame, honouring its bytes_per_line. Unpacked 10/12-bit words keep only their low
// bits (a driver's stray high bits are not light). Throws std::invalid_argument naming the problem
// when the frame is not Bayer, its size is not one the format allows, its stride is below the
// format's minimum or its buffer is shorter than height rows of that stride.
void unpack_bayer(const Frame& frame, BayerMosaic& out);
// The inverse, for writers of raw frames (the simulator): the mosaic's values (masked to the
// format's depth) packed into a new frame of `format` with the minimum stride. The mosaic's order
// and depth must be the format's (std::invalid_argument otherwise).
Frame pack_bayer(const BayerMosaic& mosaic, PixelFormat format);

}  // namespace arpipe
