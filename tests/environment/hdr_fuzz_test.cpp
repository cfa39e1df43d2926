// Deterministic mutation fuzzing of the HDR readers: valid run-length, flat and old run-length
// Radiance files and an OpenEXR file are mutated (bit flips, byte changes, insertions, deletions,
// truncation, resolution-number changes); each input must either decode to a finite, non-negative
// image of consistent size or throw AssetError. Anything else escaping (or a crash under ASan)
// fails. Seeded std::mt19937_64, so every run tries the same inputs.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "core/image/hdr_file.h"
#include "core/image/openexr_file.h"
#include "core/image/radiance_hdr.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

HdrImage pattern_image(int width, int height) {
  HdrImage image{width, height, std::vector<float>(3 * static_cast<size_t>(width) * height)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)  // runs (x / 5) and literals, over several exponents
        image.rgb[3 * (static_cast<size_t>(y) * width + x) + c] =
            static_cast<float>(std::ldexp(1.0 + 0.1 * ((x / 5 + c) % 7), (x + 3 * y + c) % 9 - 4));
  return image;
}

class Mutator {
 public:
  explicit Mutator(uint64_t seed) : rng_(seed) {}

  std::vector<uint8_t> mutate(std::vector<uint8_t> bytes) {
    const int steps = 1 + pick(3);
    for (int s = 0; s < steps; ++s) {
      if (bytes.empty()) bytes.push_back(0);
      const size_t at = static_cast<size_t>(pick(static_cast<int>(bytes.size())));
      switch (pick(7)) {
        case 0: bytes[at] ^= static_cast<uint8_t>(1u << pick(8)); break;          // bit flip
        case 1: bytes[at] = static_cast<uint8_t>(pick(256)); break;                // byte change
        case 2: bytes[at] = std::array<uint8_t, 6>{0, 1, 2, 127, 128, 255}[pick(6)]; break;  // edge values
        case 3: bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at), static_cast<uint8_t>(pick(256))); break;
        case 4: bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                            bytes.begin() + static_cast<std::ptrdiff_t>(std::min(bytes.size(), at + 1 + pick(8))));
                break;
        case 5: bytes.resize(at); break;                                           // truncation
        case 6: change_number(bytes); break;                                       // header numbers
      }
    }
    return bytes;
  }

 private:
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }

  // Replaces one decimal number among the first 80 bytes (the Radiance resolution line) with an
  // edge value: 0, 1, 7, 8, 9, 32767, 32768, 32769, 16384, 99999.
  void change_number(std::vector<uint8_t>& bytes) {
    std::vector<size_t> starts;
    for (size_t i = 0; i < std::min<size_t>(bytes.size(), 80); ++i)
      if (std::isdigit(bytes[i]) && (i == 0 || !std::isdigit(bytes[i - 1]))) starts.push_back(i);
    if (starts.empty()) return;
    const size_t start = starts[static_cast<size_t>(pick(static_cast<int>(starts.size())))];
    size_t end = start;
    while (end < bytes.size() && std::isdigit(bytes[end])) ++end;
    const std::string value = std::to_string(std::array<int, 10>{0, 1, 7, 8, 9, 32767, 32768, 32769, 16384, 99999}[pick(10)]);
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(start), bytes.begin() + static_cast<std::ptrdiff_t>(end));
    bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(start), value.begin(), value.end());
  }

  std::mt19937_64 rng_;
};

// The outcome the readers promise: a consistent, finite, non-negative image, or AssetError.
struct Outcome {
  int decoded = 0, rejected = 0;
};

void expect_sane(const HdrImage& image, const std::string& what) {
  ASSERT_GE(image.width, 1) << what;
  ASSERT_GE(image.height, 1) << what;
  ASSERT_EQ(image.rgb.size(), 3 * static_cast<size_t>(image.width) * image.height) << what;
  for (float v : image.rgb) ASSERT_TRUE(std::isfinite(v) && v >= 0) << what << ": value " << v;
}

TEST(HdrFuzz, MutatedRadianceAndOpenExrInputsDecodeOrThrowAssetError) {
  const auto start = std::chrono::steady_clock::now();
  const auto dir = hdr_test::scratch_dir();
  // Seeds: run-length (width 40, so new-style scanlines), flat and old run-length Radiance files,
  // and a ZIP-compressed half OpenEXR file.
  const HdrImage image = pattern_image(40, 6);
  write_radiance_hdr(dir / "rle.hdr", image, true);
  write_radiance_hdr(dir / "flat.hdr", pattern_image(7, 5), false);
  write_openexr(dir / "seed.exr", pattern_image(12, 10));
  std::vector<uint8_t> old = hdr_test::bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 3 +X 20\n");
  for (int row = 0; row < 3; ++row)
    hdr_test::append(old, {128, 64, 32, 129 + row, 1, 1, 1, 9, 200, 100, 50, 128, 1, 1, 1, 9});
  const std::vector<std::vector<uint8_t>> radiance_seeds = {hdr_test::read_bytes(dir / "rle.hdr"),
                                                            hdr_test::read_bytes(dir / "flat.hdr"), old};
  const std::vector<uint8_t> exr_seed = hdr_test::read_bytes(dir / "seed.exr");
  for (const auto& seed : radiance_seeds) ASSERT_NO_THROW(decode_radiance_hdr(seed, "seed.hdr"));

  constexpr int kRadianceIterations = 6000, kExrIterations = 2000;
  Mutator mutator(0x5eed'0002);
  Outcome radiance, exr;
  for (int i = 0; i < kRadianceIterations; ++i) {
    const std::vector<uint8_t> input = mutator.mutate(radiance_seeds[static_cast<size_t>(i) % radiance_seeds.size()]);
    try {
      expect_sane(decode_radiance_hdr(input, "fuzz.hdr"), "radiance iteration " + std::to_string(i));
      ++radiance.decoded;
    } catch (const AssetError&) {
      ++radiance.rejected;
    }
    if (HasFatalFailure()) return;
  }
  const double radiance_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (int i = 0; i < kExrIterations; ++i) {
    const std::filesystem::path file = dir / "fuzz.exr";
    hdr_test::write_bytes(file, mutator.mutate(exr_seed));
    try {
      expect_sane(read_hdr_image(file), "exr iteration " + std::to_string(i));  // magic dispatch and texel check
      ++exr.decoded;
    } catch (const AssetError&) {
      ++exr.rejected;
    }
    if (HasFatalFailure()) return;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Both outcomes must occur, or the mutations are too mild (or too harsh) to test anything.
  EXPECT_GT(radiance.decoded, 0);
  EXPECT_GT(radiance.rejected, 0);
  EXPECT_GT(exr.decoded, 0);
  EXPECT_GT(exr.rejected, 0);
  RecordProperty("seconds", std::to_string(seconds));
  std::printf("fuzz: %d Radiance inputs (%d decoded, %d rejected), %d OpenEXR inputs (%d decoded, %d rejected) in %.2f s "
              "(Radiance part %.2f s)\n",
              kRadianceIterations, radiance.decoded, radiance.rejected, kExrIterations, exr.decoded, exr.rejected, seconds,
              radiance_seconds);
}

}  // namespace
}  // namespace arpipe
