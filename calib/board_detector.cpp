// Board detection: chessboards by mrgingham (square boards) or OpenCV, refined by cornerSubPix and
// put into one canonical point order; AprilTag grids by tag id, each tag's centre from its corners.
#include "calib/board_detector.h"

#include "calib/chessboard_corner_fit.h"
#include "calib/grid_consistency.h"

#include <fmt/format.h>
#include <mrgingham/mrgingham.hh>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/camera_model.h"
#include "core/track/tag_corner_refiner.h"
#include "core/track/tag_detector.h"

namespace arpipe::calib {

namespace {

// Chessboards: mrgingham on square boards, findChessboardCornersSB on the others and where
// mrgingham finds nothing; cornerSubPix then refines the corners on the image as it came, and the
// X-junction model fit after it (0.011 px per coordinate against cornerSubPix's 0.055 px on the
// 36-sample capture: docs/BENCHMARKS.md). Measured
// on the simulator's calib-board capture (60 frames, noise on; the table is in
// tests/calib/board_chessboard_test.cpp): SB's own corners are off by up to 0.5-1.5 px where a
// corner is strongly sheared (RMS 0.08-0.18 px), while cornerSubPix on them gives RMS 0.093 px,
// max 0.39 px, unbiased. So SB only has to find the board: with no flag or EXHAUSTIVE it finds all
// 60; NORMALIZE_IMAGE and ACCURACY each lose the most oblique view (squares 7 px across in an image
// corner), and ACCURACY is 3-4x slower. EXHAUSTIVE is OpenCV's "improve detection rate" search, at
// no measured cost where the board is found. (The classic findChessboardCorners on a 2x upsampled
// image finds every board too, but takes 1-4.6 s to give up on a view whose board is cut off.)
constexpr int kSbFlags = cv::CALIB_CB_EXHAUSTIVE;

// mrgingham's own CLI (mrgingham-from-image.cc) stretches the image to 0..255, applies CLAHE with
// clip limit 8 and a 3x3 box blur; the library does none of it. Measured on 10 rendered views of
// mrgingham's own board (chessboard.10x10.pdf: wider outer squares), 16 samples/px: without it
// mrgingham found 8 and its corners had RMS 0.27 px; with it, all 10 at 0.136 px; refined by
// cornerSubPix on the original image, 0.051 px (max 0.15 px), as SB + cornerSubPix there. On a
// board whose outer squares are not wider it misses more (2 of 3 rendered views found), hence
// the fallback to SB.
constexpr double kClaheClipLimit = 8.0;
constexpr int kBlurRadius = 1;

// cornerSubPix's half window, per corner: this share of the distance to its nearest neighbour,
// within [2, 10] px. Measured on the calib-board capture: 0.25, 0.3, 0.4, 0.5 gave RMS 0.107,
// 0.101, 0.094, 0.090 px; a larger window averages more of the edges until it takes in the next
// junction (a fixed 5 px window on 7 px squares: errors of 4 px), so 0.4 keeps a margin. A corner
// that the refinement moves farther than kMaxRefineShare of that distance has slid towards
// another junction and keeps its first place.
constexpr double kRefineWindowShare = 0.4;
constexpr int kMinRefineWindow = 2;
constexpr int kMaxRefineWindow = 10;
constexpr double kMaxRefineShare = 0.3;

// The model fit's window radius: this share of the distance to the nearest neighbour, within
// [kMinFitRadius, kMaxFitRadius] px. Measured on the calib-board capture (bench/calib_corners):
// 0.35, 0.45, 0.5 gave 0.012, 0.011, 0.010 px per coordinate at 190, 290, 340 ms per image; a
// larger window reaches the neighbouring junctions' blur, so 0.45 keeps a margin.
constexpr double kFitRadiusShare = 0.45;
constexpr double kMinFitRadius = 2.5;
constexpr double kMaxFitRadius = 10;

// An observation needs at least this share of the board's points, spread over two rows and two
// columns. Why: the solve seeds each board pose by PnP from the points seen (two rows and columns
// make them non-collinear), and a view with few points fixes its own six pose parameters from
// little more than six numbers, so it adds little about the lens while any wrong tag id it carries
// weighs as much as in a full view. 60% still keeps the partial views at the image's edges and
// corners, where the lens distortion is largest and observations are scarcest.
constexpr double kMinSeenFraction = 0.6;

// A ChArUco view needs at least this many corners, over two rows and two columns (so not all on
// one line of the board). Every corner is named by the markers beside it, so any subset is
// unambiguous, and the 60 % above would throw away exactly the views that reach into the image's
// corners with most of the board outside the image (on the calib-charuco capture: 16 of its 36
// views, the corners' reach from 31-33 px to 35-36 px, the lens's error from 0.025 to 0.037 px).
// Why 12, measured there (tests/calib/charuco_calibration_test.cpp): every view cut to its N
// corners nearest an image corner, solved alone, gives a lens off by 83, 5.6, 2.6, 0.62, 0.64 px
// for N = 4, 6, 8, 12, 20: below 12 corners a view does not pin its own pose (from 12 on the error
// is what corner-only coverage allows); added to the full views, views of any N did no harm
// (0.036-0.049 px against 0.037 without them).
// AprilTag grids keep the 60 % rule, by measurement: the same minimum for tag centres, on the
// calib-charuco poses with the 6 x 8 grid in place of the board, kept 36 views instead of 23 but
// brought the image corners only 0-10 px nearer (a tag counts only with its whole white ring
// inside the image) and made the lens worse, 0.096 px from the truth against 0.028 (25 samples
// per pixel; docs/CALIBRATION.md, "AprilTag grids seen in part").
constexpr int kMinCharucoCorners = 12;

// libapriltag's decision margin below which a detection is not trusted (the tracker's default).
constexpr double kMinDecisionMargin = 20.0;
// Quads found at full resolution: calibration tags are small. Measured on a 5 x 6 grid of 30 mm
// tags 0.75-1 m away (16-20 px across) in 640 x 480 frames: decimation 1 found all 29 tags in each
// of 3 views, 1.5 lost 2 in one, 2 found 5-21, 3 none; decimation 1 costs 20-26 ms per frame.
constexpr double kAprilTagQuadDecimate = 1.0;

// Pixel of a point that was not seen (weight -1): outside every image, never a plausible corner.
constexpr Vec2 kUnseen{-1.0, -1.0};

// Whether a view with points missing still counts: kMinSeenFraction of a chessboard's or an
// AprilTag grid's points, kMinCharucoCorners of a ChArUco board's, over two rows and two columns.
bool enough_seen(const BoardObservation& view, const CalibrationBoard& board) {
  std::set<int> rows, cols;
  for (size_t i = 0; i < view.weights.size(); ++i)
    if (view.weights[i] > 0) {
      rows.insert(int(i) / board.cols);
      cols.insert(int(i) % board.cols);
    }
  const double minimum =
      board.kind == BoardKind::charuco ? kMinCharucoCorners : std::ceil(kMinSeenFraction * board.point_count());
  return view.seen_count() >= minimum && rows.size() >= 2 && cols.size() >= 2;
}

// A rows x cols grid of detected points in row-major order (index r*cols + c).
struct Grid {
  int rows = 0;
  int cols = 0;
  std::vector<Vec2> px;
  std::vector<double> weights;

