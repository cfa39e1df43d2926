#include "core/system/frame_memory.h"

#include <malloc.h>

#include <fstream>
#include <string>

namespace arpipe {

void keep_frame_memory_resident() {
  // Blocks up to 64 MiB (a 4K RGB frame is 25 MiB) come from the heap, and the heap keeps up to
  // 256 MiB of free space instead of trimming it back to the kernel after every frame.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

long resident_memory_kib() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

}  // namespace arpipe
