// mrcal_optimize for a monocular board calibration: one intrinsics set, no extrinsics (the camera is
// the reference frame), one frame (board pose) per view, no discrete points.
#include "calib/mrcal_problem.h"

#include <algorithm>
#include <cstdio>

namespace arpipe::calib {

namespace {

constexpr int kIntrinsicsSets = 1;
constexpr int kExtrinsics = 0;  // the camera sits at the reference
constexpr int kPoints = 0;
constexpr int kPointsFixed = 0;
constexpr int kPointObservations = 0;

}  // namespace

int MrcalProblem::state_count(mrcal_problem_selections_t selections) const {
  return mrcal_num_states(kIntrinsicsSets, kExtrinsics, views(), kPoints, kPointsFixed, views(), selections,
                          &lensmodel);
}

int MrcalProblem::measurement_count(mrcal_problem_selections_t selections) const {
  return mrcal_num_measurements(views(), kPointObservations, width_n, height_n, kIntrinsicsSets, kExtrinsics,
                                views(), kPoints, kPointsFixed, selections, &lensmodel);
}

int MrcalProblem::board_measurement_count() const {
  return mrcal_num_measurements_boards(views(), width_n, height_n);
}

namespace {

mrcal_stats_t optimize(MrcalProblem& problem, mrcal_problem_selections_t selections, bool verbose,
                       std::vector<double>& x) {
  // mrcal checks the x buffer's size in bytes against the measurement count; it must match exactly.
  x.assign(size_t(problem.measurement_count(selections)), 0.0);
  const mrcal_problem_constants_t constants{-1.0, -1.0};  // point ranges: unused without points
  return mrcal_optimize(nullptr, 0, x.data(), int(x.size() * sizeof(double)), problem.intrinsics.data(), nullptr,
                        problem.frames_toref.data(), nullptr, &problem.calobject_warp, kIntrinsicsSets, kExtrinsics,
                        problem.views(), kPoints, kPointsFixed, problem.observations_board.data(), nullptr,
                        problem.views(), kPointObservations, problem.pool.data(), &problem.lensmodel,
                        problem.imagersize, selections, &constants, problem.spacing_m, problem.width_n,
                        problem.height_n, verbose, false);
}

// The least sigma the outlier rule assumes, px. With corners better than this the residuals are no
// longer noise but mrcal's regularisation bias (its weight is fixed for ~1 px of noise: a constant
// few thousandths of a pixel, systematic where the distortion is largest), and mrcal's rule marks
// those regions, then more after each re-solve: on synthetic views with 0.001 px of corner noise a
// splined solve marked up to 2201 of 11700 corners and ended 3-25 px from the true lens where the
// board was seen, against 0.03-0.05 px with this floor (docs/CALIBRATION.md, "What the
// regularisation costs"; `arpipe bench calib-solve --sigma 0.001`). 0.01 px is the best the
// simulator's corners reach (the calib-board capture: 0.011 px), so no real residual sits under it.
constexpr double kOutlierSigmaFloorPx = 0.01;

// mrcal's outlier rule (mrcal.c markOutliers): sigma^2 = mean of the squared inlier measurements
// (weighted x and y alike), here at least kOutlierSigmaFloorPx^2; when any inlier measurement
// exceeds 5 sigma, every point with a measurement beyond 4 sigma is marked (weight < 0). Returns
// how many were marked.
int mark_outliers(MrcalProblem& problem, const std::vector<double>& x) {
  double sum_squared = 0;
  size_t n = 0;
  for (size_t k = 0; k < problem.pool.size(); ++k)
    if (problem.pool[k].z > 0) {
      sum_squared += x[2 * k] * x[2 * k] + x[2 * k + 1] * x[2 * k + 1];
      n += 2;
    }
  if (n == 0) return 0;
  const double variance = std::max(sum_squared / double(n), kOutlierSigmaFloorPx * kOutlierSigmaFloorPx);
  const auto beyond = [&](size_t k, double sigmas) {
    return x[2 * k] * x[2 * k] > sigmas * sigmas * variance || x[2 * k + 1] * x[2 * k + 1] > sigmas * sigmas * variance;
  };
  bool any = false;
  for (size_t k = 0; k < problem.pool.size() && !any; ++k) any = problem.pool[k].z > 0 && beyond(k, 5.0);
  if (!any) return 0;
  int marked = 0;
  for (size_t k = 0; k < problem.pool.size(); ++k)
    if (problem.pool[k].z > 0 && beyond(k, 4.0)) {
      problem.pool[k].z = -problem.pool[k].z;
      ++marked;
    }
  return marked;
}

}  // namespace

mrcal_stats_t run_stage(MrcalProblem& problem, mrcal_problem_selections_t selections, bool verbose,
                        std::vector<double>* x_out) {
  std::vector<double> local;
  std::vector<double>& x = x_out != nullptr ? *x_out : local;
  if (!selections.do_apply_outlier_rejection) return optimize(problem, selections, verbose, x);
  // The outlier loop runs here rather than inside mrcal_optimize: mrcal 2.2 leaks its solver context
  // (~2.4 MB, found by LeakSanitizer) on every pass of its own loop after the first. Same rule, same
  // passes: solve, mark, solve again from where it stopped until nothing new is marked.
  selections.do_apply_outlier_rejection = false;
  mrcal_stats_t stats{};
  for (int pass = 0; pass < 100; ++pass) {
    stats = optimize(problem, selections, verbose, x);
    if (!(stats.rms_reproj_error__pixels >= 0)) return stats;
    const int marked = mark_outliers(problem, x);
    if (marked == 0) break;
    if (verbose) std::fprintf(stderr, "arpipe: marked %d more outliers; solving again\n", marked);
  }
  return stats;
}

mrcal_point3_t warped_board_point(const MrcalProblem& problem, int row, int col) {
  mrcal_point3_t p{};
  p.x = col * problem.spacing_m;
  p.y = row * problem.spacing_m;
  const double xr = problem.width_n > 1 ? double(col) / (problem.width_n - 1) : 0.0;
  const double yr = problem.height_n > 1 ? double(row) / (problem.height_n - 1) : 0.0;
  p.z = problem.calobject_warp.x2 * 4.0 * xr * (1.0 - xr) + problem.calobject_warp.y2 * 4.0 * yr * (1.0 - yr);
  return p;
}

}  // namespace arpipe::calib
