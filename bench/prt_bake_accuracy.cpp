// arpipe bench prt: the PRT bake's time against its sample count, and the error of the transfer
// vectors and of the shaded radiance against a reference (the closed form for unshadowed, a bake
// with many more samples for shadowed and interreflected), on a concave mesh: an open box.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "bench/prt_runtime_cost.h"
#include "core/sh/sh_basis.h"
#include "render/prt/prt_bake.h"
#include "render/prt/prt_test_meshes.h"

namespace arpipe {
namespace {

// The test lighting, radiance SH in the object frame (z up), 3 bands: Ramamoorthi and Hanrahan's
// Grace Cathedral coefficients (docs/reference/rendering.md section 3), same basis convention.
constexpr std::array<std::array<double, 3>, 9> kLighting{{{0.79, 0.44, 0.54},
                                                          {0.39, 0.35, 0.60},
                                                          {-0.34, -0.18, -0.27},
                                                          {-0.29, -0.06, 0.01},
                                                          {-0.11, -0.05, -0.12},
                                                          {-0.26, -0.22, -0.47},
                                                          {-0.16, -0.09, -0.15},
                                                          {0.56, 0.21, 0.14},
                                                          {0.21, -0.05, -0.30}}};
constexpr int kBands = 3;

struct Errors {
  double transfer_rms = 0, transfer_max = 0;    // relative to the reference transfer's RMS
  double radiance_rms = 0, radiance_max = 0;    // relative to the reference radiance's RMS
};

// White albedo: radiance per channel is sum_i L_i T_i.
std::vector<double> shade(const std::vector<double>& transfer) {
  std::vector<double> out;
  for (size_t v = 0; v < transfer.size() / 9; ++v)
    for (size_t c = 0; c < 3; ++c) {
      double sum = 0;
      for (size_t i = 0; i < 9; ++i) sum += kLighting[i][c] * transfer[9 * v + i];
      out.push_back(sum);
    }
  return out;
}

// RMS and max of got - want over RMS of want.
std::pair<double, double> relative(const std::vector<double>& got, const std::vector<double>& want) {
  double sq = 0, ref = 0, worst = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    sq += (got[i] - want[i]) * (got[i] - want[i]);
    ref += want[i] * want[i];
    worst = std::max(worst, std::abs(got[i] - want[i]));
  }
  const double ref_rms = std::sqrt(ref / double(want.size()));
  return {std::sqrt(sq / double(got.size())) / ref_rms, worst / ref_rms};
}

Errors compare(const PrtTransfer& got, const std::vector<double>& want) {
  const std::vector<double> g(got.coefficients.begin(), got.coefficients.end());
  Errors e;
  std::tie(e.transfer_rms, e.transfer_max) = relative(g, want);
  std::tie(e.radiance_rms, e.radiance_max) = relative(shade(g), shade(want));
  return e;
}

std::vector<double> analytic_unshadowed(const Mesh& mesh) {
  const double a[3] = {1.0, 2.0 / 3.0, 1.0 / 4.0};  // A_l / pi
  std::vector<double> out;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const std::vector<double> y =
        sh_basis(kBands, normalized(Vec3{mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]}));
    for (int l = 0; l < kBands; ++l)
      for (int m = -l; m <= l; ++m) out.push_back(a[l] * y[size_t(sh_index(l, m))]);
  }
  return out;
}

struct PrtOptions {
  std::vector<int> sample_counts{4, 8, 16, 32, 64};
  int reference_samples = 256, subdivisions = 8, threads = 0, runtime_frames = 40;
};