  const Vec2& at(int r, int c) const { return px[static_cast<size_t>(r * cols + c)]; }

  // Mean image direction from one column to the next (along a row) and from one row to the next.
  Vec2 row_direction() const {
    Vec2 d{0, 0};
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c + 1 < cols; ++c) d = {d[0] + at(r, c + 1)[0] - at(r, c)[0], d[1] + at(r, c + 1)[1] - at(r, c)[1]};
    return d;
  }
  Vec2 column_direction() const {
    Vec2 d{0, 0};
    for (int r = 0; r + 1 < rows; ++r)
      for (int c = 0; c < cols; ++c) d = {d[0] + at(r + 1, c)[0] - at(r, c)[0], d[1] + at(r + 1, c)[1] - at(r, c)[1]};
    return d;
  }

  // new(r, c) = old(map(r, c)); the shape stays rows x cols (square grids for the 90-degree turns).
  template <typename Map>
  Grid remapped(Map map) const {
    Grid out = *this;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const auto [r0, c0] = map(r, c);
        out.px[static_cast<size_t>(r * cols + c)] = px[static_cast<size_t>(r0 * cols + c0)];
        out.weights[static_cast<size_t>(r * cols + c)] = weights[static_cast<size_t>(r0 * cols + c0)];
      }
    return out;
  }
};

// The canonical order of a chessboard's corners, which no detector guarantees on its own:
// 1. The board's frame (x along a row, y down the rows, z = x cross y) has its printed face
//    towards the camera, z pointing away from it, so in the image x-then-y turns clockwise
//    (image y is down). A mirrored order fits a flat grid too, but only as the board seen from
//    behind: the solve's board warp (a bulge along the board's z, shared by all views) would flip
//    sign in that view, and PnP seeds such a view with the camera behind the board.
// 2. Of the orders the grid's symmetry still allows (a 180-degree turn; on a square board also the
//    90-degree turns), the one whose rows run most nearly left to right in the image, so point 0 is
//    at the top left as in mrgingham's output: views of one board held the same way agree.
Grid canonical_order(const Grid& grid) {
  Grid g = grid;
  const Vec2 x = g.row_direction();
  const Vec2 y = g.column_direction();
  if (x[0] * y[1] - x[1] * y[0] < 0) {
    const int cols = g.cols;
    g = g.remapped([cols](int r, int c) { return std::pair{r, cols - 1 - c}; });
  }
  std::vector<Grid> candidates{g, g.remapped([&g](int r, int c) { return std::pair{g.rows - 1 - r, g.cols - 1 - c}; })};
  if (g.rows == g.cols) {
    const int n = g.rows;
    candidates.push_back(g.remapped([n](int r, int c) { return std::pair{c, n - 1 - r}; }));
    candidates.push_back(g.remapped([n](int r, int c) { return std::pair{n - 1 - c, r}; }));
  }
  const auto leftness = [](const Grid& candidate) {
    const Vec2 d = candidate.row_direction();
    const double length = norm(d);
    return length > 0 ? d[0] / length : -1.0;
  };
  return *std::max_element(candidates.begin(), candidates.end(),
                           [&](const Grid& a, const Grid& b) { return leftness(a) < leftness(b); });
}

