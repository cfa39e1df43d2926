// libFuzzer target: the PRT bake's cache files (render/prt read_prt_cache). Each input is read
// as it is, then again with its trailing XXH3-64 checksum made right, so that the fuzzer gets past
// the checksum to the fields behind it; the expected key is the one the file holds. The reader
// must never throw; a transfer it returns must hold bands^2 coefficients per vertex.
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "render/prt/prt_cache.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/fuzz_temp_dir.h"

namespace {

constexpr size_t kKeyOffset = 15;  // prt_cache.h's file format
constexpr size_t kKeyChars = 32;
constexpr size_t kChecksumBytes = 8;

void read(const std::vector<uint8_t>& bytes) {
  const std::filesystem::path file = arpipe::fuzz::write_temp_file("cache.prt", bytes.data(), bytes.size());
  std::string key(kKeyChars, '0');
  if (bytes.size() >= kKeyOffset + kKeyChars) key.assign(reinterpret_cast<const char*>(&bytes[kKeyOffset]), kKeyChars);
  std::string why_not;
  const std::optional<arpipe::PrtTransfer> transfer = arpipe::read_prt_cache(file, key, &why_not);
  if (!transfer) {
    ARPIPE_FUZZ_CHECK(!why_not.empty(), "a reason for a rejected cache");
    return;
  }
  ARPIPE_FUZZ_CHECK(transfer->bands >= 1, "at least one band");
  const size_t per_vertex = static_cast<size_t>(transfer->bands) * static_cast<size_t>(transfer->bands);
  ARPIPE_FUZZ_CHECK(transfer->coefficients.size() % per_vertex == 0, "bands^2 coefficients per vertex");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  read(bytes);
  if (bytes.size() >= kChecksumBytes) {
    const uint64_t checksum = XXH3_64bits(bytes.data(), bytes.size() - kChecksumBytes);
    std::memcpy(&bytes[bytes.size() - kChecksumBytes], &checksum, kChecksumBytes);  // little-endian host
    read(bytes);
  }
  return 0;
}
