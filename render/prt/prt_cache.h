// The PRT bake's on-disk cache, keyed by the mesh's content and the bake settings, so that a model
// is baked once and loaded afterwards; a stale, foreign or damaged file is re-baked, never trusted.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "core/scene/mesh.h"
#include "render/prt/prt_transfer.h"

namespace arpipe {

// File format ("<key>.prt", all integers and floats little-endian):
//   offset  size  field
//   0       11    magic "ARPIPE-PRT\n"
//   11      4     uint32 format version (kPrtCacheVersion)
//   15      32    the key: prt_cache_key(), 32 lowercase hex characters
//   47      4     uint32 transfer kind: 0 unshadowed, 1 shadowed, 2 interreflected
//   51      4     uint32 bands (bands^2 coefficients per vertex)
//   55      8     uint64 vertex count V
//   63      4     uint32 samples per axis N (the bake used N^2 directions)
//   67      4 V bands^2   float32 coefficients, vertex-major (prt_transfer.h's convention)
//   end-8   8     uint64 XXH3-64 (seed 0) of every byte before it
// A reader rejects a file whose magic, version, size, checksum or key is not the expected one.
inline constexpr uint32_t kPrtCacheVersion = 1;

// Lowercase hex of XXH3-128 over kPrtCacheVersion, the positions, normals and indices (their counts
// and raw float32 / uint32 bytes), the parts' index ranges (and their base colours for
// Interreflected only: the other kinds do not depend on them) and the settings (kind, bands,
// samples per axis, seed, ray offset). 32 characters.
std::string prt_cache_key(const Mesh& mesh, const PrtBakeSettings& settings);

// cache_dir / (key + ".prt").
std::filesystem::path prt_cache_file(const std::filesystem::path& cache_dir, const std::string& key);

// The largest cache file read or written (2 GiB): a bigger transfer is baked but not cached.
inline constexpr uint64_t kMaxPrtCacheBytes = uint64_t{2} << 30;

// What the caller expects a cache file to hold: its mesh's vertex count and the bake's bands.
struct PrtCacheShape {
  uint64_t vertices = 0;
  int bands = 0;
};

// The transfer stored in `file` for `key`; nullopt (with the reason in *why_not) when the file is
// missing or unreadable, not a regular file (a FIFO or device is never opened for blocking reads),
// over kMaxPrtCacheBytes, truncated, corrupt (checksum), of another format version or another key,
// or (given `expected`) of another shape. The file is untrusted: its header is checked against the
// file's size (overflow-checked) before the body is read, so nothing larger than the file, and with
// `expected` nothing larger than the expected transfer, is allocated. Never throws for a bad file.
std::optional<PrtTransfer> read_prt_cache(const std::filesystem::path& file, const std::string& key,
                                          std::string* why_not = nullptr,
                                          std::optional<PrtCacheShape> expected = std::nullopt);

// Writes atomically: the parent directories are created, the data goes to a temporary file in the
// same directory, which is then renamed over `file`, so a crash never leaves a partial file under
// the final name. Throws std::runtime_error naming the path on I/O failure (no temp file is left)
// or when the file would be larger than kMaxPrtCacheBytes.
void write_prt_cache(const std::filesystem::path& file, const std::string& key, const PrtTransfer& transfer);

// $XDG_CACHE_HOME/arpipe/prt, else $HOME/.cache/arpipe/prt, else an empty path (no cache).
std::filesystem::path default_prt_cache_dir();

struct PrtLoad {
  PrtTransfer transfer;
  bool baked = false;           // false: loaded from the cache
  std::filesystem::path file;   // the cache file (empty without a cache directory)
  std::string note;             // why it was baked, or why the result could not be cached
};

// The cached transfer when the cache holds one for this mesh and these settings, else a fresh bake
// (progress as in bake_prt), written to the cache. A cache that cannot be written is a note, not an
// error; an empty cache_dir means no cache. Throws what bake_prt throws.
PrtLoad load_or_bake_prt(const Mesh& mesh, const PrtBakeSettings& settings, const std::filesystem::path& cache_dir,
                         const std::function<void(size_t, size_t)>& progress = {});

}  // namespace arpipe
