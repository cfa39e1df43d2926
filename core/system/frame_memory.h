// Keeps frame-sized heap blocks resident: glibc otherwise returns a freed frame's pages to the
// kernel (trim, or one mmap per block) and the next frame faults them back in, page by page.
#pragma once

namespace arpipe {

// Call once at program start (arpiped, arpipe, benchmarks). bench/capture_path measured 418 page
// faults and 2 ms per 640x480 RGB24 frame without it, none with it.
void keep_frame_memory_resident();

// This process's resident set size (VmRSS) in KiB, -1 when /proc does not say: for soak
// benchmarks and the tests that memory stays flat.
long resident_memory_kib();

}  // namespace arpipe
