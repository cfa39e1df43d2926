// The run-time half of `arpipe bench prt`: the render stage drawing the same meshes with per-pixel
// Lambert + SH irradiance (prt = "off") and with PRT (prt = "shadowed"), side by side in one run.
#pragma once

namespace arpipe {

// Prints a table of milliseconds per frame for both, interleaved frame by frame so that the
// machine's drift hits both alike; `frames` measured frames each after a warm-up.
void print_prt_runtime_cost(int frames);

}  // namespace arpipe
