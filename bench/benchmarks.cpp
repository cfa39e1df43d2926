// add_benchmarks: every benchmark on `arpipe bench`, in the order docs/BENCHMARKS.md shows them.
#include "bench/benchmarks.h"

namespace arpipe {

void add_benchmarks(CLI::App& bench) {
  add_pipeline_benchmark(bench);
  add_scaling_benchmark(bench);
  add_latency_benchmark(bench);
  add_pose_benchmark(bench);
  add_sim_render_benchmark(bench);
  add_blur_benchmark(bench);
  add_shadows_benchmark(bench);
  add_probe_benchmark(bench);
  add_sun_benchmark(bench);
  add_capture_path_benchmark(bench);
  add_calib_corners_benchmark(bench);
  add_calib_solve_benchmark(bench);
  add_sh_benchmark(bench);
  add_prt_benchmark(bench);
  add_physics_benchmark(bench);
  add_proxies_benchmark(bench);
  add_panorama_benchmark(bench);
  add_hybrid_benchmark(bench);
}

}  // namespace arpipe
