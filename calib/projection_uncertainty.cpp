// mrcal 2.2's projection uncertainty (model_analysis.py projection_uncertainty() and its helpers
// _projection_uncertainty(), _projection_uncertainty_rotationonly(), _propagate_calibration_uncertainty())
// in C++, for the monocular problem the solver sets up (camera at the reference, one frame per view).
#include "calib/projection_uncertainty.h"
#include "core/geometry/math_constants.h"

extern "C" {
#include <mrcal/mrcal.h>
#include <mrcal/mrcal-internal.h>  // _mrcal_num_j_nonzero (exported for mrcal's Python layer); needs mrcal.h first
}
#include <suitesparse/cholmod.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "calib/mrcal_problem.h"

namespace arpipe::calib {

namespace {


using RowMatrix2X = Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor>;

// The solver's Jacobian at the solution, in mrcal's packed (unitless) state: Jt is nrow = Nstate by
// ncol = Nmeasurements, compressed columns (one column per measurement).
struct PackedJacobian {
  std::vector<int> p, i;
  std::vector<double> x;
  std::vector<double> measurements;
  int states = 0;
};

PackedJacobian jacobian_at_solution(const SolvedProblem& solved) {
  const MrcalProblem& problem = solved.problem;
  const mrcal_problem_selections_t selections = solved.selections;
  PackedJacobian J;
  J.states = problem.state_count(selections);
  const int measurements = problem.measurement_count(selections);
  const int nonzero = _mrcal_num_j_nonzero(problem.views(), 0, problem.width_n, problem.height_n, 1, 0,
                                           problem.views(), 0, 0, problem.observations_board.data(), nullptr,
                                           selections, &problem.lensmodel);
  J.p.assign(size_t(measurements) + 1, 0);
  J.i.assign(size_t(nonzero), 0);
  J.x.assign(size_t(nonzero), 0.0);
  J.measurements.assign(size_t(measurements), 0.0);
  std::vector<double> b_packed(size_t(J.states));
  cholmod_sparse Jt{};
  Jt.nrow = size_t(J.states);
  Jt.ncol = size_t(measurements);
  Jt.nzmax = size_t(nonzero);
  Jt.p = J.p.data();
  Jt.i = J.i.data();
  Jt.x = J.x.data();
  Jt.stype = 0;
  Jt.itype = CHOLMOD_INT;
  Jt.xtype = CHOLMOD_REAL;
  Jt.dtype = CHOLMOD_DOUBLE;
  Jt.sorted = 1;
  Jt.packed = 1;
  const mrcal_problem_constants_t constants{-1.0, -1.0};
  if (!mrcal_optimizer_callback(b_packed.data(), int(b_packed.size() * sizeof(double)), J.measurements.data(),
                                int(J.measurements.size() * sizeof(double)), &Jt, problem.intrinsics.data(), nullptr,
                                problem.frames_toref.data(), nullptr, &problem.calobject_warp, 1, 0, problem.views(), 0,
                                0, problem.observations_board.data(), nullptr, problem.views(), 0, problem.pool.data(),
                                &problem.lensmodel, problem.imagersize, selections, &constants, problem.spacing_m,
                                problem.width_n, problem.height_n, false))
    throw CalibrationError("projection uncertainty: mrcal_optimizer_callback failed at the solution");
  return J;
}

// mrcal's default observed-pixel noise: the standard deviation of the inlier board residuals
// (weighted, x and y pooled, mean removed), as np.std(mrcal.residuals_chessboard(...)).
double residual_stdev(const MrcalProblem& problem, const std::vector<double>& x) {
  double sum = 0, sum_squared = 0;
  size_t n = 0;
  for (size_t k = 0; k < problem.pool.size(); ++k) {
    if (!(problem.pool[k].z > 0)) continue;
    for (size_t c = 0; c < 2; ++c) {
      sum += x[2 * k + c];
      sum_squared += x[2 * k + c] * x[2 * k + c];
      ++n;
    }
  }
  if (n == 0) return kNaN;
  const double mean = sum / double(n);
  return std::sqrt(std::max(0.0, sum_squared / double(n) - mean * mean));
}

// dq/db for the query point: the intrinsics directly, and every frame's pose through the mean of
// the point as seen from each frame (uncertainty.org: the fixed point is defined in the frames'
// coordinates). Full units; the caller scales to the packed state.
RowMatrix2X projection_gradient(const SolvedProblem& solved, const mrcal_point3_t& p_cam, bool at_infinity,
                                mrcal_point2_t& q) {
  const MrcalProblem& problem = solved.problem;
  const mrcal_problem_selections_t selections = solved.selections;
  const int states = problem.state_count(selections);
  const int frames = problem.views();
  const int intrinsics_count = int(problem.intrinsics.size());
  RowMatrix2X dq_db = RowMatrix2X::Zero(2, states);

  mrcal_point3_t dq_dp[2];
  std::vector<double> dq_dintrinsics(size_t(2 * intrinsics_count));
  if (!mrcal_project(&q, dq_dp, dq_dintrinsics.data(), &p_cam, 1, &problem.lensmodel, problem.intrinsics.data())) {
    q = mrcal_point2_t{{kNaN, kNaN}};
    return dq_db;
  }

  const int istate_intrinsics = mrcal_state_index_intrinsics(0, 1, 0, frames, 0, 0, frames, selections,
                                                             &problem.lensmodel);
  if (istate_intrinsics >= 0 &&
      (selections.do_optimize_intrinsics_core || selections.do_optimize_intrinsics_distortions)) {
    const int core = mrcal_lensmodel_metadata(&problem.lensmodel).has_core ? 4 : 0;
    const int first = selections.do_optimize_intrinsics_core ? 0 : core;
    const int last = selections.do_optimize_intrinsics_distortions ? intrinsics_count : core;
    for (int r = 0; r < 2; ++r)
      for (int k = first; k < last; ++k)
        dq_db(r, istate_intrinsics + k - first) = dq_dintrinsics[size_t(r * intrinsics_count + k)];
  }

  const int istate_frames = mrcal_state_index_frames(0, 1, 0, frames, 0, 0, frames, selections, &problem.lensmodel);
  if (istate_frames >= 0 && selections.do_optimize_frames) {
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> dq_dpcam;
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 3; ++c) dq_dpcam(r, c) = dq_dp[r].xyz[c];
    for (int f = 0; f < frames; ++f) {
      const mrcal_pose_t& frame = problem.frames_toref[size_t(f)];
      const double rt[6] = {frame.r.x, frame.r.y, frame.r.z, frame.t.x, frame.t.y, frame.t.z};
      double p_frame[3], p_ref[3];
      if (!at_infinity) {
        // p_ref = mean over frames of T_ref_frame(p_frame); d/d(rt) of one term, / Nframes.
        Eigen::Matrix<double, 3, 6, Eigen::RowMajor> dpref_drt;
        mrcal_transform_point_rt_inverted(p_frame, nullptr, nullptr, rt, p_cam.xyz);
        mrcal_transform_point_rt(p_ref, dpref_drt.data(), nullptr, rt, p_frame);
        dq_db.block<2, 6>(0, istate_frames + 6 * f) = dq_dpcam * dpref_drt / double(frames);
      } else {
        // At infinity only the rotations move the direction (mrcal's atinfinity).
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> dpref_dr;
        mrcal_rotate_point_r_inverted(p_frame, nullptr, nullptr, rt, p_cam.xyz);
        mrcal_rotate_point_r(p_ref, dpref_dr.data(), nullptr, rt, p_frame);
        dq_db.block<2, 3>(0, istate_frames + 6 * f) = dq_dpcam * dpref_dr / double(frames);
      }
    }
  }
  return dq_db;
}

}  // namespace