// Sub-pixel corners: cornerSubPix (gradients orthogonal to the corner-to-pixel vector over a
// window), on the image as it came, then optionally the X-junction model fit from there, with the
// edges' directions from the neighbouring corners. A corner either step moves farther than
// kMaxRefineShare of the distance to its nearest neighbour has slid towards another junction and
// keeps its place from before that step.
// How far refinement may reach around a corner, as shares of the distance to its nearest
// neighbour. A chessboard's nearest other feature is the next junction; a ChArUco board's is the
// nearest marker corner, sqrt(2) x the gap between marker and square from the corner.
struct RefineReach {
  bool corner_subpix = true;               // false: the corners come cornerSubPix-refined already
  double window_share = kRefineWindowShare;
  double fit_radius_share = kFitRadiusShare;
  bool drop_unfitted = false;              // model_fit: a corner the fit cannot place is dropped
};

// Sub-pixel corners: cornerSubPix (gradients orthogonal to the corner-to-pixel vector over a
// window), on the image as it came, then optionally the X-junction model fit from there, with the
// edges' directions from the neighbouring corners. A corner either step moves farther than
// kMaxRefineShare of the distance to its nearest neighbour has slid towards another junction and
// keeps its place from before that step. Points with weight <= 0 (not seen) are left alone and are
// nobody's neighbour; a corner with no seen neighbour takes its `fallback_spacing` (px, one per
// point; none given: such a corner is dropped) as that distance, and the model fit needs a seen neighbour along its row and along its column.
// check_grid: then drops the refined corners that lie off their neighbours' homography
// (grid_consistency.h), for a finder that does not check its grid itself.
BoardObservation::Refinements refine_corners(const cv::Mat& image, CornerRefinement refinement, Grid& grid,
                                             const RefineReach& reach = {},
                                             const std::vector<double>& fallback_spacing = {},
                                             bool check_grid = false) {
  BoardObservation::Refinements counts;
  if (refinement == CornerRefinement::none) {
    for (double w : grid.weights) counts.detector += w > 0;
    return counts;
  }
  const cv::TermCriteria stop(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 0.001);
  const Grid found = grid;
  std::vector<int*> placed(grid.px.size(), nullptr);  // which count each corner went to
  const auto seen = [&found](int r, int c) {
    return r >= 0 && r < found.rows && c >= 0 && c < found.cols && found.weights[size_t(r * found.cols + c)] > 0;
  };
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c) {
      if (!seen(r, c)) continue;
      double spacing = std::numeric_limits<double>::infinity();
      const Vec2& p = found.at(r, c);
      for (const auto& [dr, dc] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        if (!seen(r + dr, c + dc)) continue;
        const Vec2& q = found.at(r + dr, c + dc);
        spacing = std::min(spacing, std::hypot(q[0] - p[0], q[1] - p[1]));
      }
      if (!std::isfinite(spacing) && size_t(r * grid.cols + c) < fallback_spacing.size())
        spacing = fallback_spacing[size_t(r * grid.cols + c)];
      if (!std::isfinite(spacing)) {  // nothing says how large the squares are here
        grid.weights[static_cast<size_t>(r * grid.cols + c)] = -1.0;
        ++counts.dropped;
        continue;
      }
      Vec2 refined = p;
      int* placed_by = &counts.detector;
      if (reach.corner_subpix) {
        const int window =
            std::clamp(static_cast<int>(reach.window_share * spacing), kMinRefineWindow, kMaxRefineWindow);
        std::vector<cv::Point2f> corner{cv::Point2f(static_cast<float>(p[0]), static_cast<float>(p[1]))};
        cv::cornerSubPix(image, corner, cv::Size(window, window), cv::Size(-1, -1), stop);
        refined = {corner[0].x, corner[0].y};
        if (!std::isfinite(refined[0]) || !std::isfinite(refined[1]) ||
            std::hypot(refined[0] - p[0], refined[1] - p[1]) > kMaxRefineShare * spacing) {
          // No junction near the finder's place, or the window slid to another: the finder's place
          // is not a corner to trust. Dropped, mrcal's outlier way (never on the calib-board and
          // calib-board-photo captures, whose corners all get the model fit); its pixel stays until
          // the grid is ordered.
          grid.weights[static_cast<size_t>(r * grid.cols + c)] = -1.0;
          ++counts.dropped;
          continue;
        }
        placed_by = &counts.corner_subpix;
      }
      // The edges through the corner run towards the neighbours in its row and its column.
      const auto direction = [&](int r0, int c0, int r1, int c1) -> std::optional<Vec2> {
        const Vec2& a = seen(r0, c0) ? found.at(r0, c0) : p;
        const Vec2& b = seen(r1, c1) ? found.at(r1, c1) : p;
        if (!seen(r0, c0) && !seen(r1, c1)) return std::nullopt;
        return b - a;
      };
      const auto along_row = direction(r, c - 1, r, c + 1);
      const auto along_column = direction(r - 1, c, r + 1, c);
      if (refinement == CornerRefinement::model_fit && along_row && along_column) {
        CornerFitOptions options;
        options.radius_px = std::clamp(reach.fit_radius_share * spacing, kMinFitRadius, kMaxFitRadius);
        if (const auto fitted = fit_chessboard_corner(image, refined, *along_row, *along_column, options);
            fitted && std::hypot((*fitted)[0] - p[0], (*fitted)[1] - p[1]) <= kMaxRefineShare * spacing) {
          refined = *fitted;
          placed_by = &counts.model_fit;
        }
      }
      if (reach.drop_unfitted && refinement == CornerRefinement::model_fit && placed_by != &counts.model_fit) {
        grid.weights[static_cast<size_t>(r * grid.cols + c)] = -1.0;
        ++counts.dropped;
        continue;
      }
      ++*placed_by;
      placed[static_cast<size_t>(r * grid.cols + c)] = placed_by;
      grid.px[static_cast<size_t>(r * grid.cols + c)] = refined;
    }
  if (check_grid) {
    const std::vector<double> before = grid.weights;
    drop_off_grid_corners(grid.rows, grid.cols, grid.px, grid.weights);
    for (size_t i = 0; i < before.size(); ++i)
      if (before[i] > 0 && grid.weights[i] <= 0 && placed[i] != nullptr) {
        --*placed[i];
        ++counts.dropped;
      }
  }
  return counts;
}

