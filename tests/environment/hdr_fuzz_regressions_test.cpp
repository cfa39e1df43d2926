// Reproducers the fuzz targets found in the HDR readers (tests/fuzz/regressions), and constructed
// headers for each rule of the OpenEXR header walk: each is a clean AssetError naming the file and
// the byte, before the OpenEXR library allocates from a header it trusts.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/image/openexr_file.h"
#include "core/scene/asset_error.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using hdr_test::asset_error_message;
using hdr_test::scratch_dir;
using hdr_test::write_bytes;

fs::path reproducer(const std::string& name) {
  return fs::path(ARPIPE_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "fuzz_openexr" / name;
}

TEST(HdrFuzzRegressions, AnExrHeaderWithoutItsRequiredAttributesIsRefused) {
  // A tiled file whose only attribute is a chlist "c" of 0 bytes: the library reads a channel list
  // up to its empty name whatever the size says, took defaults and allocated 2 GB.
  const fs::path file = reproducer("header-attribute-2gb-alloc.exr");
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte 21): attribute \"c\" (chlist, 0 bytes): the channel list has no "
                            "terminating empty name inside the value");
}

TEST(HdrFuzzRegressions, AnExrHeaderWithGarbledRepeatedAttributesIsRefused) {
  // "channels" holds a channel of pixel type 0xc0001; later "channels", "compression" and
  // "dataWindow" come again, garbled, and the library allocated 1.7 GB for one of them.
  const fs::path file = reproducer("header-attribute-1.7gb-alloc-2.exr");
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte 28): attribute \"channels\" (chlist, 19 bytes): channel \"Y\" "
                            "has pixel type 786433 (expected 0 UINT, 1 HALF or 2 FLOAT)");
}

// A minimal single-part scanline file: one HALF channel "R", 1 x 1 pixel, no compression, built
// attribute by attribute so that each test can change one thing.
struct ExrBuilder {
  std::vector<uint8_t> bytes{0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};

  void u32(uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<uint8_t>(v >> (8 * k)));
  }
  void f32(float v) {
    uint32_t bits = 0;
    std::memcpy(&bits, &v, 4);
    u32(bits);
  }
  void text(const std::string& s) {
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
  }
  // An attribute whose value is written by `value`; its declared size is what was written plus `extra`.
  template <typename F>
  void attribute(const std::string& name, const std::string& type, F value, int extra = 0) {
    text(name);
    text(type);
    const size_t size_at = bytes.size();
    u32(0);
    const size_t start = bytes.size();
    value();
    const auto size = static_cast<uint32_t>(static_cast<int>(bytes.size() - start) + extra);
    for (int k = 0; k < 4; ++k) bytes[size_at + static_cast<size_t>(k)] = static_cast<uint8_t>(size >> (8 * k));
  }
  void channels(int extra = 0) {
    attribute("channels", "chlist", [&] {
      text("R");
      u32(1);  // HALF
      u32(0);  // pLinear, reserved
      u32(1), u32(1);
      bytes.push_back(0);
      for (int k = 0; k < extra; ++k) bytes.push_back(0);
    });
  }
  void window(const std::string& name, int width = 1, int height = 1) {
    attribute(name, "box2i", [&] { u32(0), u32(0), u32(static_cast<uint32_t>(width - 1)), u32(static_cast<uint32_t>(height - 1)); });
  }
  void others() {
    attribute("compression", "compression", [&] { bytes.push_back(0); });
    window("displayWindow");
    attribute("lineOrder", "lineOrder", [&] { bytes.push_back(0); });
    attribute("pixelAspectRatio", "float", [&] { f32(1); });
    attribute("screenWindowCenter", "v2f", [&] { f32(0), f32(0); });
    attribute("screenWindowWidth", "float", [&] { f32(1); });
  }
  // The header's end, the offset table and the one scanline (y, size, one half: 0x3c00 = 1.0).
  void end_and_pixels() {
    bytes.push_back(0);
    const uint32_t chunk = static_cast<uint32_t>(bytes.size() + 8);
    u32(chunk), u32(0);
    u32(0), u32(2);
    bytes.push_back(0x00), bytes.push_back(0x3c);
  }
};

fs::path write_exr(const ExrBuilder& exr) {
  const fs::path file = scratch_dir() / "probe.exr";
  write_bytes(file, exr.bytes);
  return file;
}

