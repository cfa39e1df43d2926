// The benchmarks, each a subcommand of `arpipe bench` (docs/BENCHMARKS.md): each add_*_benchmark
// declares its name, options and run on `bench`. Timings depend on the machine: compare the rows of
// one run with each other, not with another machine's.
#pragma once

#include <CLI/CLI.hpp>

namespace arpipe {

// All of the below.
void add_benchmarks(CLI::App& bench);

void add_pipeline_benchmark(CLI::App& bench);       // pipeline: per-stage time, frames/s, memory (pipeline_throughput.cpp)
void add_scaling_benchmark(CLI::App& bench);        // scaling: cost against objects and frame size (pipeline_scaling.cpp)
void add_latency_benchmark(CLI::App& bench);        // latency: live outputs' cost and end-to-end latency (live_outputs.cpp)
void add_pose_benchmark(CLI::App& bench);           // pose: tracking time against pose error (pose_accuracy.cpp)
void add_sim_render_benchmark(CLI::App& bench);     // sim-render: simulator time against its noise (sim_render_speed.cpp)
void add_blur_benchmark(CLI::App& bench);           // blur: motion-blur methods, time against error (blur_methods.cpp)
void add_shadows_benchmark(CLI::App& bench);        // shadows: shadow methods against ray tracing (shadow_methods.cpp)
void add_probe_benchmark(CLI::App& bench);          // probe: light-probe analyses, time against error (probe_analysis.cpp)
void add_sun_benchmark(CLI::App& bench);            // sun: sun-position algorithms per call (sun_position.cpp)
void add_capture_path_benchmark(CLI::App& bench);   // capture-path: V4L2 capture cost and latency (capture_path.cpp)
void add_calib_corners_benchmark(CLI::App& bench);  // calib-corners: corner accuracy (calib_corners.cpp)
void add_calib_solve_benchmark(CLI::App& bench);    // calib-solve: calibration solve against views (calib_solve.cpp)
void add_sh_benchmark(CLI::App& bench);             // sh: spherical-harmonic error against bands (sh_accuracy.cpp)
void add_prt_benchmark(CLI::App& bench);            // prt: PRT bake time against error, run-time cost (prt_bake_accuracy.cpp)
void add_physics_benchmark(CLI::App& bench);        // physics: time per frame against bounce error, per substep rate (physics_cost.cpp)
void add_proxies_benchmark(CLI::App& bench);        // proxies: render time against occlusion edge error, full and simplified (proxies_cost.cpp)
void add_panorama_benchmark(CLI::App& bench);
void add_hybrid_benchmark(CLI::App& bench);         // hybrid: seed 003's protocol, the hybrid against the full 3D scene (hybrid_speedup.cpp)       // panorama: the 360° background's lookup, time against error (panorama_lookup.cpp)

}  // namespace arpipe