std::vector<PixelUncertainty> projection_uncertainty(const CalibrationResult& result, const std::vector<Vec2>& pixels,
                                                     double distance_m, double observed_pixel_stdev) {
  if (!result.problem)
    throw CalibrationError("projection uncertainty: the calibration result carries no solved problem");
  const SolvedProblem& solved = *result.problem;
  const MrcalProblem& problem = solved.problem;
  const mrcal_problem_selections_t selections = solved.selections;
  if (!selections.do_optimize_frames)
    throw CalibrationError("projection uncertainty: needs a solve that optimised the board poses");

  const PackedJacobian J = jacobian_at_solution(solved);
  const int measurements = int(J.measurements.size());
  const int board_measurements = problem.board_measurement_count();
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, int>> Jt(
      J.states, measurements, J.p.back(), J.p.data(), J.i.data(), J.x.data());

  // Var(b*) = s^2 inv(J*'J*) J*obs' J*obs inv(J*'J*) in the packed state b* (uncertainty.org); with no
  // regularisation every measurement is an observation and this is s^2 inv(J*'J*).
  const Eigen::MatrixXd JtJ = Eigen::MatrixXd(Jt * Jt.transpose());
  const Eigen::LLT<Eigen::MatrixXd> factor(JtJ);
  if (factor.info() != Eigen::Success)
    throw CalibrationError(
        "projection uncertainty: the solve's normal equations are singular (some lens parameters are not pinned by "
        "the data); add views that cover the image");
  const bool regularized = board_measurements < measurements;
  Eigen::MatrixXd JobsTJobs;
  if (regularized) {
    const auto Jobs_t = Jt.leftCols(board_measurements);
    JobsTJobs = Eigen::MatrixXd(Jobs_t * Jobs_t.transpose());
  }

  const double s = observed_pixel_stdev > 0 ? observed_pixel_stdev : residual_stdev(problem, J.measurements);

  std::vector<PixelUncertainty> out;
  out.reserve(pixels.size());
  for (const Vec2& pixel : pixels) {
    PixelUncertainty u;
    u.pixel = {kNaN, kNaN};
    u.distance_m = distance_m > 0 ? distance_m : 0.0;
    u.worst_direction_stdev_px = u.rms_stdev_px = kNaN;
    const auto ray = result.model.unproject(pixel);
    if (!ray) {
      out.push_back(u);
      continue;
    }
    const Vec3 direction = normalized(*ray);
    const Vec3 p = distance_m > 0 ? distance_m * direction : direction;
    mrcal_point2_t q;
    RowMatrix2X dq_db = projection_gradient(solved, mrcal_point3_t{{p[0], p[1], p[2]}}, !(distance_m > 0), q);
    // To the packed state: b = D b*, so dq/db* = dq/db D, which is what unpacking a row does
    // (mrcal.unpack_state(dq_dbief) in the Python).
    for (int r = 0; r < 2; ++r)
      mrcal_unpack_solver_state_vector(dq_db.row(r).data(), 1, 0, problem.views(), 0, 0, selections,
                                       &problem.lensmodel);
    const Eigen::MatrixXd A = factor.solve(dq_db.transpose());  // inv(J*'J*) (dq/db*)'
    Eigen::Matrix2d covariance = regularized ? Eigen::Matrix2d(A.transpose() * JobsTJobs * A)
                                             : Eigen::Matrix2d(dq_db * A);
    covariance *= s * s;
    u.pixel = {q.x, q.y};
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) u.covariance[r][c] = covariance(r, c);
    // mrcal.worst_direction_stdev(): sqrt of the larger eigenvalue of the 2x2 covariance.
    const double a = covariance(0, 0), b = covariance(1, 0), c = covariance(1, 1);
    u.worst_direction_stdev_px = std::sqrt((a + c) / 2 + std::sqrt((a - c) * (a - c) / 4 + b * b));
    u.rms_stdev_px = std::sqrt((a + c) / 2);
    out.push_back(u);
  }
  return out;
}

}  // namespace arpipe::calib
