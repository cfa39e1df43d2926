// The calibration solve: a seed computed here (mrcal 2.2 seeds only in Python), then mrcal's staged
// optimisation in the order mrcal-calibrate-cameras runs it (solve_initial() and the final solve).
#include "calib/calibration_solver.h"
#include "core/geometry/math_constants.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>

#include "calib/mrcal_problem.h"

namespace arpipe::calib {

namespace {

constexpr int kMinViews = 4;            // mrcal's solve and our seed need at least this many
constexpr int kMinPointsPerView = 4;    // PnP on a plane (IPPE) needs 4
constexpr double kFrontoParallelDeg = 10.0;
const char* const kSplinedBare = "LENSMODEL_SPLINED_STEREOGRAPHIC";

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// ---- Lens model --------------------------------------------------------------------------------

struct TargetModel {
  mrcal_lensmodel_t lensmodel{};
  bool auto_splined = false;  // configuration chosen after the presolve
};

TargetModel parse_target(const std::string& name, int width, int height) {
  TargetModel target;
  if (name == kSplinedBare || name == std::string(kSplinedBare) + "_") {
    target.auto_splined = true;
    target.lensmodel.type = MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC;
    return target;
  }
  if (!mrcal_lensmodel_from_name(&target.lensmodel, name.c_str()) ||
      !mrcal_lensmodel_type_is_valid(target.lensmodel.type)) {
    // CameraModel's constructor words the error (unknown name, or a malformed configuration).
    CameraModel(name, {}, width, height);
    throw CameraModelError(fmt::format("unknown lens model '{}'", name));  // not reached
  }
  switch (target.lensmodel.type) {
    case MRCAL_LENSMODEL_PINHOLE:
    case MRCAL_LENSMODEL_OPENCV4:
    case MRCAL_LENSMODEL_OPENCV5:
    case MRCAL_LENSMODEL_OPENCV8:
    case MRCAL_LENSMODEL_OPENCV12:
    case MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC:
      return target;
    default:
      throw CameraModelError(fmt::format(
          "lens model '{}' cannot be calibrated by arpipe; use LENSMODEL_PINHOLE, LENSMODEL_OPENCV4, "
          "LENSMODEL_OPENCV5, LENSMODEL_OPENCV8, LENSMODEL_OPENCV12 or LENSMODEL_SPLINED_STEREOGRAPHIC[_order=..._Nx="
          "..._Ny=..._fov_x_deg=...]",
          name));
  }
}

std::string lensmodel_name(const mrcal_lensmodel_t& lensmodel) {
  char name[256];
  if (!mrcal_lensmodel_name(name, sizeof name, &lensmodel)) return "?";
  return name;
}

// ---- Seed --------------------------------------------------------------------------------------

// One view's seen points: board coordinates and pixels.
struct InitialGuessView {
  size_t input_index = 0;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> pixels;
};

struct ViewPose {
  bool ok = false;
  cv::Vec3d r, t;
  double rms_px = kNaN;  // reprojection through the seed's stereographic model
};

// Pose of one view for a stereographic seed (f, f, cx, cy): its pixels are unprojected through the
// seed, re-projected to a pinhole of the same core, and given to IPPE (the board is planar). This is
// mrcal's own seeding (calibration.py estimate_monocular_calobject_poses_Rt_tocam), with IPPE for
// the iterative PnP. A board solved behind the camera is flipped (t -> -t) and re-solved.
ViewPose initial_guess_pose(const InitialGuessView& view, const double core[4]) {
  ViewPose pose;
  std::vector<mrcal_point2_t> q(view.pixels.size());
  for (size_t i = 0; i < q.size(); ++i) q[i] = mrcal_point2_t{{view.pixels[i].x, view.pixels[i].y}};
  std::vector<mrcal_point3_t> v(q.size());
  mrcal_unproject_stereographic(v.data(), nullptr, q.data(), int(q.size()), core);
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> pinhole;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!(v[i].z > 1e-6)) continue;  // 90 degrees or more off axis: no pinhole image
    object.push_back(view.object[i]);
    pinhole.emplace_back(core[0] * v[i].x / v[i].z + core[2], core[1] * v[i].y / v[i].z + core[3]);
  }
  if (int(object.size()) < kMinPointsPerView) return pose;
  const cv::Matx33d K(core[0], 0, core[2], 0, core[1], core[3], 0, 0, 1);
  cv::Vec3d r, t;
  try {
    if (!cv::solvePnP(object, pinhole, K, cv::noArray(), r, t, false, cv::SOLVEPNP_IPPE)) return pose;
    if (t[2] <= 0) {
      t = -t;
      if (!cv::solvePnP(object, pinhole, K, cv::noArray(), r, t, true, cv::SOLVEPNP_ITERATIVE) || t[2] <= 0)
        return pose;
    }
  } catch (const cv::Exception&) {
    return pose;  // degenerate points (collinear): no pose from this view
  }
  // Reprojection through the stereographic seed, in the image's own pixels.
  cv::Matx33d R;
  cv::Rodrigues(r, R);
  std::vector<mrcal_point3_t> p(view.object.size());
  for (size_t i = 0; i < p.size(); ++i) {
    const cv::Vec3d pc = R * cv::Vec3d(view.object[i].x, view.object[i].y, view.object[i].z) + t;
    p[i] = mrcal_point3_t{{pc[0], pc[1], pc[2]}};
  }
  std::vector<mrcal_point2_t> projected(p.size());
  mrcal_project_stereographic(projected.data(), nullptr, p.data(), int(p.size()), core);
  double sum = 0;
  for (size_t i = 0; i < p.size(); ++i)
    sum += std::pow(projected[i].x - view.pixels[i].x, 2) + std::pow(projected[i].y - view.pixels[i].y, 2);
  pose.ok = std::isfinite(sum);
  pose.r = r;
  pose.t = t;
  pose.rms_px = std::sqrt(sum / double(p.size()));
  return pose;
}