bool finite_inside(const Vec2& p, int width, int height) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && p[0] >= -0.5 && p[1] >= -0.5 && p[0] <= width - 0.5 &&
         p[1] <= height - 0.5;
}

// Whether a tag's white ring (one code cell around its black square) lies inside the image. A tag
// cut by the image's edge can still yield a quad, with a corner on the edge (AprilRobotics/apriltag
// #375), and its centre would then be wrong.
bool white_ring_inside(const std::array<Vec2, 4>& q, int border_cells, int width, int height) {
  double perimeter = 0;
  for (size_t k = 0; k < 4; ++k) perimeter += std::hypot(q[(k + 1) % 4][0] - q[k][0], q[(k + 1) % 4][1] - q[k][1]);
  const double cell = perimeter / 4 / border_cells;
  for (const Vec2& p : q)
    if (!(p[0] >= cell && p[1] >= cell && p[0] <= width - 1 - cell && p[1] <= height - 1 - cell)) return false;
  return true;
}

// Where the diagonals of a quad cross: the image of the tag's centre under any homography, so
// exact for a pinhole view of the flat tag (a lens's distortion bends it by a second-order amount).
std::optional<Vec2> diagonal_intersection(const std::array<Vec2, 4>& q) {
  const Vec2 d0{q[2][0] - q[0][0], q[2][1] - q[0][1]};
  const Vec2 d1{q[3][0] - q[1][0], q[3][1] - q[1][1]};
  const double det = d0[0] * d1[1] - d0[1] * d1[0];
  if (std::abs(det) < 1e-9 * (norm(d0) * norm(d1) + 1e-300)) return std::nullopt;
  const Vec2 w{q[1][0] - q[0][0], q[1][1] - q[0][1]};
  const double s = (w[0] * d1[1] - w[1] * d1[0]) / det;
  // A convex quad's diagonals cross inside both of them.
  const double t = (w[0] * d0[1] - w[1] * d0[0]) / det;
  if (!(s > 0 && s < 1 && t > 0 && t < 1)) return std::nullopt;
  return Vec2{q[0][0] + s * d0[0], q[0][1] + s * d0[1]};
}

// The image of a tag's centre. Where the diagonals of the tag's quad cross is the centre's image
// under any homography, so exact for a pinhole view; through a real lens the tag's image is bent
// and that point is off by the bend's second-order part: measured 0.10 px RMS on a full view and
// 0.39 px near the image's edges for the calib scene's wide lens, with exact corners. Given the lens
// (from a first solve), the diagonals are crossed in undistorted coordinates instead, where they
// are straight: 0.0003 px with exact corners.
std::optional<Vec2> tag_centre(const std::array<Vec2, 4>& corners, const CameraModel* lens) {
  if (lens == nullptr) return diagonal_intersection(corners);
  std::array<Vec2, 4> normalised;
  for (size_t k = 0; k < 4; ++k) {
    const auto n = lens->normalize(corners[k]);
    if (!n) return std::nullopt;
    normalised[k] = *n;
  }
  const auto centre = diagonal_intersection(normalised);
  if (!centre) return std::nullopt;
  return lens->project(Vec3{(*centre)[0], (*centre)[1], 1.0});
}

}  // namespace

