// Per-process scratch directory for the fuzz targets whose parsers read files.
#include "tests/fuzz/fuzz_temp_dir.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace arpipe::fuzz {
namespace {

std::filesystem::path make_temp_dir() {
  // scripts/fuzz.sh names a directory that it removes afterwards: a crashing process skips its
  // destructors.
  std::error_code ec;
  const char* chosen = std::getenv("ARPIPE_FUZZ_TMPDIR");
  const std::filesystem::path base = chosen != nullptr && *chosen != '\0'      ? chosen
                                     : std::filesystem::is_directory("/dev/shm", ec) ? "/dev/shm"
                                                                                     : "/tmp";
  std::string pattern = (base / "arpipe-fuzz-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    std::perror("arpipe fuzz: mkdtemp");
    std::abort();
  }
  return pattern;
}

struct TempDir {
  std::filesystem::path path = make_temp_dir();
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

}  // namespace

const std::filesystem::path& temp_dir() {
  static const TempDir dir;
  return dir.path;
}

std::filesystem::path write_temp_file(std::string_view name, const uint8_t* data, size_t size) {
  const std::filesystem::path path = temp_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "arpipe fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

}  // namespace arpipe::fuzz
