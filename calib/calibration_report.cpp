#include "calib/calibration_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>

namespace arpipe::calib {
namespace {

// Thresholds of the advice, from mrcal's how-to-calibrate: residuals near the detector's noise
// (a few tenths of a pixel), the whole imager covered, tens of views, few outliers.
constexpr double kLargeRmsPx = 1.0;
constexpr double kMinCoveredFraction = 0.75;
constexpr double kCornerGapFraction = 0.12;   // of the image diagonal
constexpr int kFewViews = 10;
constexpr double kManyOutliersFraction = 0.03;
constexpr double kBentBoardM = 0.002;
constexpr double kUncertainCornerPx = 0.5;

bool is_seen(const Vec2& residual) { return std::isfinite(residual[0]) && std::isfinite(residual[1]); }

CoverageGrid coverage_of(const CalibrationResult& result) {
  CoverageGrid grid;
  grid.points.assign(size_t(grid.cols * grid.rows), 0);
  const int w = result.model.width();
  const int h = result.model.height();
  const std::array<Vec2, 4> corners{Vec2{0, 0}, Vec2{double(w - 1), 0}, Vec2{0, double(h - 1)},
                                    Vec2{double(w - 1), double(h - 1)}};
  std::array<double, 4> nearest;
  nearest.fill(std::hypot(w, h));
  for (size_t v = 0; v < result.observations.size(); ++v) {
    const BoardObservation& obs = result.observations[v];
    for (size_t i = 0; i < obs.pixels.size(); ++i) {
      if (!(obs.weights[i] > 0)) continue;
      const Vec2& q = obs.pixels[i];
      const int cx = std::clamp(int(q[0] * grid.cols / w), 0, grid.cols - 1);
      const int cy = std::clamp(int(q[1] * grid.rows / h), 0, grid.rows - 1);
      ++grid.points[size_t(cy * grid.cols + cx)];
      for (size_t c = 0; c < 4; ++c) nearest[c] = std::min(nearest[c], std::hypot(q[0] - corners[c][0], q[1] - corners[c][1]));
    }
  }
  const auto covered = std::count_if(grid.points.begin(), grid.points.end(), [](int n) { return n > 0; });
  grid.covered_fraction = double(covered) / double(grid.points.size());
  grid.worst_corner_gap_px = *std::max_element(nearest.begin(), nearest.end());
  return grid;
}

// "found by: findChessboardCornersSB 10, findChessboardCorners 3; corners placed by the model fit
// 690, cornerSubPix 12, the finder 0, dropped 0": which detector each view needed, and how its
// corners were refined (docs/CALIBRATION.md "Finding the board").
std::string found_by_text(const std::vector<ImageResidual>& images) {
  std::vector<std::pair<std::string, int>> finders;
  BoardObservation::Refinements sum;
  for (const ImageResidual& e : images) {
    auto it = std::find_if(finders.begin(), finders.end(), [&](const auto& f) { return f.first == e.detector; });
    if (it == finders.end())
      finders.emplace_back(e.detector, 1);
    else
      ++it->second;
    sum.model_fit += e.refined.model_fit;
    sum.corner_subpix += e.refined.corner_subpix;
    sum.detector += e.refined.detector;
    sum.dropped += e.refined.dropped;
  }
  std::string s = "found by:";
  for (size_t i = 0; i < finders.size(); ++i)
    s += fmt::format("{} {} {}", i ? "," : "", finders[i].first, finders[i].second);
  if (sum.model_fit + sum.corner_subpix + sum.detector + sum.dropped > 0)
    s += fmt::format("; corners placed by the model fit {}, cornerSubPix {}, the finder {}, dropped {}", sum.model_fit,
                     sum.corner_subpix, sum.detector, sum.dropped);
  return s + "\n";
}

std::vector<ImageResidual> residuals_per_image(const CalibrationResult& result) {
  std::vector<ImageResidual> out;
  for (size_t v = 0; v < result.observations.size(); ++v) {
    const BoardObservation& obs = result.observations[v];
    ImageResidual r;
    r.image = obs.image;
    r.detector = obs.detector;
    r.refined = obs.refined;
    double sum2 = 0;
    for (size_t i = 0; i < obs.pixels.size(); ++i) {
      const Vec2& e = result.residuals_px[v][i];
      if (!is_seen(e)) continue;
      if (!(obs.weights[i] > 0)) {
        ++r.outliers;
        continue;
      }
      ++r.points;
      sum2 += e[0] * e[0] + e[1] * e[1];
      r.max_px = std::max(r.max_px, norm(e));
    }
    r.rms_px = r.points ? std::sqrt(sum2 / r.points) : 0.0;
    out.push_back(r);
  }
  return out;
}

std::vector<std::string> advice_for(const CalibrationReport& r) {
  std::vector<std::string> advice;
  if (r.rms_per_point_px > kLargeRmsPx)
    advice.push_back(fmt::format(
        "the residuals are large ({:.2f} px per point): check focus and motion blur, that the board is flat and "
        "its file matches the print, or try a richer lens model",
        r.rms_per_point_px));
  if (r.views_used < kFewViews)
    advice.push_back(fmt::format("only {} views were used: mrcal's authors aim for 20 to 100, with close-ups",
                                 r.views_used));
  if (r.coverage.covered_fraction < kMinCoveredFraction)
    advice.push_back(fmt::format(
        "the observations cover {:.0f} % of the image (cells of a {}x{} grid): add views with the board in the empty "
        "parts; the model is only known where it was observed",
        100 * r.coverage.covered_fraction, r.coverage.cols, r.coverage.rows));
  if (r.coverage.worst_corner_gap_px > kCornerGapFraction * std::hypot(r.width, r.height))
    advice.push_back(fmt::format(
        "no observation comes closer than {:.0f} px to one of the image corners: add close-ups with the board "
        "reaching into every corner",
        r.coverage.worst_corner_gap_px));
  const int points = r.inliers + r.outliers;
  if (points > 0 && r.outliers > kManyOutliersFraction * points)
    advice.push_back(fmt::format("{} of {} points ({:.1f} %) were thrown out as outliers: look at the worst images",
                                 r.outliers, points, 100.0 * r.outliers / points));
  if (std::max(std::abs(r.board_warp_x_m), std::abs(r.board_warp_y_m)) > kBentBoardM)
    advice.push_back(fmt::format("the board bulges by {:.1f} mm: mount it on something rigid and flat",
                                 1e3 * std::max(std::abs(r.board_warp_x_m), std::abs(r.board_warp_y_m))));
  for (size_t i = 1; i < r.uncertainty.size(); ++i)
    if (r.uncertainty[i].worst_direction_stdev_px > kUncertainCornerPx) {
      advice.push_back(fmt::format(
          "the projection is uncertain near the image corners (up to {:.2f} px, 1 sigma): add views there",
          r.uncertainty[i].worst_direction_stdev_px));
      break;
    }
  if (r.images_total > 0 && 2 * int(r.images_without_board.size()) > r.images_total)
    advice.push_back(fmt::format("the board was found in only {} of {} images", r.images_total - int(r.images_without_board.size()),
                                 r.images_total));
  return advice;
}

}  // namespace

CalibrationReport make_report(const CalibrationResult& result, int images_total,
                              std::vector<std::string> images_without_board) {
  CalibrationReport r;
  r.lensmodel = result.model.lensmodel();
  r.intrinsics = result.model.intrinsics();
  r.width = result.model.width();
  r.height = result.model.height();
  r.images_total = images_total;
  r.images_without_board = std::move(images_without_board);
  r.views_used = int(result.observations.size());
  r.rms_per_coordinate_px = result.rms_per_coordinate_px;
  r.rms_per_point_px = result.rms_per_point_px;
  r.inliers = result.inlier_count;
  r.outliers = result.outlier_count;
  r.board_warp_x_m = result.board_warp_x_m;
  r.board_warp_y_m = result.board_warp_y_m;
  r.per_image = residuals_per_image(result);
  std::vector<int> order(r.per_image.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return r.per_image[size_t(a)].rms_px > r.per_image[size_t(b)].rms_px; });
  order.resize(std::min<size_t>(order.size(), 5));
  r.worst_images = order;
  r.coverage = coverage_of(result);
  const double w = r.width - 1.0;
  const double h = r.height - 1.0;
  r.uncertainty = projection_uncertainty(result, {{w / 2, h / 2}, {0, 0}, {w, 0}, {0, h}, {w, h}}, 0.0);
  std::vector<Vec2> grid;
  for (int j = 0; j < r.uncertainty_grid_rows; ++j)
    for (int i = 0; i < r.uncertainty_grid_cols; ++i)
      grid.push_back({w * i / (r.uncertainty_grid_cols - 1), h * j / (r.uncertainty_grid_rows - 1)});
  r.uncertainty_grid = projection_uncertainty(result, grid, 0.0);
  r.stages = result.stages;
  r.solve_seconds = result.seconds;
  r.advice = advice_for(r);
  return r;
}