// What each finder's flags are for is said at ChessboardFinder (board_detector.h).
constexpr int kSbNormalizedFlags = cv::CALIB_CB_NORMALIZE_IMAGE;
constexpr int kClassicFlags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;

const char* chessboard_finder_name(ChessboardFinder finder) {
  switch (finder) {
    case ChessboardFinder::mrgingham: return "mrgingham";
    case ChessboardFinder::sb_exhaustive: return "findChessboardCornersSB";
    case ChessboardFinder::sb_normalized: return "findChessboardCornersSB (NORMALIZE_IMAGE)";
    case ChessboardFinder::classic: return "findChessboardCorners";
  }
  return "?";
}

std::vector<ChessboardFinder> chessboard_finders(const CalibrationBoard& board) {
  std::vector<ChessboardFinder> out;
  if (board.rows == board.cols) out.push_back(ChessboardFinder::mrgingham);
  out.insert(out.end(), {ChessboardFinder::sb_exhaustive, ChessboardFinder::sb_normalized, ChessboardFinder::classic});
  return out;
}

struct BoardDetector::Impl {
  CalibrationBoard board;
  CornerRefinement refinement = CornerRefinement::model_fit;
  std::vector<ChessboardFinder> finders;
  std::string method;
  // AprilTag grids only.
  std::unique_ptr<TagDetector> tags;
  TagCornerRefiner refiner{PixelFormat::GREY};

  std::optional<BoardObservation> detect_chessboard(const cv::Mat& image) const;
  std::optional<BoardObservation> detect_mrgingham(const cv::Mat& image) const;
  std::optional<BoardObservation> detect_sb(const cv::Mat& image, int flags, ChessboardFinder finder) const;
  std::optional<BoardObservation> detect_classic(const cv::Mat& image) const;
  std::optional<BoardObservation> from_corners(const std::vector<cv::Point2f>& corners, const cv::Mat& image,
                                               ChessboardFinder finder) const;
  std::optional<BoardObservation> detect_apriltags(const cv::Mat& image, const CameraModel* lens) const;
  // ChArUco boards only.
  cv::Ptr<cv::aruco::CharucoBoard> charuco;
  cv::Ptr<cv::aruco::DetectorParameters> aruco_parameters;
  std::optional<BoardObservation> detect_charuco(const cv::Mat& image) const;
  // Refines the corners (check_grid: see refine_corners) and puts them in the canonical order.
  std::optional<BoardObservation> observation(Grid grid, const cv::Mat& image, const std::string& detector,
                                              bool check_grid = false) const;
};

std::optional<BoardObservation> BoardDetector::Impl::observation(Grid grid, const cv::Mat& image,
                                                                 const std::string& detector, bool check_grid) const {
  const BoardObservation::Refinements refined = refine_corners(image, refinement, grid, {}, {}, check_grid);
  grid = canonical_order(grid);
  for (size_t i = 0; i < grid.px.size(); ++i)
    if (grid.weights[i] <= 0) grid.px[i] = kUnseen;
  BoardObservation out;
  out.detector = detector;
  out.refined = refined;
  out.pixels = std::move(grid.px);
  out.weights = std::move(grid.weights);
  return out;
}

std::optional<BoardObservation> BoardDetector::Impl::detect_mrgingham(const cv::Mat& image) const {
  cv::Mat stretched, equalised, prepared;
  cv::normalize(image, stretched, 0, 255, cv::NORM_MINMAX);
  cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE();
  clahe->setClipLimit(kClaheClipLimit);
  clahe->apply(stretched, equalised);
  cv::blur(equalised, prepared, cv::Size(1 + 2 * kBlurRadius, 1 + 2 * kBlurRadius));

  std::vector<mrgingham::PointDouble> points;
  signed char* levels = nullptr;  // realloc()ed by mrgingham; left null when the board was found at level 0
  const int found = mrgingham::find_chessboard_from_image_array(points, &levels, board.rows, prepared);
  const size_t n = static_cast<size_t>(board.point_count());
  std::optional<BoardObservation> out;
  if (found >= 0 && points.size() == n) {
    Grid grid{board.rows, board.cols, {}, {}};
    for (size_t i = 0; i < n; ++i) {
      grid.px.push_back({points[i].x, points[i].y});
      const int level = levels != nullptr ? levels[i] : found;
      grid.weights.push_back(std::ldexp(1.0, -std::max(0, level)));
    }
    out = observation(std::move(grid), image, "mrgingham");
  }
  std::free(levels);
  return out;
}

std::optional<BoardObservation> BoardDetector::Impl::from_corners(const std::vector<cv::Point2f>& corners,
                                                                  const cv::Mat& image, ChessboardFinder finder) const {
  if (corners.size() != static_cast<size_t>(board.point_count())) return std::nullopt;
  Grid grid{board.rows, board.cols, {}, {}};
  for (const cv::Point2f& p : corners) {
    grid.px.push_back({p.x, p.y});
    grid.weights.push_back(1.0);
  }
  // The classic finder can put a corner on the wrong junction (glare), and nothing checks it there.
  return observation(std::move(grid), image, chessboard_finder_name(finder), finder == ChessboardFinder::classic);
}

