// Radiance .hdr (RGBE) files: read and write light probes in Ward's format, with its flat,
// old run-length and new (per-channel) run-length scanlines; corrupt input throws AssetError.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "core/image/hdr_image.h"

namespace arpipe {

// Reads a whole .hdr file. Pixels are decoded with B. Walter's convention (E == 0 -> 0, else
// byte * 2^(E - 136)) and divided by the product of the header's EXPOSURE= values, as Radiance
// defines them ("multiplier applied to all pixels; divide by it to get the original values").
// Accepted: magic "#?RADIANCE" or "#?RGBE"; FORMAT=32-bit_rle_rgbe (or no FORMAT line); all eight
// resolution-line orientations ("-Y H +X W" is the standard one); sides 1..32768, at most 2^28
// pixels. Throws AssetError naming the file, the header line or scanline/pixel and byte offset,
// and what was expected.
HdrImage read_radiance_hdr(const std::filesystem::path& file);

// The same from bytes in memory; `name` stands for the file in messages.
HdrImage decode_radiance_hdr(std::span<const uint8_t> bytes, const std::string& name);

// Writes "-Y H +X W" RGBE, Ward's encoding (frexp; channel byte = floor(c * 2^(8 - e))), with
// new-style run-length scanlines when run_length is set and 8 <= width <= 32767, flat otherwise.
// Writes a temporary file next to `file` and renames it, so a failure leaves an existing file
// untouched. Throws AssetError for NaN, infinite or negative texels or values above RGBE's range.
void write_radiance_hdr(const std::filesystem::path& file, const HdrImage& image, bool run_length = true);

}  // namespace arpipe
