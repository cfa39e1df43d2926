// The PRT cache: content key (XXH3-128), a small checksummed binary file, atomic writes.
#include "render/prt/prt_cache.h"

#include "core/config/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <fmt/format.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "core/sh/sh_basis.h"
#include "render/prt/prt_bake.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "ARPIPE-PRT\n";
constexpr size_t kKeyChars = 32;
constexpr size_t kHeaderBytes = kMagic.size() + 4 + kKeyChars + 4 + 4 + 8 + 4;  // 67
constexpr size_t kChecksumBytes = 8;

// The cache stores little-endian numbers; the byte order is written out explicitly.
void put_u32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xffu));
}
void put_u64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(char((v >> (8 * i)) & 0xffu));
}
uint32_t get_u32(const std::string& in, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(in[at + size_t(i)])) << (8 * i);
  return v;
}
uint64_t get_u64(const std::string& in, size_t at) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(in[at + size_t(i)])) << (8 * i);
  return v;
}

struct StateDeleter {
  void operator()(XXH3_state_t* state) const { XXH3_freeState(state); }
};

class KeyHasher {
 public:
  KeyHasher() : state_(XXH3_createState()) {
    if (!state_ || XXH3_128bits_reset(state_.get()) == XXH_ERROR)
      throw std::runtime_error("xxHash: cannot start a hash");
  }
  void bytes(const void* data, size_t size) { XXH3_128bits_update(state_.get(), data, size); }
  // Numbers in little-endian order, so the key is the same on every host.
  void u64(uint64_t v) {
    std::string le;
    put_u64(le, v);
    bytes(le.data(), le.size());
  }
  void u32(uint32_t v) {
    std::string le;
    put_u32(le, v);
    bytes(le.data(), le.size());
  }
  void f64(double v) { u64(std::bit_cast<uint64_t>(v)); }
  void floats(const std::vector<float>& values) {
    u64(values.size());
    for (float f : values) u32(std::bit_cast<uint32_t>(f));
  }
  void u32s(const std::vector<uint32_t>& values) {
    u64(values.size());
    for (uint32_t v : values) u32(v);
  }
  std::string hex() const {
    XXH128_canonical_t canonical;
    XXH128_canonicalFromHash(&canonical, XXH3_128bits_digest(state_.get()));
    std::string out;
    for (unsigned char byte : canonical.digest) out += fmt::format("{:02x}", byte);
    return out;
  }

 private:
  std::unique_ptr<XXH3_state_t, StateDeleter> state_;
};

uint32_t kind_code(TransferKind kind) {
  switch (kind) {
    case TransferKind::Unshadowed:
      return 0;
    case TransferKind::Shadowed:
      return 1;
    case TransferKind::Interreflected:
      return 2;
  }
  return 1;
}

std::optional<PrtTransfer> reject(std::string* why_not, std::string reason) {
  if (why_not) *why_not = std::move(reason);
  return std::nullopt;
}

std::string errno_text() { return std::error_code(errno, std::generic_category()).message(); }

}  // namespace

std::string prt_cache_key(const Mesh& mesh, const PrtBakeSettings& settings) {
  KeyHasher h;
  h.bytes(kMagic.data(), kMagic.size());
  h.u32(kPrtCacheVersion);
  h.floats(mesh.positions);
  h.floats(mesh.normals);
  h.u32s(mesh.indices);
  const bool colours = settings.kind == TransferKind::Interreflected;
  h.u64(mesh.parts.size());
  for (const MeshPart& part : mesh.parts) {
    h.u32(part.first_index);
    h.u32(part.index_count);
    if (colours)
      for (float c : part.base_color) h.u32(std::bit_cast<uint32_t>(c));
  }
  h.u32(kind_code(settings.kind));
  h.u32(uint32_t(settings.bands));
  h.u32(uint32_t(settings.samples_per_axis));
  h.u64(settings.seed);
  h.f64(settings.ray_offset);
  return h.hex();
}

fs::path prt_cache_file(const fs::path& cache_dir, const std::string& key) { return cache_dir / (key + ".prt"); }