TEST(HdrFuzzRegressions, TheMinimalExrHeaderDecodes) {
  ExrBuilder exr;
  exr.channels();
  exr.window("dataWindow");
  exr.others();
  exr.end_and_pixels();
  const HdrImage image = read_openexr(write_exr(exr));
  ASSERT_EQ(image.width, 1);
  ASSERT_EQ(image.height, 1);
  EXPECT_EQ(image.rgb[0], 1.0f);
  EXPECT_EQ(image.rgb[1], 0.0f);  // G and B missing: read as 0
  EXPECT_EQ(image.rgb[2], 0.0f);
}

TEST(HdrFuzzRegressions, ARepeatedExrAttributeIsRefused) {
  ExrBuilder exr;
  exr.channels();
  const size_t first = exr.bytes.size();
  exr.window("dataWindow");
  exr.others();
  const size_t second = exr.bytes.size();
  exr.window("dataWindow", 4, 4);
  exr.end_and_pixels();
  const fs::path file = write_exr(exr);
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte " + std::to_string(second) +
                "): attribute \"dataWindow\" appears a second time (first at byte " + std::to_string(first) + ")");
}

TEST(HdrFuzzRegressions, AnExrChannelListShorterThanItsDeclaredSizeIsRefused) {
  // The library stops at the empty name and reads the padding as the next attribute's name.
  ExrBuilder exr;
  exr.channels(/*extra=*/3);
  exr.window("dataWindow");
  exr.others();
  exr.end_and_pixels();
  const fs::path file = write_exr(exr);
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte 28): attribute \"channels\" (chlist, 22 bytes): the channel list "
                            "ends at byte 19 of the value, not at its end");
}

TEST(HdrFuzzRegressions, AnExrAttributeOfAFixedSizeTypeMustHaveThatSize) {
  // The library reads a box2i as 16 bytes whatever the size says.
  ExrBuilder exr;
  exr.channels();
  const size_t window_at = exr.bytes.size();
  exr.attribute("dataWindow", "box2i", [&] { exr.u32(0), exr.u32(0), exr.u32(0), exr.u32(0); }, /*extra=*/4);
  exr.others();
  exr.end_and_pixels();
  const fs::path file = write_exr(exr);
  // The declared size runs 4 bytes into what follows; the walk refuses it by the type's layout.
  const size_t value_at = window_at + std::string("dataWindow").size() + 1 + std::string("box2i").size() + 1 + 4;
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte " + std::to_string(value_at) +
                "): attribute \"dataWindow\" (box2i, 20 bytes): a box2i is 16 bytes");
}

TEST(HdrFuzzRegressions, ALargeExrAttributeOfAnUnknownTypeIsRefused) {
  // The library allocates an unknown type's declared size and keeps it as opaque bytes.
  ExrBuilder exr;
  exr.channels();
  exr.window("dataWindow");
  exr.others();
  const size_t note_at = exr.bytes.size();
  exr.attribute("note", "blob", [&] { exr.bytes.resize(exr.bytes.size() + 65537, 0); });
  exr.end_and_pixels();
  const fs::path file = write_exr(exr);
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte " + std::to_string(note_at + 5 + 5 + 4) +
                "): attribute \"note\" (blob, 65537 bytes): an attribute of a type OpenEXR does not know may hold at "
                "most 65536 bytes");
}

TEST(HdrFuzzRegressions, AnExrPreviewMustHoldItsDeclaredPixels) {
  // The library allocates width x height preview pixels from the first 8 bytes.
  ExrBuilder exr;
  exr.channels();
  exr.window("dataWindow");
  exr.others();
  const size_t preview_at = exr.bytes.size();
  exr.attribute("preview", "preview", [&] { exr.u32(30000), exr.u32(30000); });
  exr.end_and_pixels();
  const fs::path file = write_exr(exr);
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte " + std::to_string(preview_at + 8 + 8 + 4) +
                "): attribute \"preview\" (preview, 8 bytes): a 30000 x 30000 preview is 3600000008 bytes");
}

TEST(HdrFuzzRegressions, AnExrOffsetTableLongerThanTheFileIsRefused) {
  // 30000 rows without compression are 30000 chunks: a 240000-byte offset table the library
  // allocates before reading it.
  ExrBuilder exr;
  exr.channels();
  exr.window("dataWindow", 1, 30000);
  exr.others();
  exr.end_and_pixels();
  const fs::path file = write_exr(exr);
  const size_t header_end = exr.bytes.size() - 18;
  EXPECT_EQ(asset_error_message([&] { read_openexr(file); }),
            file.string() + ": OpenEXR header (byte " + std::to_string(header_end) +
                "): the header(s) declare 30000 chunks, whose offset table (240000 bytes) is longer than the 18 bytes "
                "left in the file");
}

}  // namespace
}  // namespace arpipe
