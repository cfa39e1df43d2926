// The simulator's raw Bayer output: the code of a linear value, and a simulated Bayer capture
// developed (black level, demosaicing) against the same scene's noise-free linear image.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "capture/recording/recording_reader.h"
#include "capture/sim/raw_exposure.h"
#include "capture/sim/simulator.h"
#include "tests/core/image/demosaic_neighbourhood.h"
#include "core/image/bayer.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

TEST(RawExposure, CodesSpanBlackToTheTopCode) {
  EXPECT_EQ(raw_code(0.0, 10, 64), 64);
  EXPECT_EQ(raw_code(1.0, 10, 64), 1023);
  EXPECT_EQ(raw_code(0.5, 10, 64), 544);  // 64 + 0.5 * 959 = 543.5, rounded away from zero
  EXPECT_EQ(raw_code(2.0, 12, 0), 4095);  // clipped at full scale
  EXPECT_EQ(raw_code(-0.01, 10, 64), 54);  // read noise below black stays below it: 64 - 9.59
  EXPECT_EQ(raw_code(-1.0, 10, 64), 0);
  EXPECT_EQ(raw_code(std::nan(""), 10, 64), 64);
}

// A 0.6 m square of one albedo under an overhead sun, against black: flat regions and edges.
TEST(RawExposure, SimulatedBayerCaptureDevelopsToTheLinearImage) {
  SimScene scene;
  scene.camera = exact_camera(32, 24, 30);
  scene.camera.pixel_format = PixelFormat::SGRBG10P;
  scene.camera.sensor.black_level = 64;
  SimObject card = ground_plane("card", 0.6, 0.6);
  card.material.albedo = {0.6, 0.35, 0.15};
  scene.objects.push_back(card);
  scene.lights.push_back(overhead_sun(2.0));
  scene.trajectory = still({0, 0, 1}, {0, 0, 0});
  scene.render.samples_per_pixel = 1;
  scene.render.write_linear = true;

  const fs::path dir = scratch_dir("bayer");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  simulate(scene, options);
  const RecordingReader reader(dir);
  ASSERT_EQ(reader.info().pixel_format, PixelFormat::SGRBG10P);
  Frame frame;
  reader.read(0, frame);
  const cv::Mat linear = read_linear(dir / reader.ground_truth()[0].linear_image);
  ASSERT_EQ(linear.type(), CV_32FC3);

  BayerDevelopment development;
  development.black_level = {64, 64, 64, 64};
  std::vector<float> rgb;
  develop_bayer(frame, development, rgb);
  const int w = frame.width, h = frame.height, radius = 2;
  auto truth = [&](int x, int y, int c) { return double(linear.at<cv::Vec3f>(y, x)[2 - c]); };
  // The analytic bound of tests/core/image/bayer_test: exact where the 5x5 neighbourhood is flat,
  // within 3x its range elsewhere; plus half a raw code (0.5 / 959) of quantisation.
  const double quantisation = 0.5 / (1023 - 64) + 2.0 / 65535;
  int flat_pixels = 0, edge_pixels = 0;
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto [lo, hi, flat] = arpipe::test::demosaic_neighbourhood(truth, x, y, w, h, radius, 1e-6);
      (flat ? flat_pixels : edge_pixels) += 1;
      for (int c = 0; c < 3; ++c) {
        const double error = std::abs(rgb[(size_t(y) * w + x) * 3 + size_t(c)] - truth(x, y, c));
        worst = std::max(worst, error);
        ASSERT_LE(error, (flat ? 0.0 : 3 * (hi - lo)) + quantisation) << x << "," << y << " channel " << c;
      }
    }
  // The scene has both kinds, so both bounds were tested; the card is well below full scale.
  EXPECT_GT(flat_pixels, 50);
  EXPECT_GT(edge_pixels, 50);
  EXPECT_LT(truth(w / 2, h / 2, 0), 0.9);
  EXPECT_GT(truth(w / 2, h / 2, 0), 0.05);
  std::printf("simulated SGRBG10P capture against its linear image: worst error %.4f (%d flat, %d edge pixels)\n", worst,
              flat_pixels, edge_pixels);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arpipe::sim