namespace {

// Reads exactly `size` bytes at the file's current position (false on error or early end).
bool read_exactly(int fd, char* out, size_t size) {
  for (size_t done = 0; done < size;) {
    const ssize_t n = ::read(fd, out + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

std::optional<PrtTransfer> read_checked_prt_cache(const fs::path& file, const std::string& key, std::string* why_not,
                                                  const std::optional<PrtCacheShape>& expected) {
  if (!fs::exists(fs::symlink_status(file))) return reject(why_not, fmt::format("{}: no cache file", file.string()));
  // The project's regular-file rule: a FIFO in the cache directory must not block, nor a device feed it.
  int fd = -1;
  try {
    fd = open_regular_file(file, "PRT cache");
  } catch (const FileAccessError& error) {
    return reject(why_not, error.what());
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0) return reject(why_not, fmt::format("{}: cannot stat: {}", file.string(), errno_text()));
  const uint64_t size = uint64_t(std::max<off_t>(info.st_size, 0));
  if (size > kMaxPrtCacheBytes)
    return reject(why_not, fmt::format("{}: {} bytes, over the limit of {} bytes for a cache file", file.string(), size,
                                       kMaxPrtCacheBytes));
  // The header first: the size it implies is checked against the file before the body is read.
  std::string data(std::min<uint64_t>(size, kHeaderBytes), '\0');
  if (!read_exactly(fd, data.data(), data.size())) return reject(why_not, fmt::format("{}: read error", file.string()));
  if (data.size() < kMagic.size() || std::string_view(data).substr(0, kMagic.size()) != kMagic)
    return reject(why_not, fmt::format("{}: not a PRT cache file (no \"ARPIPE-PRT\" magic)", file.string()));
  if (size < kHeaderBytes + kChecksumBytes)
    return reject(why_not, fmt::format("{}: truncated ({} bytes, the header alone is {})", file.string(), size,
                                       kHeaderBytes + kChecksumBytes));
  const uint32_t version = get_u32(data, 11);
  if (version != kPrtCacheVersion)
    return reject(why_not,
                  fmt::format("{}: format version {}, this build reads {}", file.string(), version, kPrtCacheVersion));
  const uint32_t kind = get_u32(data, 47);
  const uint32_t bands = get_u32(data, 51);
  const uint64_t vertices = get_u64(data, 55);
  const uint32_t samples = get_u32(data, 63);
  if (bands < 1 || bands > uint32_t(kMaxShBands) || kind > 2)
    return reject(why_not, fmt::format("{}: corrupt header (kind {}, bands {})", file.string(), kind, bands));
  if (expected && (vertices != expected->vertices || int(bands) != expected->bands))
    return reject(why_not, fmt::format("{}: does not fit the mesh ({} vertices of {} bands, {} of {} expected)",
                                       file.string(), vertices, bands, expected->vertices, expected->bands));
  const uint64_t per_vertex = uint64_t(bands) * bands * 4;
  if (vertices > (size - kHeaderBytes - kChecksumBytes) / per_vertex)
    return reject(why_not, fmt::format("{}: truncated ({} bytes for {} vertices of {} bands)", file.string(), size,
                                       vertices, bands));
  const uint64_t expected_size = kHeaderBytes + vertices * per_vertex + kChecksumBytes;  // <= size: no overflow
  if (size != expected_size)
    return reject(why_not, fmt::format("{}: {} bytes where {} were expected (trailing data)", file.string(), size,
                                       expected_size));
  data.resize(size_t(size));
  if (!read_exactly(fd, data.data() + kHeaderBytes, data.size() - kHeaderBytes))
    return reject(why_not, fmt::format("{}: read error or the file shrank while being read", file.string()));
  const uint64_t stored = get_u64(data, size_t(size) - kChecksumBytes);
  const uint64_t actual = XXH3_64bits(data.data(), size_t(size) - kChecksumBytes);
  if (stored != actual)
    return reject(why_not, fmt::format("{}: corrupt (checksum {:016x}, the data hashes to {:016x})", file.string(),
                                       stored, actual));
  const std::string_view stored_key = std::string_view(data).substr(15, kKeyChars);
  if (stored_key != key)
    return reject(why_not, fmt::format("{}: holds key {}, not {}", file.string(), stored_key, key));
  PrtTransfer transfer;
  transfer.kind = kind == 0   ? TransferKind::Unshadowed
                  : kind == 1 ? TransferKind::Shadowed
                              : TransferKind::Interreflected;
  transfer.bands = int(bands);
  transfer.samples_per_axis = int(std::min<uint32_t>(samples, uint32_t(std::numeric_limits<int>::max())));
  transfer.coefficients.resize(size_t(vertices) * bands * bands);
  for (size_t i = 0; i < transfer.coefficients.size(); ++i)
    transfer.coefficients[i] = std::bit_cast<float>(get_u32(data, kHeaderBytes + 4 * i));
  if (why_not) why_not->clear();
  return transfer;
}

}  // namespace

std::optional<PrtTransfer> read_prt_cache(const fs::path& file, const std::string& key, std::string* why_not,
                                          std::optional<PrtCacheShape> expected) {
  try {
    return read_checked_prt_cache(file, key, why_not, expected);
  } catch (const std::exception& e) {  // out of memory for a large, plausible file: still only a miss
    return reject(why_not, fmt::format("{}: cannot read: {}", file.string(), e.what()));
  }
}

void write_prt_cache(const fs::path& file, const std::string& key, const PrtTransfer& transfer) {
  if (key.size() != kKeyChars)
    throw std::invalid_argument(fmt::format("PRT cache {}: the key must have {} characters", file.string(), kKeyChars));
  std::string data(kMagic);
  put_u32(data, kPrtCacheVersion);
  data += key;
  put_u32(data, kind_code(transfer.kind));
  put_u32(data, uint32_t(transfer.bands));
  put_u64(data, transfer.vertex_count());
  put_u32(data, uint32_t(std::max(0, transfer.samples_per_axis)));
  if (uint64_t(transfer.coefficients.size()) > (kMaxPrtCacheBytes - kHeaderBytes - kChecksumBytes) / 4)
    throw std::runtime_error(fmt::format("PRT cache {}: {} coefficients would make the file larger than the limit "
                                         "of {} bytes",
                                         file.string(), transfer.coefficients.size(), kMaxPrtCacheBytes));
  data.reserve(data.size() + 4 * transfer.coefficients.size() + kChecksumBytes);
  for (float c : transfer.coefficients) put_u32(data, std::bit_cast<uint32_t>(c));
  put_u64(data, XXH3_64bits(data.data(), data.size()));

  const fs::path dir = file.parent_path();
  std::error_code error;
  if (!dir.empty()) {
    fs::create_directories(dir, error);
    if (error)
      throw std::runtime_error(fmt::format("PRT cache: cannot create {}: {}", dir.string(), error.message()));
  }
  // A name of its own per process and call, in the same directory (rename is atomic only there).
  static std::atomic<unsigned> counter{0};
  const fs::path temp = file.string() + fmt::format(".tmp.{}.{}", ::getpid(), counter++);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(fmt::format("PRT cache: cannot create {}: {}", temp.string(), errno_text()));
  auto fail = [&](const char* what) {
    const std::string reason = errno_text();
    ::close(fd);
    ::unlink(temp.c_str());
    throw std::runtime_error(fmt::format("PRT cache: cannot {} {}: {}", what, temp.string(), reason));
  };
  for (size_t written = 0; written < data.size();) {
    const ssize_t n = ::write(fd, data.data() + written, data.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write");
    }
    written += size_t(n);
  }
  if (::fsync(fd) != 0) fail("sync");  // the data is on disk before the name points at it
  if (::close(fd) != 0) {
    const std::string reason = errno_text();
    ::unlink(temp.c_str());
    throw std::runtime_error(fmt::format("PRT cache: cannot close {}: {}", temp.string(), reason));
  }
  if (::rename(temp.c_str(), file.c_str()) != 0) {
    const std::string reason = errno_text();
    ::unlink(temp.c_str());
    throw std::runtime_error(
        fmt::format("PRT cache: cannot rename {} to {}: {}", temp.string(), file.string(), reason));
  }
}

fs::path default_prt_cache_dir() {
  // The XDG base-directory spec ignores relative paths.
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute())
    return fs::path(xdg) / "arpipe" / "prt";
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "arpipe" / "prt";
  return {};
}

PrtLoad load_or_bake_prt(const Mesh& mesh, const PrtBakeSettings& settings, const fs::path& cache_dir,
                         const std::function<void(size_t, size_t)>& progress) {
  PrtLoad load;
  if (cache_dir.empty()) {
    load.transfer = bake_prt(mesh, settings, progress);
    load.baked = true;
    load.note = "no cache directory: baked, not cached";
    return load;
  }
  const std::string key = prt_cache_key(mesh, settings);
  load.file = prt_cache_file(cache_dir, key);
  std::string why_not;
  if (std::optional<PrtTransfer> cached =
          read_prt_cache(load.file, key, &why_not, PrtCacheShape{mesh.vertex_count(), settings.bands})) {
    // A key collision is beyond unlikely, but a transfer that does not fit the mesh is never used.
    if (cached->vertex_count() == mesh.vertex_count() && cached->bands == settings.bands &&
        cached->kind == settings.kind && (mesh.vertex_count() > 0 || cached->coefficients.empty())) {
      load.transfer = std::move(*cached);
      return load;
    }
    why_not = fmt::format("{}: does not fit the mesh ({} vertices of {} bands)", load.file.string(),
                          cached->vertex_count(), cached->bands);
  }
  load.transfer = bake_prt(mesh, settings, progress);
  load.baked = true;
  load.note = why_not;
  try {
    write_prt_cache(load.file, key, load.transfer);
  } catch (const std::exception& e) {
    load.note += fmt::format("; not cached: {}", e.what());
  }
  return load;
}

}  // namespace arpipe
