// Benchmark: the calibration solve's run time and accuracy against the number of views, on
// synthetic views of the calib-board scene's board through its wide OPENCV8 lens (analytic truth,
// Gaussian corner noise), for LENSMODEL_OPENCV8 and the auto-configured splined model; plus the time
// of the projection uncertainty the report computes (centre and four corners).
// `arpipe bench calib-solve [--sigma PX] [--seeds N]` prints markdown tables for docs/BENCHMARKS.md.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "calib/calibration_solver.h"
#include "calib/projection_uncertainty.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "tests/calib/solver_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::calib;

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

struct Row {
  std::vector<double> solve_ms, uncertainty_ms;
  double fx_pct = 0, fy_pct = 0, cx_px = 0, cy_px = 0;  // worst over the seeds
  double diff_px = 0;          // max over the image (splined: where observed), uncompensated
  double diff_rotated_px = 0;  // the same after mrcal's implied rotation (projection_diff at infinity)
  double corner_stdev_px = 0;  // predicted worst-direction stdev at the image corners, at infinity
  double rms_px = 0;           // per coordinate (mrcal's figure)
  int solved = 0;
  std::string failure;
};

Row measure(const std::string& lensmodel, int views, double sigma, int seeds) {
  const CameraModel truth = test::opencv8_truth();
  const bool splined = lensmodel.find("SPLINED") != std::string::npos;
  Row row;
  for (int seed = 1; seed <= seeds; ++seed) {
    const auto data = test::make_views(truth, test::chessboard_9x13(), views, sigma, unsigned(1000 * views + seed));
    SolveOptions options;
    options.lensmodel = lensmodel;
    try {
      const auto start = std::chrono::steady_clock::now();
      const CalibrationResult result = solve_calibration(data.board, data.views, test::kWidth, test::kHeight, options);
      row.solve_ms.push_back(milliseconds_since(start));
      const double w = test::kWidth - 1, h = test::kHeight - 1;
      const auto u_start = std::chrono::steady_clock::now();
      const auto u = projection_uncertainty(result, {{w / 2, h / 2}, {0, 0}, {w, 0}, {0, h}, {w, h}}, 0.0);
      row.uncertainty_ms.push_back(milliseconds_since(u_start));
      for (size_t i = 1; i < u.size(); ++i) row.corner_stdev_px = std::max(row.corner_stdev_px, u[i].worst_direction_stdev_px);
      if (!splined) {
        row.fx_pct = std::max(row.fx_pct, 100 * std::abs(result.model.fx() / truth.fx() - 1));
        row.fy_pct = std::max(row.fy_pct, 100 * std::abs(result.model.fy() / truth.fy() - 1));
        row.cx_px = std::max(row.cx_px, std::abs(result.model.cx() - truth.cx()));
        row.cy_px = std::max(row.cy_px, std::abs(result.model.cy() - truth.cy()));
      }
      const auto where = [&](const Vec2& q) { return !splined || test::covered(data, q); };
      row.diff_px = std::max(row.diff_px, test::max_projection_difference(truth, result.model, 5, where));
      const Mat3 R = test::implied_rotation(truth, result.model, 10, where);
      row.diff_rotated_px =
          std::max(row.diff_rotated_px, test::max_projection_difference_rotated(truth, result.model, R, 5, where));
      row.rms_px = std::max(row.rms_px, result.rms_per_coordinate_px);
      ++row.solved;
    } catch (const std::exception& e) {
      row.failure = e.what();
    }
  }
  return row;
}

int run_calib_solve_benchmark(double sigma, int seeds) {
  log::set_max_level(log::Level::Warning);
  fmt::print(
      "Synthetic views: 640x480 OPENCV8 lens of configs/sim/calib-board.toml, 9x13-corner 20 mm board, tilted "
      "15-45 deg, 0.28-0.55 m, centres swept over the image; Gaussian corner noise sigma = {} px per coordinate; "
      "{} seeds per row (times: median; errors: worst seed).\n"
      "Projection difference: max over a 5 px grid (OPENCV8: the whole image; splined: where a board was seen), "
      "uncompensated / after mrcal's implied rotation (projection_diff at infinity).\n\n",
      sigma, seeds);
  for (const std::string lensmodel : {"LENSMODEL_OPENCV8", "LENSMODEL_SPLINED_STEREOGRAPHIC"}) {
    fmt::print("{}\n\n", lensmodel);
    fmt::print(
        "| views | solve s | uncertainty ms | fx err % | fy err % | cx err px | cy err px | projection diff px "
        "(raw / rotated) | corner stdev px | RMS px/coord |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int views : {5, 10, 20, 30, 50, 100}) {
      const Row r = measure(lensmodel, views, sigma, seeds);
      if (r.solved == 0) {
        fmt::print("| {} | failed: {} |||||||||\n", views, r.failure);
        continue;
      }
      const bool splined = lensmodel.find("SPLINED") != std::string::npos;
      const std::string core =
          splined ? std::string("- | - | - | -")
                  : fmt::format("{:.3f} | {:.3f} | {:.2f} | {:.2f}", r.fx_pct, r.fy_pct, r.cx_px, r.cy_px);
      fmt::print("| {} | {:.2f} | {:.0f} | {} | {:.3f} / {:.3f} | {:.3f} | {:.3f} |{}\n", views,
                 median(r.solve_ms) / 1000, median(r.uncertainty_ms), core, r.diff_px, r.diff_rotated_px,
                 r.corner_stdev_px, r.rms_px,
                 r.solved < seeds ? fmt::format(" {} of {} failed: {}", seeds - r.solved, seeds, r.failure) : "");
    }
    fmt::print("\n");
  }
  return 0;
}

}  // namespace

void add_calib_solve_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "calib-solve", "the calibration solve's time and accuracy against the number of views, on synthetic views");
  struct Options {
    double sigma = 0.1;
    int seeds = 3;
  };
  auto options = std::make_shared<Options>();
  command->add_option("--sigma", options->sigma, "Gaussian corner noise per coordinate")
      ->type_name("PX")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--seeds", options->seeds, "noise seeds per row")->check(CLI::PositiveNumber);
  cli::on_run(command, [options] { return run_calib_solve_benchmark(options->sigma, options->seeds); }, cli::Failure{});
}

}  // namespace arpipe