std::optional<BoardObservation> BoardDetector::Impl::detect_sb(const cv::Mat& image, int flags,
                                                               ChessboardFinder finder) const {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCornersSB(image, cv::Size(board.cols, board.rows), corners, flags)) return std::nullopt;
  return from_corners(corners, image, finder);
}

std::optional<BoardObservation> BoardDetector::Impl::detect_classic(const cv::Mat& image) const {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(image, cv::Size(board.cols, board.rows), corners, kClassicFlags)) return std::nullopt;
  return from_corners(corners, image, ChessboardFinder::classic);
}

std::optional<BoardObservation> BoardDetector::Impl::detect_chessboard(const cv::Mat& image) const {
  for (ChessboardFinder finder : finders) {
    std::optional<BoardObservation> out;
    switch (finder) {
      case ChessboardFinder::mrgingham: out = detect_mrgingham(image); break;
      case ChessboardFinder::sb_exhaustive: out = detect_sb(image, kSbFlags, finder); break;
      case ChessboardFinder::sb_normalized: out = detect_sb(image, kSbNormalizedFlags, finder); break;
      case ChessboardFinder::classic: out = detect_classic(image); break;
    }
    if (out) return out;
  }
  return std::nullopt;
}

std::optional<BoardObservation> BoardDetector::Impl::detect_apriltags(const cv::Mat& image,
                                                                      const CameraModel* lens) const {
  std::vector<TagObservation> found;
  tags->detect(image.data, image.cols, image.rows, image.step, found);

  // Without a lens, a stand-in pinhole camera: the refiner then fits straight edges in the
  // distorted image, as libapriltag does.
  const CameraModel pinhole = CameraModel::pinhole(image.cols, image.cols, (image.cols - 1) / 2.0,
                                                   (image.rows - 1) / 2.0, image.cols, image.rows);
  const CameraModel& camera = lens != nullptr ? *lens : pinhole;
  const int count = board.point_count();
  std::vector<int> hits(static_cast<size_t>(count), 0);
  std::vector<Vec2> centres(static_cast<size_t>(count), kUnseen);
  for (TagObservation& tag : found) {
    const int index = tag.id - board.first_id;
    if (index < 0 || index >= count || tag.decision_margin < kMinDecisionMargin) continue;
    if (!white_ring_inside(tag.corners, tags->border_cells(), image.cols, image.rows)) continue;
    // Refinement moves corners by a fraction of a pixel; when it cannot (a tiny tag), keep
    // libapriltag's corners.
    refiner.refine(image.data, image.cols, image.rows, image.step, camera, tags->border_cells(), tag.corners);
    const auto centre = tag_centre(tag.corners, lens);
    if (!centre || !finite_inside(*centre, image.cols, image.rows)) continue;
    ++hits[static_cast<size_t>(index)];
    centres[static_cast<size_t>(index)] = *centre;
  }

  BoardObservation out;
  out.detector = method;
  out.pixels.resize(static_cast<size_t>(count), kUnseen);
  out.weights.resize(static_cast<size_t>(count), -1.0);
  for (int i = 0; i < count; ++i) {
    // An id seen twice is a false detection somewhere; neither place can be trusted.
    if (hits[static_cast<size_t>(i)] != 1) continue;
    out.pixels[static_cast<size_t>(i)] = centres[static_cast<size_t>(i)];
    out.weights[static_cast<size_t>(i)] = 1.0;
  }
  if (!enough_seen(out, board)) return std::nullopt;
  return out;
}

// ChArUco: the markers by OpenCV's detectMarkers, then refineDetectedMarkers (which looks for the
// board's missing markers where the found ones say they are: on the calib-charuco capture it
// raises the views found from 28 to 35 of 36); interpolateCornersCharuco says which corners lie
// between found markers. Its corner places are not used: measured on that capture against the
// truth, they are off by 0.64 px (median) and up to 7 px where its cornerSubPix window reaches a
// marker's corner. Each corner's first guess is instead the mean of where its two neighbouring
// markers' homographies put it (0.36 px median), a corner whose two guesses disagree by more than
// kMaxGuessSpread of a square is dropped, and the X-junction model fit places it, with a window
// that stays clear of the markers; a corner the fit cannot place is dropped (weight -1): nothing
// else places a ChArUco corner to better than tenths of a pixel. The lens is not used: the fit
// works on the pixels around the corner, whatever the guess.
constexpr double kMaxGuessSpread = 0.5;
constexpr double kMaxSingleMarkerShift = 0.05;

