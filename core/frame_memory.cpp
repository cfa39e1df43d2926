#include "core/frame_memory.h"

#include <malloc.h>

namespace arpipe {

void keep_frame_memory_resident() {
  // Blocks up to 64 MiB (a 4K RGB frame is 25 MiB) come from the heap, and the heap keeps up to
  // 256 MiB of free space instead of trimming it back to the kernel after every frame.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace arpipe