// How well a focal length explains every view: the median of the per-view PnP reprojection RMS.
// A tilted board's perspective pins the focal length (a fronto-parallel one does not: distance and
// focal length trade off); the median keeps one odd view from steering the choice.
double focal_cost(const std::vector<InitialGuessView>& views, double f, double cx, double cy) {
  const double core[4] = {f, f, cx, cy};
  std::vector<double> rms;
  rms.reserve(views.size());
  for (const InitialGuessView& view : views) {
    const ViewPose pose = initial_guess_pose(view, core);
    rms.push_back(pose.ok ? pose.rms_px : std::numeric_limits<double>::infinity());
  }
  std::nth_element(rms.begin(), rms.begin() + long(rms.size() / 2), rms.end());
  return rms[rms.size() / 2];
}

// The stereographic focal length that best explains the views. Candidates cover horizontal fields of
// view from 10 to 180 degrees (f = W / (4 tan(fov/4)), mrcal's stereographic focal estimate), then a
// golden-section search in log f between the best candidate's neighbours refines it.
double guess_focal(const std::vector<InitialGuessView>& views, int width, double cx, double cy) {
  constexpr int kCandidates = 40;
  const double f_min = width / (4.0 * std::tan(180.0 * kPi / 180.0 / 4.0));
  const double f_max = width / (4.0 * std::tan(10.0 * kPi / 180.0 / 4.0));
  std::vector<double> log_f(kCandidates), cost(kCandidates);
  for (int i = 0; i < kCandidates; ++i) {
    log_f[size_t(i)] = std::log(f_min) + (std::log(f_max) - std::log(f_min)) * i / (kCandidates - 1);
    cost[size_t(i)] = focal_cost(views, std::exp(log_f[size_t(i)]), cx, cy);
  }
  const size_t best = size_t(std::min_element(cost.begin(), cost.end()) - cost.begin());
  double a = log_f[best > 0 ? best - 1 : 0];
  double b = log_f[std::min(best + 1, size_t(kCandidates - 1))];
  const double golden = (std::sqrt(5.0) - 1) / 2;
  double c = b - golden * (b - a), d = a + golden * (b - a);
  double fc = focal_cost(views, std::exp(c), cx, cy), fd = focal_cost(views, std::exp(d), cx, cy);
  for (int i = 0; i < 20; ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - golden * (b - a);
      fc = focal_cost(views, std::exp(c), cx, cy);
    } else {
      a = c, c = d, fc = fd;
      d = a + golden * (b - a);
      fd = focal_cost(views, std::exp(d), cx, cy);
    }
  }
  const double refined = std::exp((a + b) / 2);
  return focal_cost(views, refined, cx, cy) <= cost[best] ? refined : std::exp(log_f[best]);
}