int run_prt_benchmark(const PrtOptions& options) {
  const std::vector<int>& sample_counts = options.sample_counts;
  const int reference_samples = options.reference_samples, subdivisions = options.subdivisions,
            threads = options.threads, runtime_frames = options.runtime_frames;
  try {
    const Mesh box = make_open_box(1.0, 0.5, subdivisions);
    std::printf("open box 1 x 1 x 0.5 m, %d x %d per face: %zu vertices, %zu triangles; %d bands\n", subdivisions,
                subdivisions, box.vertex_count(), box.triangle_count(), kBands);
    std::printf("lighting: Grace Cathedral (Ramamoorthi-Hanrahan), white albedo\n");
    std::printf("errors: RMS and max of |T - T_ref| (and of the radiance sum_i L_i T_i) over the reference's RMS\n\n");
    std::fflush(stdout);
    PrtBakeSettings settings;
    settings.bands = kBands;
    settings.threads = threads;
    std::vector<double> references[3];
    references[0] = analytic_unshadowed(box);
    for (TransferKind kind : {TransferKind::Shadowed, TransferKind::Interreflected}) {
      settings.kind = kind;
      settings.samples_per_axis = reference_samples;
      settings.seed = 7;  // not the rows' seed: the reference's jitter is independent of theirs
      PrtBakeStats stats;
      const PrtTransfer ref = bake_prt(box, settings, {}, &stats);
      references[int(kind)].assign(ref.coefficients.begin(), ref.coefficients.end());
      std::printf("reference %s, %d x %d samples: %.2f s, %.2f Mrays/s on %d threads\n",
                  std::string(transfer_kind_name(kind)).c_str(), reference_samples, reference_samples, stats.seconds,
                  stats.seconds > 0 ? double(stats.rays) / stats.seconds * 1e-6 : 0.0, stats.threads);
      std::fflush(stdout);
    }
    std::printf("\n| kind | samples | bake ms | Mrays/s | transfer RMS err | transfer max err | radiance RMS err | "
                "radiance max err |\n|---|---|---|---|---|---|---|---|\n");
    for (TransferKind kind : {TransferKind::Unshadowed, TransferKind::Shadowed, TransferKind::Interreflected})
      for (int n : sample_counts) {
        settings.kind = kind;
        settings.samples_per_axis = n;
        settings.seed = 1;
        // The fastest of three runs: the time least disturbed by the rest of the machine.
        PrtBakeStats stats;
        PrtTransfer t;
        for (int run = 0; run < 3; ++run) {
          PrtBakeStats this_run;
          t = bake_prt(box, settings, {}, &this_run);
          if (run == 0 || this_run.seconds < stats.seconds) stats = this_run;
        }
        const Errors e = compare(t, references[int(kind)]);
        const std::string rays =
            stats.rays == 0 ? "-" : fmt::format("{:.2f}", double(stats.rays) / stats.seconds * 1e-6);
        std::printf("| %s | %d x %d | %.1f | %s | %.2e | %.2e | %.2e | %.2e |\n",
                    std::string(transfer_kind_name(kind)).c_str(), n, n, stats.seconds * 1e3, rays.c_str(),
                    e.transfer_rms, e.transfer_max, e.radiance_rms, e.radiance_max);
        std::fflush(stdout);
      }
    if (runtime_frames > 0) print_prt_runtime_cost(runtime_frames);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bench prt: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

void add_prt_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "prt", "PRT bake: time against samples against the error vs a ray-traced reference; run-time cost vs Lambert");
  command->footer(
      "Bakes an open box (1 m floor, 0.5 m walls, open at the top) with every transfer kind at each sample count\n"
      "and prints the bake time, rays per second, and the RMS and max error of the transfer vectors and of the\n"
      "radiance they shade under a fixed lighting (Grace Cathedral's 9 coefficients), relative to the\n"
      "reference's RMS. Times are the fastest of 3 runs and include building Embree's BVH.");
  auto options = std::make_shared<PrtOptions>();
  command->add_option("--samples", options->sample_counts, "samples per axis, a comma-separated list")
      ->type_name("N,N,...")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(CLI::Range(1, 4096));
  command->add_option("--reference", options->reference_samples,
                      "samples per axis of the shadowed and interreflected reference (the unshadowed reference is "
                      "the closed form A_l / pi y_i(n))")
      ->check(CLI::Range(1, 4096));
  command->add_option("--subdivisions", options->subdivisions, "grid per face of the box (8: 405 vertices)")
      ->check(CLI::Range(1, 256));
  command->add_option("--threads", options->threads, "bake threads (0: every core)")->check(CLI::Range(0, 1024));
  command->add_option("--frames", options->runtime_frames,
                      "then the run-time cost: the render stage with PRT against per-pixel Lambert + SH irradiance on "
                      "the same meshes, N frames each (0: skip)")
      ->check(CLI::Range(0, 10000));
  cli::on_run(command, [options] { return run_prt_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