std::optional<BoardObservation> BoardDetector::Impl::detect_charuco(const cv::Mat& image) const {
  std::vector<std::vector<cv::Point2f>> markers, rejected;
  std::vector<int> ids;
  cv::aruco::detectMarkers(image, charuco->dictionary, markers, ids, aruco_parameters, rejected);
  if (ids.empty()) return std::nullopt;
  cv::aruco::refineDetectedMarkers(image, charuco, markers, ids, rejected);
  std::vector<cv::Point2f> interpolated;
  std::vector<int> corner_ids;
  // minMarkers 1: a corner beside one found marker counts (its other marker may be cut by the
  // image's edge: exactly the corners nearest the image's corners); the model fit must still find
  // a junction there.
  cv::aruco::interpolateCornersCharuco(markers, ids, image, charuco, interpolated, corner_ids, cv::noArray(),
                                       cv::noArray(), 1);

  // Each found marker's homography from the board's plane to the image; a marker id found twice
  // is a false detection somewhere, and neither is used.
  std::vector<cv::Mat> homography(charuco->ids.size());
  std::vector<int> found_count(charuco->ids.size(), 0);
  for (size_t j = 0; j < ids.size(); ++j) {
    const auto at = std::find(charuco->ids.begin(), charuco->ids.end(), ids[j]);
    if (at == charuco->ids.end()) continue;
    const size_t m = size_t(at - charuco->ids.begin());
    std::vector<cv::Point2f> plane;
    for (const cv::Point3f& q : charuco->objPoints[m]) plane.emplace_back(q.x, q.y);
    homography[m] = cv::getPerspectiveTransform(plane, markers[j]);
    ++found_count[m];
  }
  const auto guess = [&](int id, size_t m) -> std::optional<Vec2> {
    if (found_count[m] != 1 || homography[m].empty()) return std::nullopt;
    const cv::Point3f& c = charuco->chessboardCorners[size_t(id)];
    std::vector<cv::Point2f> out;
    cv::perspectiveTransform(std::vector<cv::Point2f>{{c.x, c.y}}, out, homography[m]);
    return Vec2{out[0].x, out[0].y};
  };

  const int count = board.point_count();
  Grid grid{board.rows, board.cols, std::vector<Vec2>(size_t(count), kUnseen), std::vector<double>(size_t(count), -1.0)};
  const cv::Point3f step = charuco->chessboardCorners.size() > 1 ? charuco->chessboardCorners[1] - charuco->chessboardCorners[0]
                                                                  : cv::Point3f(1, 0, 0);
  std::vector<double> local_square(size_t(count), std::numeric_limits<double>::infinity());
  std::vector<int> guessed_from(size_t(count), 0);  // how many markers placed the first guess
  for (const int id : corner_ids) {
    if (id < 0 || id >= count || grid.weights[size_t(id)] > 0) continue;
    std::vector<Vec2> guesses;
    for (const int m : charuco->nearestMarkerIdx[size_t(id)])
      if (const auto g = guess(id, size_t(m))) guesses.push_back(*g);
    if (guesses.empty()) continue;
    // A square's size here, the shorter of its two edges from the corner, by a found marker's homography.
    const cv::Point3f c = charuco->chessboardCorners[size_t(id)];
    std::vector<cv::Point2f> ends;
    for (const int m : charuco->nearestMarkerIdx[size_t(id)])
      if (found_count[size_t(m)] == 1 && !homography[size_t(m)].empty()) {
        cv::perspectiveTransform(std::vector<cv::Point2f>{{c.x, c.y}, {c.x + step.x, c.y}, {c.x, c.y + step.x}}, ends,
                                 homography[size_t(m)]);
        break;
      }
    const double square_px = std::min(std::hypot(ends[1].x - ends[0].x, ends[1].y - ends[0].y),
                                      std::hypot(ends[2].x - ends[0].x, ends[2].y - ends[0].y));
    local_square[size_t(id)] = square_px;
    if (guesses.size() == 2) {
      if (std::hypot(guesses[0][0] - guesses[1][0], guesses[0][1] - guesses[1][1]) > kMaxGuessSpread * square_px)
        continue;
      guesses[0] = {(guesses[0][0] + guesses[1][0]) / 2, (guesses[0][1] + guesses[1][1]) / 2};
    }
    grid.px[size_t(id)] = guesses[0];
    guessed_from[size_t(id)] = int(guesses.size());
    grid.weights[size_t(id)] = 1.0;
  }
  RefineReach reach;
  reach.corner_subpix = false;  // its window would reach the markers' corners
  reach.drop_unfitted = true;
  // The nearest marker corner is sqrt(2) x the gap from the square's corner; the model's window
  // keeps a quarter of that clear for the blur.
  const double gap_share = (board.spacing_m - board.marker_m) / 2 / board.spacing_m;
  reach.fit_radius_share = std::min(kFitRadiusShare, 0.75 * std::sqrt(2.0) * gap_share);
  BoardObservation out;
  const std::vector<Vec2> guessed = grid.px;
  out.refined = refine_corners(image, refinement, grid, reach, local_square);
  // A corner guessed from one marker (its other one not found, most often cut by the image's edge)
  // has no second opinion: the fit must land within kMaxSingleMarkerShift of a square of the guess.
  // On the calib-charuco capture this drops 118 of 3024 corners, among them the only 3 that the fit
  // placed more than 0.31 px from the truth (1.9-3.1 px, each beside a marker cut by the image's
  // edge); the rest then lie within 0.135 px, and every image corner is still reached within 33 px.
  for (size_t i = 0; i < grid.px.size(); ++i)
    if (grid.weights[i] > 0 && guessed_from[i] == 1 &&
        std::hypot(grid.px[i][0] - guessed[i][0], grid.px[i][1] - guessed[i][1]) > kMaxSingleMarkerShift * local_square[i]) {
      grid.weights[i] = -1.0;
      --out.refined.model_fit;
      ++out.refined.dropped;
    }
  for (size_t i = 0; i < grid.px.size(); ++i)
    if (grid.weights[i] <= 0) grid.px[i] = kUnseen;
  out.detector = method;
  out.pixels = std::move(grid.px);
  out.weights = std::move(grid.weights);
  if (!enough_seen(out, board)) return std::nullopt;
  return out;
}

