// Frame k's time on a timeline of a given rate, in whole nanoseconds, computed exactly in 128-bit
// integers so that frame times never drift however long a capture or a looped video runs.
#pragma once

#include <cstdint>

namespace arpipe {

// frames / rate seconds (rate = rate_num / rate_den frames a second, both > 0; frames >= 0) in
// nanoseconds, rounded half up.
int64_t frames_to_ns(int64_t frames, int64_t rate_num, int64_t rate_den);

// round(k * 1e9 / fps) ns: exact for integral rates and NTSC's n * 1000 / 1001 (through
// frames_to_ns), in double otherwise. fps > 0.
int64_t frame_offset_ns(double fps, uint64_t k);

}  // namespace arpipe
