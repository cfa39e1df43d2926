// Internal to the calibration: the arrays mrcal_optimize takes for a monocular board calibration
// (one camera at the reference, one board pose per view), and one call that runs a solve stage.
#pragma once

extern "C" {
#include <mrcal/mrcal.h>
}

#include <vector>

#include "calib/calibration_solver.h"

namespace arpipe::calib {

struct MrcalProblem {
  mrcal_lensmodel_t lensmodel{};
  std::vector<double> intrinsics;              // fx, fy, cx, cy, distortions (mrcal order)
  std::vector<mrcal_pose_t> frames_toref;      // per view: board -> camera (rt), the reference is the camera
  mrcal_calobject_warp_t calobject_warp{};     // board bulge; used only by stages that optimise it
  std::vector<mrcal_observation_board_t> observations_board;  // view i sees frame i with camera {0, -1}
  // [view][row][col] = (x, y, weight): mrcal's pool. weight < 0: not seen, or an outlier (mrcal writes
  // new outliers back here).
  std::vector<mrcal_point3_t> pool;
  int imagersize[2] = {0, 0};
  double spacing_m = 0;
  int width_n = 0;   // board points along a row (cols)
  int height_n = 0;  // rows

  int views() const { return int(frames_toref.size()); }
  mrcal_point3_t& at(int view, int row, int col) { return pool[size_t((view * height_n + row) * width_n + col)]; }
  const mrcal_point3_t& at(int view, int row, int col) const {
    return pool[size_t((view * height_n + row) * width_n + col)];
  }
  int state_count(mrcal_problem_selections_t selections) const;
  int measurement_count(mrcal_problem_selections_t selections) const;
  int board_measurement_count() const;  // the leading 2 * views * width_n * height_n entries of x
};

// Runs mrcal_optimize on the problem in place (seed in, solution out; outliers marked in the pool
// by negating their weight). With do_apply_outlier_rejection, mrcal's outlier loop runs here (see
// the .cpp for why). x, when given, receives mrcal's measurement vector at the solution (boards
// first, then the regularisation terms). Returns mrcal's stats of the last pass:
// rms_reproj_error__pixels < 0 means mrcal failed (Noutliers counts unseen points too: unused).
mrcal_stats_t run_stage(MrcalProblem& problem, mrcal_problem_selections_t selections, bool verbose,
                        std::vector<double>* x = nullptr);

// The solve as it stood after its last stage: what the uncertainty needs to re-evaluate the
// Jacobian at the solution.
struct SolvedProblem {
  MrcalProblem problem;
  mrcal_problem_selections_t selections{};  // of the last stage
  std::vector<double> x;                    // measurements at the solution
};

// A board point in the board frame with mrcal's warp applied (mrcal.c: z = x2*4*xr(1-xr) + y2*4*yr(1-yr)).
mrcal_point3_t warped_board_point(const MrcalProblem& problem, int row, int col);

}  // namespace arpipe::calib