std::string report_text(const CalibrationReport& r) {
  std::string s;
  s += fmt::format("{} for a {}x{} image, from {} views ({} images given, {} without the board)\n", r.lensmodel,
                   r.width, r.height, r.views_used, r.images_total, r.images_without_board.size());
  s += fmt::format("  fx {:.3f}  fy {:.3f}  cx {:.3f}  cy {:.3f} px\n", r.intrinsics.at(0), r.intrinsics.at(1),
                   r.intrinsics.at(2), r.intrinsics.at(3));
  if (r.intrinsics.size() > 4 && r.intrinsics.size() <= 20) {
    s += "  distortion";
    for (size_t i = 4; i < r.intrinsics.size(); ++i) s += fmt::format(" {:.6g}", r.intrinsics[i]);
    s += "\n";
  } else if (r.intrinsics.size() > 20) {
    s += fmt::format("  {} spline control-point values\n", r.intrinsics.size() - 4);
  }
  s += fmt::format(
      "residuals: RMS {:.3f} px per point ({:.3f} px per coordinate, mrcal's figure); {} inliers, {} outliers\n",
      r.rms_per_point_px, r.rms_per_coordinate_px, r.inliers, r.outliers);
  s += fmt::format("board warp: {:.2f} mm along x, {:.2f} mm along y\n", 1e3 * r.board_warp_x_m, 1e3 * r.board_warp_y_m);
  s += found_by_text(r.per_image);
  s += "worst images (RMS, max px):\n";
  for (int i : r.worst_images) {
    const ImageResidual& e = r.per_image[size_t(i)];
    s += fmt::format("  {:.3f}  {:.3f}  {} ({} points, {} outliers)\n", e.rms_px, e.max_px, e.image, e.points, e.outliers);
  }
  s += fmt::format("coverage: {:.0f} % of a {}x{} grid of the image; nearest point to the farthest image corner: {:.0f} px\n",
                   100 * r.coverage.covered_fraction, r.coverage.cols, r.coverage.rows, r.coverage.worst_corner_gap_px);
  if (!r.uncertainty.empty()) {
    s += "projection uncertainty at infinity (1 sigma, worst direction):";
    const char* names[] = {"centre", "top-left", "top-right", "bottom-left", "bottom-right"};
    for (size_t i = 0; i < r.uncertainty.size() && i < 5; ++i)
      s += fmt::format(" {} {:.3f} px{}", names[i], r.uncertainty[i].worst_direction_stdev_px,
                       i + 1 < r.uncertainty.size() ? "," : "\n");
  }
  s += "solve:";
  for (const SolveStage& stage : r.stages)
    s += fmt::format(" {} (RMS {:.3f}, {:.2f} s);", stage.name, stage.rms_per_coordinate_px, stage.seconds);
  s += fmt::format(" {:.2f} s in all\n", r.solve_seconds);
  if (r.advice.empty()) {
    s += "advice: none; the data look sufficient\n";
  } else {
    for (const std::string& a : r.advice) s += "advice: " + a + "\n";
  }
  return s;
}

