// Benchmark: the calibration solve's run time and accuracy against the number of views, on
// synthetic views of the calib-board scene's board through its wide OPENCV8 lens (analytic truth,
// Gaussian corner noise), for LENSMODEL_OPENCV8 and the auto-configured splined model; plus the time
// of the projection uncertainty the report computes (centre and four corners).
// `arpipe bench calib-solve [--sigma PX] [--seeds N] [--no-regularization] [--no-outlier-rejection]`
// prints markdown tables for docs/BENCHMARKS.md; the two switches take mrcal's regularisation and
// outlier rejection out of the full-model stage, to see what each costs at a given noise.
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
  int outliers = 0;            // most corners marked outliers in one solve
  std::string solved_as;       // the lens model's full name (a splined model's chosen configuration)
  int solved = 0;
  std::string failure;
};

struct BenchOptions {
  double sigma = 0.1;
  int seeds = 3;
  bool no_regularization = false;
  bool no_outlier_rejection = false;
  std::vector<std::string> lensmodels{"LENSMODEL_OPENCV8", "LENSMODEL_SPLINED_STEREOGRAPHIC"};
};

Row measure(const std::string& lensmodel, int views, const BenchOptions& bench) {
  const double sigma = bench.sigma;
  const int seeds = bench.seeds;
  const CameraModel truth = test::opencv8_truth();
  const bool splined = lensmodel.find("SPLINED") != std::string::npos;
  Row row;
  for (int seed = 1; seed <= seeds; ++seed) {
    const auto data = test::make_views(truth, test::chessboard_9x13(), views, sigma, unsigned(1000 * views + seed));
    SolveOptions options;
    options.lensmodel = lensmodel;
    options.regularize = !bench.no_regularization;
    options.reject_outliers = !bench.no_outlier_rejection;
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
      row.outliers = std::max(row.outliers, result.outlier_count);
      row.solved_as = result.model.lensmodel();
      ++row.solved;
    } catch (const std::exception& e) {
      row.failure = e.what();
    }
  }
  return row;
}

int run_calib_solve_benchmark(const BenchOptions& bench) {
  log::set_max_level(log::Level::Warning);
  fmt::print(
      "Synthetic views: 640x480 OPENCV8 lens of configs/sim/calib-board.toml, 9x13-corner 20 mm board, tilted "
      "15-45 deg, 0.28-0.55 m, centres swept over the image; Gaussian corner noise sigma = {} px per coordinate; "
      "{} seeds per row (times: median; errors: worst seed); full-model stage with mrcal's regularisation {}, "
      "outlier rejection {}.\n"
      "Projection difference: max over a 5 px grid (OPENCV8: the whole image; splined: where a board was seen), "
      "uncompensated / after mrcal's implied rotation (projection_diff at infinity).\n\n",
      bench.sigma, bench.seeds, bench.no_regularization ? "off" : "on",
      bench.no_outlier_rejection ? "off" : "on");
  for (const std::string& lensmodel : bench.lensmodels) {
    fmt::print("{}\n\n", lensmodel);
    fmt::print(
        "| views | solve s | uncertainty ms | fx err % | fy err % | cx err px | cy err px | projection diff px "
        "(raw / rotated) | corner stdev px | RMS px/coord | outliers |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    std::string solved_as;
    for (int views : {5, 10, 20, 30, 50, 100}) {
      const Row r = measure(lensmodel, views, bench);
      if (!r.solved_as.empty()) solved_as = r.solved_as;
      if (r.solved == 0) {
        fmt::print("| {} | failed: {} ||||||||||\n", views, r.failure);
        continue;
      }
      const bool splined = lensmodel.find("SPLINED") != std::string::npos;
      const std::string core =
          splined ? std::string("- | - | - | -")
                  : fmt::format("{:.3f} | {:.3f} | {:.2f} | {:.2f}", r.fx_pct, r.fy_pct, r.cx_px, r.cy_px);
      fmt::print("| {} | {:.2f} | {:.0f} | {} | {:.4f} / {:.4f} | {:.4f} | {:.4f} | {} |{}\n", views,
                 median(r.solve_ms) / 1000, median(r.uncertainty_ms), core, r.diff_px, r.diff_rotated_px,
                 r.corner_stdev_px, r.rms_px, r.outliers,
                 r.solved < bench.seeds ? fmt::format(" {} of {} failed: {}", bench.seeds - r.solved, bench.seeds, r.failure) : "");
    }
    if (!solved_as.empty() && solved_as != lensmodel) fmt::print("\nsolved as {}\n", solved_as);
    fmt::print("\n");
  }
  return 0;
}

}  // namespace

void add_calib_solve_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "calib-solve", "the calibration solve's time and accuracy against the number of views, on synthetic views");
  auto options = std::make_shared<BenchOptions>();
  command->add_option("--sigma", options->sigma, "Gaussian corner noise per coordinate")
      ->type_name("PX")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--seeds", options->seeds, "noise seeds per row")->check(CLI::PositiveNumber);
  command->add_option("--lensmodel", options->lensmodels, "lens models to solve for (default: OPENCV8 and the auto-configured splined)")
      ->type_name("NAME");
  command->add_flag("--no-regularization", options->no_regularization, "solve the full model without mrcal's regularisation");
  command->add_flag("--no-outlier-rejection", options->no_outlier_rejection, "solve the full model keeping every corner");
  cli::on_run(command, [options] { return run_calib_solve_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
