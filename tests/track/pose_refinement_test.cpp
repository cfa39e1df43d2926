// refine_pose against the truth (exact points) and against OpenCV's solvePnPRefineLM, an
// independent implementation of the same least-squares problem (noisy points: the same minimum).
#include "core/track/pose_refinement.h"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <random>
#include <vector>

namespace arpipe {
namespace {

// Two tags' corners, 10 and 8 cm, in the z = 0 plane of the world.
std::vector<Vec3> bundle_corners() {
  return {{-0.05, -0.05, 0}, {0.05, -0.05, 0}, {0.05, 0.05, 0},   {-0.05, 0.05, 0},
          {0.13, -0.07, 0},  {0.21, -0.07, 0}, {0.21, 0.01, 0},   {0.13, 0.01, 0}};
}

std::vector<Vec2> seen(const SE3& T, const std::vector<Vec3>& world, double noise, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, noise);
  std::vector<Vec2> out;
  for (const Vec3& w : world) {
    const Vec3 p = T * w;
    out.push_back({p[0] / p[2] + gauss(rng), p[1] / p[2] + gauss(rng)});
  }
  return out;
}

SE3 view(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // The camera 0.4-0.6 m in front of the tags, looking at them, tilted up to ~35 degrees.
  const Vec3 r{3.14159 + 0.5 * u(rng), 0.5 * u(rng), 0.3 * u(rng)};
  return SE3::from_rt(r, {0.05 * u(rng), 0.05 * u(rng), 0.5 + 0.1 * u(rng)});
}

TEST(RefinePose, FindsTheTruePoseFromASeedDegreesAndCentimetresOff) {
  std::mt19937_64 rng(11);
  const auto world = bundle_corners();
  for (int trial = 0; trial < 50; ++trial) {
    const SE3 truth = view(rng);
    const auto image = seen(truth, world, 0.0, rng);
    const SE3 seed = SE3::exp(Vec6{0.02, -0.01, 0.015, 0.05, -0.03, 0.04}) * truth;  // ~4 degrees, ~3 cm
    const auto refined = refine_pose(seed, world, image);
    ASSERT_TRUE(refined) << "trial " << trial;
    EXPECT_LT(norm(refined->translation() - truth.translation()), 1e-9) << "trial " << trial;
    EXPECT_LT(rotation_angle_between(*refined, truth), 1e-9) << "trial " << trial;
  }
}

TEST(RefinePose, ReachesOpenCvsMinimumOnNoisyPoints) {
  std::mt19937_64 rng(12);
  const auto world = bundle_corners();
  std::vector<cv::Point3d> object;
  for (const Vec3& w : world) object.emplace_back(w[0], w[1], w[2]);
  for (int trial = 0; trial < 50; ++trial) {
    const SE3 truth = view(rng);
    const auto image = seen(truth, world, 0.3 / 500.0, rng);  // 0.3 px at 500 px of focal length
    std::vector<cv::Point2d> points;
    for (const Vec2& p : image) points.emplace_back(p[0], p[1]);
    const Vec3 r = truth.rotation_vector();
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << r[0], r[1], r[2]);
    cv::Mat tvec = (cv::Mat_<double>(3, 1) << truth.translation()[0], truth.translation()[1], truth.translation()[2]);
    cv::solvePnPRefineLM(object, points, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec,
                         cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
    const SE3 opencv = SE3::from_rt({rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)},
                                    {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)});
    const auto refined = refine_pose(truth, world, image);
    ASSERT_TRUE(refined) << "trial " << trial;
    // Both at the least-squares minimum; the noise moved it ~1 mm and ~0.1 degree from the truth.
    EXPECT_LT(norm(refined->translation() - opencv.translation()), 1e-8) << "trial " << trial;
    EXPECT_LT(rotation_angle_between(*refined, opencv), 1e-8) << "trial " << trial;
  }
}

TEST(RefinePose, RefusesASeedWithPointsBehindTheCameraAndMismatchedSizes) {
  const auto world = bundle_corners();
  std::mt19937_64 rng(13);
  const SE3 truth = view(rng);
  const auto image = seen(truth, world, 0.0, rng);
  const SE3 behind = SE3::from_rt(truth.rotation_vector(), {0, 0, -0.5});
  EXPECT_FALSE(refine_pose(behind, world, image));
  EXPECT_FALSE(refine_pose(truth, world, std::vector<Vec2>(image.begin(), image.end() - 1)));
  EXPECT_FALSE(refine_pose(truth, {}, {}));
}

}  // namespace
}  // namespace arpipe