std::string report_json(const CalibrationReport& r) {
  nlohmann::ordered_json j;
  j["lensmodel"] = r.lensmodel;
  j["intrinsics"] = r.intrinsics;
  j["imagersize"] = {r.width, r.height};
  j["images_total"] = r.images_total;
  j["images_without_board"] = r.images_without_board;
  j["views_used"] = r.views_used;
  j["rms_per_point_px"] = r.rms_per_point_px;
  j["rms_per_coordinate_px"] = r.rms_per_coordinate_px;
  j["inliers"] = r.inliers;
  j["outliers"] = r.outliers;
  j["board_warp_m"] = {r.board_warp_x_m, r.board_warp_y_m};
  auto& images = j["per_image"] = nlohmann::ordered_json::array();
  for (const ImageResidual& e : r.per_image)
    images.push_back({{"image", e.image}, {"points", e.points}, {"outliers", e.outliers}, {"rms_px", e.rms_px},
                      {"max_px", e.max_px}, {"detector", e.detector},
                      {"corners_placed_by", {{"model_fit", e.refined.model_fit}, {"corner_subpix", e.refined.corner_subpix},
                                             {"detector", e.refined.detector}, {"dropped", e.refined.dropped}}}});
  j["worst_images"] = r.worst_images;
  j["coverage"] = {{"cols", r.coverage.cols},
                   {"rows", r.coverage.rows},
                   {"points", r.coverage.points},
                   {"covered_fraction", r.coverage.covered_fraction},
                   {"worst_corner_gap_px", r.coverage.worst_corner_gap_px}};
  auto& uncertainty = j["projection_uncertainty_at_infinity"] = nlohmann::ordered_json::array();
  for (const PixelUncertainty& u : r.uncertainty)
    uncertainty.push_back({{"pixel", {u.pixel[0], u.pixel[1]}},
                           {"worst_direction_stdev_px", u.worst_direction_stdev_px},
                           {"rms_stdev_px", u.rms_stdev_px}});
  auto& grid = j["projection_uncertainty_grid"] = {{"cols", r.uncertainty_grid_cols},
                                                   {"rows", r.uncertainty_grid_rows},
                                                   {"pixels", nlohmann::ordered_json::array()},
                                                   {"worst_direction_stdev_px", nlohmann::ordered_json::array()}};
  for (const PixelUncertainty& u : r.uncertainty_grid) {
    grid["pixels"].push_back({u.pixel[0], u.pixel[1]});
    grid["worst_direction_stdev_px"].push_back(u.worst_direction_stdev_px);
  }
  auto& stages = j["stages"] = nlohmann::ordered_json::array();
  for (const SolveStage& s : r.stages)
    stages.push_back({{"name", s.name}, {"rms_per_coordinate_px", s.rms_per_coordinate_px}, {"outliers", s.outliers},
                      {"seconds", s.seconds}});
  j["solve_seconds"] = r.solve_seconds;
  j["advice"] = r.advice;
  return j.dump(2) + "\n";
}

}  // namespace arpipe::calib