BoardDetector::BoardDetector(const CalibrationBoard& board, CornerRefinement refinement,
                             std::vector<ChessboardFinder> finders)
    : impl_(std::make_unique<Impl>()) {
  impl_->board = board;
  impl_->refinement = refinement;
  impl_->finders = finders.empty() ? chessboard_finders(board) : std::move(finders);
  if (board.rows != board.cols)  // mrgingham finds square boards only
    std::erase(impl_->finders, ChessboardFinder::mrgingham);
  if (impl_->finders.empty()) throw BoardError(fmt::format("{}: no chessboard finder applies to this board", board.name));
  if (board.kind == BoardKind::apriltag_grid) {
    impl_->method = "apriltag";
    Config config;
    config.track.family = board.family;
    config.track.quad_decimate = kAprilTagQuadDecimate;
    config.track.threads = 1;
    try {
      impl_->tags = std::make_unique<TagDetector>(config);
    } catch (const std::exception& e) {  // a board made in code with a family libapriltag lacks
      throw BoardError(fmt::format("{}: family: cannot detect \"{}\" tags: {}", board.name, board.family, e.what()));
    }
  } else if (board.kind == BoardKind::charuco) {
    impl_->method = "charuco";
    impl_->charuco = cv::aruco::CharucoBoard::create(board.cols + 1, board.rows + 1, float(board.spacing_m),
                                                     float(board.marker_m),
                                                     cv::aruco::getPredefinedDictionary(board.dictionary_id));
    impl_->aruco_parameters = cv::aruco::DetectorParameters::create();
    // Markers 1 px from the image's edge, not OpenCV's 3: on the calib-charuco capture 2817 corners
    // interpolated instead of 2771, the gain all at the image's edges.
    impl_->aruco_parameters->minDistanceToBorder = 1;
  } else {
    impl_->method = chessboard_finder_name(impl_->finders.front());
  }
}

BoardDetector::~BoardDetector() = default;

const std::string& BoardDetector::method() const { return impl_->method; }

std::optional<BoardObservation> BoardDetector::detect(const unsigned char* grey, int width, int height, size_t stride,
                                                      const std::string& image_name) const {
  return find(grey, width, height, stride, image_name, nullptr);
}

std::optional<BoardObservation> BoardDetector::detect(const unsigned char* grey, int width, int height, size_t stride,
                                                      const std::string& image_name, const CameraModel& lens) const {
  return find(grey, width, height, stride, image_name, &lens);
}

std::optional<BoardObservation> BoardDetector::find(const unsigned char* grey, int width, int height, size_t stride,
                                                    const std::string& image_name, const CameraModel* lens) const {
  if (grey == nullptr || width < 8 || height < 8 || stride < static_cast<size_t>(width)) return std::nullopt;
  // A lens made for another image size would put every point in the wrong place.
  if (lens != nullptr && (lens->width() != width || lens->height() != height)) return std::nullopt;
  try {
    const cv::Mat image(height, width, CV_8UC1, const_cast<unsigned char*>(grey), stride);
    std::optional<BoardObservation> out;
    if (impl_->method == "apriltag")
      out = impl_->detect_apriltags(image, lens);
    else if (impl_->method == "charuco")
      out = impl_->detect_charuco(image);
    else
      out = impl_->detect_chessboard(image);
    if (!out) return std::nullopt;
    // A point with no place inside the image is dropped (mrcal's convention: weight < 0), not the
    // view; the view then needs what a partial view needs.
    for (size_t i = 0; i < out->pixels.size(); ++i)
      if (out->weights[i] > 0 && !finite_inside(out->pixels[i], width, height)) {
        out->pixels[i] = kUnseen;
        out->weights[i] = -1.0;
        ++out->refined.dropped;
      }
    if (out->seen_count() < impl_->board.point_count() && !enough_seen(*out, impl_->board)) return std::nullopt;
    out->image = image_name;
    out->width = width;
    out->height = height;
    return out;
  } catch (...) {  // OpenCV or allocation failure: this image simply has no board
    return std::nullopt;
  }
}

}  // namespace arpipe::calib