// Angle between the board's normal and the line of sight to the board's centre, degrees: 0 when the
// board squarely faces the camera.
double tilt_deg(const cv::Vec3d& r, const cv::Vec3d& t, const CalibrationBoard& board) {
  cv::Matx33d R;
  cv::Rodrigues(r, R);
  const cv::Vec3d normal = R * cv::Vec3d(0, 0, 1);
  const cv::Vec3d centre =
      R * cv::Vec3d((board.cols - 1) * board.spacing_m / 2, (board.rows - 1) * board.spacing_m / 2, 0) + t;
  const double c = std::abs(normal.dot(centre)) / cv::norm(centre);
  return std::acos(std::min(1.0, c)) * 180.0 / kPi;
}

// ---- Stages ------------------------------------------------------------------------------------

// New distortion parameters start tiny and random, as mrcal-calibrate-cameras' expand_intrinsics():
// exactly zero can sit on a symmetric saddle; tiny keeps the seed a pinhole/stereographic lens. The
// rational terms of OPENCV8+ (k5..k7, the denominator) start 1000x smaller still, so the denominator
// starts at ~1 and the 0/0 ~ 1 degeneracy of the rational model is never approached.
std::vector<double> expand_intrinsics(const std::vector<double>& core, const mrcal_lensmodel_t& lensmodel,
                                      std::mt19937& random) {
  const int n = mrcal_lensmodel_num_params(&lensmodel);
  std::vector<double> intrinsics(core.begin(), core.begin() + 4);
  std::uniform_real_distribution<double> tiny(-1e-6, 1e-6);
  for (int i = 4; i < n; ++i) intrinsics.push_back(tiny(random));
  if (lensmodel.type == MRCAL_LENSMODEL_OPENCV8 || lensmodel.type == MRCAL_LENSMODEL_OPENCV12)
    for (int i = 4 + 5; i < 4 + 8; ++i) intrinsics[size_t(i)] *= 1e-3;
  return intrinsics;
}

// The splined model's configuration when the caller gave none: cubic (mrcal's recommendation),
// knots in the imager's aspect (16 across, 12 down for 4:3), spanning the horizontal field of view
// that the presolved stereographic core sees, with a margin so the image's edges sit inside the
// knot grid rather than on its border.
mrcal_lensmodel_t auto_splined(const double core[4], int width, int height) {
  const mrcal_point2_t edges[2] = {{{-0.5, core[3]}}, {{width - 0.5, core[3]}}};
  mrcal_point3_t v[2];
  mrcal_unproject_stereographic(v, nullptr, edges, 2, core);
  const double angle = std::atan2(std::hypot(v[0].x, v[0].y), v[0].z) + std::atan2(std::hypot(v[1].x, v[1].y), v[1].z);
  const double fov_deg = angle * 180.0 / kPi;
  mrcal_lensmodel_t lensmodel{};
  lensmodel.type = MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC;
  auto& config = lensmodel.LENSMODEL_SPLINED_STEREOGRAPHIC__config;
  config.order = 3;
  config.Nx = 16;
  config.Ny = uint16_t(std::max(4L, std::lround(16.0 * height / width)));
  config.fov_x_deg = uint16_t(std::clamp(std::ceil(fov_deg * 1.1 + 5.0), 10.0, 180.0));
  return lensmodel;
}

mrcal_problem_selections_t selections_none() {
  mrcal_problem_selections_t s{};
  s.do_optimize_intrinsics_core = false;
  s.do_optimize_intrinsics_distortions = false;
  s.do_optimize_extrinsics = false;
  s.do_optimize_frames = false;
  s.do_optimize_calobject_warp = false;
  s.do_apply_regularization = false;
  s.do_apply_outlier_rejection = false;
  return s;
}

std::string view_list(const std::vector<std::string>& names) {
  std::string list;
  for (size_t i = 0; i < names.size() && i < 5; ++i) list += (i ? ", " : "") + names[i];
  if (names.size() > 5) list += fmt::format(" and {} more", names.size() - 5);
  return list;
}

}  // namespace

