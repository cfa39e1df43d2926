// Where the render stage's time goes, pass by pass: with ARPIPE_GL_PASS_TIMES set in the
// environment, each marked pass ends with glFinish and its wall time is added up under its name
// (prefixed with the frame's sample count and whether it has shadows); the means are printed to
// stderr at exit. The finishes serialise the GL work, so the parts add to more than the stage's
// own time. Unset (the default), a mark costs one branch. Used for the per-pass figures in
// docs/BENCHMARKS.md: `ARPIPE_GL_PASS_TIMES=1 build/apps/arpipe bench pipeline --set
// render.reuse_layer=false`.
#pragma once

#include <string>

namespace arpipe::pass_times {

bool enabled();
// The frame's kind, put before each pass's name until the next call.
void set_frame_kind(int samples, bool shadows);
// Starts timing the next pass (after a glFinish, so earlier work is not counted in it).
void start();
// Ends the pass begun at the last start() or mark(): glFinish, then adds the time under name.
void mark(const char* name);

}  // namespace arpipe::pass_times
