#include "calib/residual_image.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibration_images.h"

namespace arpipe::calib {
namespace {

constexpr int kMinWidth = 640;
constexpr int kGridCols = 16;
constexpr int kGridRows = 12;

// Blue (small) through green to red (large); t in [0, 1].
cv::Scalar colour_for(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const double r = std::clamp(2 * t, 0.0, 1.0);
  const double g = 1 - std::abs(2 * t - 1);
  const double b = std::clamp(1 - 2 * t, 0.0, 1.0);
  return {255 * b, 200 * g, 255 * r};  // BGR
}

}  // namespace

void write_residual_image(const std::filesystem::path& png, const CalibrationResult& result) {
  const int w = result.model.width();
  const int h = result.model.height();
  const double scale = std::max(1.0, double(kMinWidth) / w);
  cv::Mat canvas(int(std::lround(h * scale)), int(std::lround(w * scale)), CV_8UC3, cv::Scalar(245, 245, 245));

  // The largest inlier residual sets the arrow magnification: it becomes 1/12 of the image width.
  double largest = 0;
  std::vector<int> cell_points(size_t(kGridCols * kGridRows), 0);
  for (size_t v = 0; v < result.observations.size(); ++v)
    for (size_t i = 0; i < result.observations[v].pixels.size(); ++i) {
      const Vec2& e = result.residuals_px[v][i];
      if (!std::isfinite(e[0]) || !(result.observations[v].weights[i] > 0)) continue;
      largest = std::max(largest, norm(e));
      const Vec2& q = result.observations[v].pixels[i];
      const int cx = std::clamp(int(q[0] * kGridCols / w), 0, kGridCols - 1);
      const int cy = std::clamp(int(q[1] * kGridRows / h), 0, kGridRows - 1);
      ++cell_points[size_t(cy * kGridCols + cx)];
    }
  const double magnify = largest > 0 ? canvas.cols / 12.0 / largest : 1.0;

  // Cells no observation reached: the lens model there is extrapolated.
  for (int cy = 0; cy < kGridRows; ++cy)
    for (int cx = 0; cx < kGridCols; ++cx)
      if (cell_points[size_t(cy * kGridCols + cx)] == 0)
        cv::rectangle(canvas, cv::Point(cx * canvas.cols / kGridCols, cy * canvas.rows / kGridRows),
                      cv::Point((cx + 1) * canvas.cols / kGridCols - 1, (cy + 1) * canvas.rows / kGridRows - 1),
                      cv::Scalar(200, 200, 225), cv::FILLED);

  for (size_t v = 0; v < result.observations.size(); ++v) {
    const BoardObservation& obs = result.observations[v];
    for (size_t i = 0; i < obs.pixels.size(); ++i) {
      const Vec2& e = result.residuals_px[v][i];
      if (!std::isfinite(e[0]) || !std::isfinite(obs.pixels[i][0])) continue;
      const cv::Point2d at(obs.pixels[i][0] * scale, obs.pixels[i][1] * scale);
      if (!(obs.weights[i] > 0)) {
        cv::drawMarker(canvas, at, cv::Scalar(0, 0, 230), cv::MARKER_CROSS, 9, 2);
        continue;
      }
      const cv::Scalar colour = colour_for(largest > 0 ? norm(e) / largest : 0);
      cv::line(canvas, at, at + cv::Point2d(e[0] * magnify, e[1] * magnify), colour, 1, cv::LINE_AA);
      cv::circle(canvas, at, 1, colour, cv::FILLED);
    }
  }
  const std::string legend = fmt::format(
      "{}  RMS {:.3f} px/point  arrows x{:.0f} (longest {:.2f} px)  red x: outliers  shaded: not observed",
      result.model.lensmodel(), result.rms_per_point_px, magnify, largest);
  cv::putText(canvas, legend, cv::Point(8, canvas.rows - 10), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(40, 40, 40), 1,
              cv::LINE_AA);
  bool written = false;
  try {
    written = cv::imwrite(png.string(), canvas);
  } catch (const cv::Exception& e) {
    throw CalibrationInputError(fmt::format("{}: cannot write the residual picture: {}", png.string(), e.what()));
  }
  if (!written) throw CalibrationInputError(fmt::format("{}: cannot write the residual picture", png.string()));
}

}  // namespace arpipe::calib