CalibrationResult solve_calibration(const CalibrationBoard& board, const std::vector<BoardObservation>& observations,
                                    int width, int height, const SolveOptions& options,
                                    const SolveProgress& progress) {
  const auto solve_start = std::chrono::steady_clock::now();
  if (width <= 0 || height <= 0)
    throw CalibrationError(fmt::format("calibration: image size must be positive, got {}x{}", width, height));
  const TargetModel target = parse_target(options.lensmodel, width, height);
  if (board.rows < 2 || board.cols < 2 || !(board.spacing_m > 0))
    throw CalibrationError(fmt::format("calibration: board '{}' needs at least 2 x 2 points and a positive spacing, "
                                       "got {} x {} points {} m apart",
                                       board.name, board.rows, board.cols, board.spacing_m));

  // ---- Usable views
  std::vector<InitialGuessView> views;
  std::vector<std::string> sparse_views;
  for (size_t v = 0; v < observations.size(); ++v) {
    const BoardObservation& obs = observations[v];
    if (int(obs.pixels.size()) != board.point_count() || obs.weights.size() != obs.pixels.size())
      throw CalibrationError(fmt::format(
          "{}: {} observed points for board '{}' of {} x {} = {} points; the board file does not match this view",
          obs.image, obs.pixels.size(), board.name, board.rows, board.cols, board.point_count()));
    if ((obs.width != 0 && obs.width != width) || (obs.height != 0 && obs.height != height))
      throw CalibrationError(fmt::format("{}: image is {}x{}, the calibration is for {}x{}; calibrate each camera "
                                         "resolution separately",
                                         obs.image, obs.width, obs.height, width, height));
    InitialGuessView view;
    view.input_index = v;
    std::vector<char> rows_seen(size_t(board.rows), 0), cols_seen(size_t(board.cols), 0);
    for (int r = 0; r < board.rows; ++r)
      for (int c = 0; c < board.cols; ++c) {
        const size_t i = size_t(r * board.cols + c);
        if (!(obs.weights[i] > 0) || !std::isfinite(obs.pixels[i][0]) || !std::isfinite(obs.pixels[i][1])) continue;
        const Vec3 p = board.point(r, c);
        view.object.emplace_back(p[0], p[1], p[2]);
        view.pixels.emplace_back(obs.pixels[i][0], obs.pixels[i][1]);
        rows_seen[size_t(r)] = cols_seen[size_t(c)] = 1;
      }
    // Points on one line of the grid give no pose (and no plane): such a view cannot be seeded.
    const bool spans_plane = std::count(rows_seen.begin(), rows_seen.end(), 1) >= 2 &&
                             std::count(cols_seen.begin(), cols_seen.end(), 1) >= 2;
    if (int(view.object.size()) >= kMinPointsPerView && spans_plane)
      views.push_back(std::move(view));
    else if (!view.object.empty())
      sparse_views.push_back(obs.image);
  }
  if (int(views.size()) < kMinViews)
    throw CalibrationError(fmt::format(
        "calibration needs the board in at least {} views, with {} or more points each (not all on one line); got "
        "{} usable of {} "
        "views{}. Take more pictures of the board: about 20-30, covering the whole image, near and far, with the "
        "board tilted 30-45 degrees in most of them",
        kMinViews, kMinPointsPerView, views.size(), observations.size(),
        sparse_views.empty() ? "" : fmt::format(" ({} with too few points: {})", sparse_views.size(), view_list(sparse_views))));

  // ---- Seed: a stereographic core (mrcal's seed model for every lens) and one PnP pose per view.
  const double cx = (width - 1) / 2.0, cy = (height - 1) / 2.0;
  const double focal = options.focal_guess_px > 0 ? options.focal_guess_px : guess_focal(views, width, cx, cy);
  const double core[4] = {focal, focal, cx, cy};
  std::vector<InitialGuessView> seeded;
  std::vector<ViewPose> poses;
  std::vector<std::string> failed;
  for (InitialGuessView& view : views) {
    const ViewPose pose = initial_guess_pose(view, core);
    if (!pose.ok) {
      failed.push_back(observations[view.input_index].image);
      continue;
    }
    seeded.push_back(std::move(view));
    poses.push_back(pose);
  }
  if (int(seeded.size()) < kMinViews)
    throw CalibrationError(fmt::format(
        "calibration: the seed (focal length {:.1f} px{}) gave a board pose in only {} of {} views (failed: {}); "
        "check that the board file matches the printed board, or pass a focal-length guess",
        focal, options.focal_guess_px > 0 ? ", given" : ", guessed", seeded.size(), views.size(), view_list(failed)));

  // ---- mrcal's problem
  MrcalProblem problem;
  problem.lensmodel.type = MRCAL_LENSMODEL_STEREOGRAPHIC;
  problem.intrinsics.assign(core, core + 4);
  problem.imagersize[0] = width;
  problem.imagersize[1] = height;
  problem.spacing_m = board.spacing_m;
  problem.width_n = board.cols;
  problem.height_n = board.rows;
  problem.pool.resize(seeded.size() * size_t(board.point_count()));
  std::vector<char> seen_mask(problem.pool.size(), 0);  // the input's seen points (mrcal marks outliers in z)
  for (size_t v = 0; v < seeded.size(); ++v) {
    const BoardObservation& obs = observations[seeded[v].input_index];
    problem.frames_toref.push_back(mrcal_pose_t{{{poses[v].r[0], poses[v].r[1], poses[v].r[2]}},
                                                {{poses[v].t[0], poses[v].t[1], poses[v].t[2]}}});
    problem.observations_board.push_back(mrcal_observation_board_t{{0, -1}, int(v)});
    for (int i = 0; i < board.point_count(); ++i) {
      const bool seen = obs.weights[size_t(i)] > 0 && std::isfinite(obs.pixels[size_t(i)][0]) &&
                        std::isfinite(obs.pixels[size_t(i)][1]);
      const size_t k = v * size_t(board.point_count()) + size_t(i);
      seen_mask[k] = seen;
      problem.pool[k] = seen ? mrcal_point3_t{{obs.pixels[size_t(i)][0], obs.pixels[size_t(i)][1], obs.weights[size_t(i)]}}
                             : mrcal_point3_t{{-1.0, -1.0, -1.0}};
    }
  }

  std::vector<SolveStage> stages;
  const int stage_count = options.optimize_board_warp ? 4 : 3;
  std::vector<double> x;
  mrcal_problem_selections_t selections = selections_none();
  auto run = [&](const std::string& name, mrcal_problem_selections_t s) {
    if (progress) progress(int(stages.size()), stage_count, name);
    const auto start = std::chrono::steady_clock::now();
    const mrcal_stats_t stats = run_stage(problem, s, options.verbose, &x);
    if (!(stats.rms_reproj_error__pixels >= 0))
      throw CalibrationError(fmt::format(
          "calibration: mrcal's solver failed in the '{}' stage ({} views, lens model {}); check that the board file "
          "(rows, columns, spacing) matches the printed board and that every view shows the whole grid the right way "
          "round",
          name, seeded.size(), lensmodel_name(problem.lensmodel)));
    int outliers = 0;
    for (size_t i = 0; i < problem.pool.size(); ++i)
      if (problem.pool[i].z < 0 && seen_mask[i]) ++outliers;
    stages.push_back(SolveStage{name, stats.rms_reproj_error__pixels, outliers, seconds_since(start)});
    selections = s;
  };

  // Stage 1, board poses only, intrinsics locked: each PnP seed was solved on its own with a rough
  // lens; settling the poses against one shared lens first keeps the core from chasing the seed's
  // per-view errors when it is freed.
  mrcal_problem_selections_t s = selections_none();
  s.do_optimize_frames = true;
  run("board poses", s);

  // Stage 2, + the core (fx, fy, cx, cy) of the stereographic lens: the focal length and centre move
  // from the guess to what all views agree on, while the model is still too simple to go astray.
  s.do_optimize_intrinsics_core = true;
  run("core intrinsics", s);

  // Stage 3, the target model: the core carried over, new distortions seeded tiny; everything solved
  // with regularisation (keeps the distortions from drifting where the data says little) and outlier
  // rejection (corners more than ~4-5 sigma off). Splined models keep the presolved core locked: the
  // spline can express the core's effect, so freeing both leaves directions the data cannot fix.
  std::mt19937 random(0x6d7263);  // fixed: the same views give the same solve
  mrcal_lensmodel_t lensmodel = target.lensmodel;
  if (target.auto_splined) lensmodel = auto_splined(problem.intrinsics.data(), width, height);
  const bool splined = lensmodel.type == MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC;
  problem.intrinsics = expand_intrinsics(problem.intrinsics, lensmodel, random);
  problem.lensmodel = lensmodel;
  const bool has_distortions = mrcal_lensmodel_num_params(&lensmodel) > 4;
  s.do_optimize_intrinsics_core = !splined;
  s.do_optimize_intrinsics_distortions = has_distortions;
  s.do_optimize_extrinsics = true;  // no extrinsics here (one camera); set as mrcal-calibrate-cameras does
  s.do_apply_regularization = options.regularize;
  s.do_apply_outlier_rejection = options.reject_outliers;
  run("full model", s);

  // Focal length is observable only through perspective: a board squarely facing the camera looks the
  // same from twice as far with twice the focal length. The tilts come from the solved poses, not the
  // seed's: a wide lens's distortion, seen through the seed's plain stereographic lens, makes an
  // off-centre board that faces the camera look tilted by 5-18 degrees (measured on a 70-degree
  // OPENCV8 lens), while the full model separates the two.
  double max_tilt = 0;
  for (const mrcal_pose_t& frame : problem.frames_toref)
    max_tilt = std::max(max_tilt, tilt_deg(cv::Vec3d(frame.r.xyz), cv::Vec3d(frame.t.xyz), board));
  if (max_tilt < kFrontoParallelDeg)
    throw CalibrationError(fmt::format(
        "calibration: every view shows the board nearly face-on (the most tilted is {:.1f} degrees), so the focal "
        "length cannot be told from the distance; tilt the board 30-45 degrees in some views (left, right, up, "
        "down) and take them again",
        max_tilt));

  // Stage 4, + the board's warp (a flat board is never quite flat): solved last, from a flat seed,
  // when the lens is already right, so the bulge is not confused with radial distortion on the way.
  if (options.optimize_board_warp) {
    problem.calobject_warp = mrcal_calobject_warp_t{{0.0, 0.0}};
    s.do_optimize_calobject_warp = true;
    run("board warp", s);
  }

  // ---- The result
  const std::string name = lensmodel_name(problem.lensmodel);
  // CameraModel has no default; every other field is filled below.
  CalibrationResult result{CameraModel(name, problem.intrinsics, width, height), board, {}, {}, 0, 0, {}, 0, 0, 0, 0,
                           {}, 0, nullptr};
  result.board_warp_x_m = options.optimize_board_warp ? problem.calobject_warp.x2 : 0.0;
  result.board_warp_y_m = options.optimize_board_warp ? problem.calobject_warp.y2 : 0.0;
  result.rms_per_coordinate_px = stages.back().rms_per_coordinate_px;
  result.stages = stages;
  double sum_squared = 0;
  for (size_t v = 0; v < seeded.size(); ++v) {
    BoardObservation obs = observations[seeded[v].input_index];
    const mrcal_pose_t& frame = problem.frames_toref[v];
    result.T_cam_board.push_back(
        SE3::from_rt({frame.r.x, frame.r.y, frame.r.z}, {frame.t.x, frame.t.y, frame.t.z}));
    std::vector<Vec2> residuals(size_t(board.point_count()), Vec2{kNaN, kNaN});
    for (int r = 0; r < board.rows; ++r)
      for (int c = 0; c < board.cols; ++c) {
        const size_t i = size_t(r * board.cols + c);
        const mrcal_point3_t& seen = problem.at(int(v), r, c);
        if (!seen_mask[v * size_t(board.point_count()) + i]) continue;
        if (seen.z > 0) {
          // x = (projected - observed) * weight (mrcal.c); the board measurements lead x in pool order.
          const size_t k = 2 * (v * size_t(board.point_count()) + i);
          residuals[i] = {x[k] / seen.z, x[k + 1] / seen.z};
          sum_squared += residuals[i][0] * residuals[i][0] + residuals[i][1] * residuals[i][1];
          ++result.inlier_count;
        } else {
          // An outlier contributes nothing to x; its residual comes from projecting the solved board point.
          const double rt[6] = {frame.r.x, frame.r.y, frame.r.z, frame.t.x, frame.t.y, frame.t.z};
          mrcal_point3_t p_cam;
          const mrcal_point3_t p_board = warped_board_point(problem, r, c);
          mrcal_transform_point_rt(p_cam.xyz, nullptr, nullptr, rt, p_board.xyz);
          mrcal_point2_t q;
          if (mrcal_project(&q, nullptr, nullptr, &p_cam, 1, &problem.lensmodel, problem.intrinsics.data()))
            residuals[i] = {q.x - seen.x, q.y - seen.y};
          obs.weights[i] = -std::abs(obs.weights[i]);
          ++result.outlier_count;
        }
      }
    result.residuals_px.push_back(std::move(residuals));
    result.observations.push_back(std::move(obs));
  }
  result.rms_per_point_px = result.inlier_count > 0 ? std::sqrt(sum_squared / result.inlier_count) : 0.0;
  auto solved = std::make_shared<SolvedProblem>();
  solved->problem = std::move(problem);
  solved->selections = selections;
  solved->x = std::move(x);
  result.problem = std::move(solved);
  result.seconds = seconds_since(solve_start);
  return result;
}

}  // namespace arpipe::calib
