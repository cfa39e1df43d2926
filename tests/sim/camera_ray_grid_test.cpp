// CameraRayGrid: interpolated rays land where mrcal projects them back, for a plain and a
// strongly distorted lens, and the grid refines itself where it must.
#include "capture/sim/camera_ray_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace arpipe::sim {
namespace {

// Reprojects interpolated rays at random sub-pixel positions and returns the worst error.
double worst_reprojection_px(const CameraModel& model, const CameraRayGrid& grid) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> x(-0.5, model.width() - 0.5), y(-0.5, model.height() - 0.5);
  double worst = 0;
  for (int i = 0; i < 5000; ++i) {
    const double px = x(random), py = y(random);
    std::array<double, 3> d{};
    EXPECT_TRUE(grid.ray(px, py, d));
    EXPECT_NEAR(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], 1.0, 1e-12);
    const auto q = model.project({d[0], d[1], d[2]});
    if (!q) {
      ADD_FAILURE() << "ray at " << px << "," << py << " does not project";
      continue;
    }
    worst = std::max(worst, std::hypot((*q)[0] - px, (*q)[1] - py));
  }
  return worst;
}

TEST(CameraRayGrid, PinholeRaysAreExact) {
  const CameraModel model = CameraModel::pinhole(400, 410, 159.5, 121.0, 320, 240);
  const CameraRayGrid grid(model);
  EXPECT_EQ(grid.spacing_px(), 1.0);
  // A pinhole's ray is linear in the pixel, so bilinear interpolation of unit rays is exact up to
  // the normalisation's curvature and float storage: far below a thousandth of a pixel.
  EXPECT_LT(worst_reprojection_px(model, grid), 1e-3);
}

TEST(CameraRayGrid, DistortedLensWithinTheRequestedError) {
  // OPENCV8 with strong barrel distortion, like a wide-angle board camera.
  const CameraModel model("LENSMODEL_OPENCV8", {300, 300, 160, 120, -0.30, 0.09, 0.001, -0.001, -0.01, 0.0, 0.0, 0.0},
                          320, 240);
  const CameraRayGrid grid(model, 0.002);
  EXPECT_LE(grid.measured_error_px(), 0.002);
  // The random positions include cell midpoints' worst cases only statistically: allow 2x the
  // midpoint check, still 50x below the simulator's 0.1 px corner budget.
  EXPECT_LT(worst_reprojection_px(model, grid), 0.004);
}

TEST(CameraRayGrid, ALensMrcalCannotUnprojectIsRefusedByName) {
  const CameraModel cahvore("LENSMODEL_CAHVORE_linearity=0.00",
                            {300, 300, 160, 120, 0.01, -0.02, 0.1, 0.01, 0.001, 0.0, 0.0, 0.0}, 320, 240);
  try {
    const CameraRayGrid grid(cahvore);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("CAHVORE"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arpipe::sim
