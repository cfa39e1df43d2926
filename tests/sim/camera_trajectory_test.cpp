// CameraTrajectory against geometry: keyframe poses look where they should, the keyframe spline
// passes through every keyframe and is C1 (also across near-pi turns), and the random orbit stays
// in its bounds and blurs by exactly the requested number of pixels.
#include "capture/sim/camera_trajectory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace arpipe::sim {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 centre_of(const SE3& T_cam_world) {
  return -1.0 * mat_mul(transpose(T_cam_world.rotation()), T_cam_world.translation());
}

Vec3 optical_axis_in_world(const SE3& T_cam_world) {
  const Mat3& R = T_cam_world.rotation();
  return {R[2][0], R[2][1], R[2][2]};
}

double max_abs_difference(const SE3& a, const SE3& b) {
  double d = 0;
  for (int i = 0; i < 3; ++i) {
    d = std::max(d, std::abs(a.translation()[i] - b.translation()[i]));
    for (int j = 0; j < 3; ++j) d = std::max(d, std::abs(a.rotation()[i][j] - b.rotation()[i][j]));
  }
  return d;
}

void expect_rotation(const Mat3& R) {
  const Mat3 RtR = mat_mul(transpose(R), R);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(RtR[i][j], i == j ? 1.0 : 0.0, 1e-12);
  const double det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) -
                     R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
                     R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
  EXPECT_NEAR(det, 1.0, 1e-12);
}

SimTrajectory keyframes(std::vector<SimKeyframe> frames) {
  SimTrajectory trajectory;
  trajectory.kind = SimTrajectory::Kind::Keyframes;
  trajectory.keyframes = std::move(frames);
  return trajectory;
}

// A keyframe at `position` looking along azimuth `yaw` (about world +z) and `pitch` above the
// horizon, rolled by `roll`.
SimKeyframe yawed(double t, const Vec3& position, double yaw, double pitch = 0, double roll = 0) {
  const Vec3 direction{std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), std::sin(pitch)};
  return {t, position, position + direction, {0, 0, 1}, roll};
}

TEST(CameraTrajectory, KeyframePoseLooksAtTheTargetWithWorldUpUp) {
  const std::vector<SimKeyframe> cases = {
      {0, {0.3, -0.5, 0.4}, {0, 0, 0}, {0, 0, 1}, 0},
      {0, {2, 1, -1}, {-1, 0.5, 3}, {0.3, 0.2, 1}, 0},  // up not orthogonal to the view
      {0, {0, 0, 1}, {0.2, 0.1, 0}, {0, 0, 1}, 0},       // steeply down
      {0, {-1, 4, 2}, {5, -3, 0.5}, {0, 0, 7}, 0},       // up not unit length
  };
  for (const SimKeyframe& k : cases) {
    const SE3 T = keyframe_pose(k);
    expect_rotation(T.rotation());
    // The camera sits at `position` and look_at lies on its optical axis, in front.
    const Vec3 c = centre_of(T);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], k.position[i], 1e-12);
    const Vec3 target = T * k.look_at;
    const double distance = norm(k.look_at - k.position);
    EXPECT_NEAR(target[0], 0, 1e-12 * distance);
    EXPECT_NEAR(target[1], 0, 1e-12 * distance);
    EXPECT_NEAR(target[2], distance, 1e-12 * distance);
    // World up points straight up the image: no x, negative y (y is down).
    const Vec3 up = T.rotate(normalized(k.up));
    EXPECT_NEAR(up[0], 0, 1e-12);
    EXPECT_LT(up[1], -1e-3);
  }
}

TEST(CameraTrajectory, RollTurnsTheCameraClockwiseInTheImage) {
  SimKeyframe k{0, {0, -1, 0}, {0, 0, 0}, {0, 0, 1}, kPi / 2};
  const SE3 T = keyframe_pose(k);
  // The camera's x axis turned onto its old y axis (clockwise as the image is drawn, y down), so
  // world up, which was image up (-y), now points to image left (-x).
  const Vec3 up = T.rotate({0, 0, 1});
  EXPECT_NEAR(up[0], -1, 1e-12);
  EXPECT_NEAR(up[1], 0, 1e-12);
  EXPECT_NEAR(up[2], 0, 1e-12);
  // A small roll: the up direction tilts by exactly that angle towards image left.
  k.roll_rad = 0.1;
  const Vec3 tilted = keyframe_pose(k).rotate({0, 0, 1});
  EXPECT_NEAR(std::atan2(-tilted[0], -tilted[1]), 0.1, 1e-12);
  // The optical axis does not move.
  const Vec3 target = keyframe_pose(k) * k.look_at;
  EXPECT_NEAR(target[0], 0, 1e-12);
  EXPECT_NEAR(target[1], 0, 1e-12);
}

TEST(CameraTrajectory, KeyframePoseFallsBackWhenUpIsAlongTheView) {
  // Looking straight down with up = +z (the defaults): world +y (the tag's top) becomes image up.
  const SE3 T = keyframe_pose({0, {0, 0, 1}, {0, 0, 0}, {0, 0, 1}, 0});
  expect_rotation(T.rotation());
  const Vec3 y_world = T.rotate({0, 1, 0});
  EXPECT_NEAR(y_world[0], 0, 1e-12);
  EXPECT_NEAR(y_world[1], -1, 1e-12);
  EXPECT_THROW(keyframe_pose({0, {1, 2, 3}, {1, 2, 3}, {0, 0, 1}, 0}), std::invalid_argument);
}

TEST(CameraTrajectory, OneKeyframeIsAStillCamera) {
  const SimKeyframe k{0.5, {0.2, -0.4, 0.6}, {0, 0, 0}, {0, 0, 1}, 0.2};
  const CameraTrajectory trajectory(keyframes({k}), SimCamera{}, 2.0, 1);
  for (double t : {-1.0, 0.0, 0.5, 1.3, 10.0})
    EXPECT_EQ(max_abs_difference(trajectory.T_cam_world(t), keyframe_pose(k)), 0);
}

std::vector<SimKeyframe> uneven_keyframes() {
  return {
      {0.0, {0.5, -0.5, 0.6}, {0, 0, 0}, {0, 0, 1}, 0.0},
      {0.4, {0.6, 0.1, 0.5}, {0.05, 0, 0}, {0, 0, 1}, 0.3},
      {1.7, {-0.2, 0.7, 0.8}, {0, 0.1, 0}, {0, 0, 1}, -0.2},
      {2.0, {-0.6, 0.2, 0.4}, {0, 0, 0.05}, {0, 0, 1}, 0.0},
  };
}

TEST(CameraTrajectory, PassesThroughEveryKeyframeAndHoldsTheEnds) {
  const auto frames = uneven_keyframes();
  const CameraTrajectory trajectory(keyframes(frames), SimCamera{}, 3.0, 1);
  // 1e-12: a pose built from the same keyframe; only rounding in the evaluation may differ.
  for (const SimKeyframe& k : frames)
    EXPECT_LT(max_abs_difference(trajectory.T_cam_world(k.time_s), keyframe_pose(k)), 1e-12);
  EXPECT_EQ(max_abs_difference(trajectory.T_cam_world(-5), keyframe_pose(frames.front())), 0);
  EXPECT_EQ(max_abs_difference(trajectory.T_cam_world(9), keyframe_pose(frames.back())), 0);
  // In between it really moves (not a step function).
  EXPECT_GT(norm(centre_of(trajectory.T_cam_world(1.0)) - frames[1].position), 0.05);
}

// Velocities from one side of t by second-order one-sided differences: for position,
// (-3 f(t) + 4 f(t +- d) - f(t +- 2d)) / (+- 2d); for rotation the same on phi(s) = log(R(t)^T R(t + s)),
// which is the body angular velocity times s to first order. Truncation ~ d^2/3 |f'''|.
struct Velocity {
  Vec3 linear;
  Vec3 angular;  // camera (body) frame
};
Velocity one_sided_velocity(const CameraTrajectory& trajectory, double t, double side, double d) {
  const SE3 T0 = trajectory.T_cam_world(t);
  const SE3 T1 = trajectory.T_cam_world(t + side * d);
  const SE3 T2 = trajectory.T_cam_world(t + 2 * side * d);
  const double scale = 1.0 / (side * 2 * d);
  Velocity v;
  v.linear = scale * (4.0 * centre_of(T1) - 3.0 * centre_of(T0) - centre_of(T2));
  // R_world_cam = R_cam_world^T; body-frame increments: log(R_wc(t)^T R_wc(t+s)) = log(R_cw(t) R_cw(t+s)^T).
  const Vec3 phi1 = vector_from_rotation(mat_mul(T0.rotation(), transpose(T1.rotation())));
  const Vec3 phi2 = vector_from_rotation(mat_mul(T0.rotation(), transpose(T2.rotation())));
  v.angular = scale * (4.0 * phi1 - phi2);
  return v;
}

// C1 at every knot: left and right velocities agree. With d = 1e-4 s the truncation error is
// ~d^2/3 x |third derivative| (< 1e3 here) ~ 3e-6 and rounding ~1e-16 / 1e-4 ~ 1e-12, so 1e-5
// m/s and rad/s separate that from a kink, which would differ by O(1) (velocities here are ~1).
void expect_c1_at(const CameraTrajectory& trajectory, double t, double min_speed) {
  constexpr double d = 1e-4;
  const Velocity left = one_sided_velocity(trajectory, t, -1, d);
  const Velocity right = one_sided_velocity(trajectory, t, +1, d);
  EXPECT_LT(norm(left.linear - right.linear), 1e-5) << "t = " << t;
  EXPECT_LT(norm(left.angular - right.angular), 1e-5) << "t = " << t;
  EXPECT_GE(norm(left.linear) + norm(left.angular), min_speed) << "t = " << t;  // not vacuous
}

TEST(CameraTrajectory, IsC1AcrossEveryKnot) {
  const auto frames = uneven_keyframes();
  const CameraTrajectory trajectory(keyframes(frames), SimCamera{}, 3.0, 1);
  expect_c1_at(trajectory, frames[1].time_s, 0.3);
  expect_c1_at(trajectory, frames[2].time_s, 0.3);
  // The ends come to rest, so holding the end poses is C1 too.
  for (const double t : {frames.front().time_s, frames.back().time_s}) {
    const Velocity inside = one_sided_velocity(trajectory, t, t == frames.front().time_s ? +1 : -1, 1e-4);
    EXPECT_LT(norm(inside.linear), 1e-5);
    EXPECT_LT(norm(inside.angular), 1e-5);
  }
  // Also inside segments (the Hermite pieces are smooth; this guards the segment lookup).
  expect_c1_at(trajectory, 1.0, 0.1);
}

// Total rotation along a sampled path: the sum of the angles between consecutive samples.
double rotation_path_length(const CameraTrajectory& trajectory, double t0, double t1, int steps) {
  double length = 0;
  SE3 previous = trajectory.T_cam_world(t0);
  for (int i = 1; i <= steps; ++i) {
    const SE3 next = trajectory.T_cam_world(t0 + (t1 - t0) * i / steps);
    length += rotation_angle_between(previous, next);
    previous = next;
  }
  return length;
}

TEST(CameraTrajectory, TurnsOf170DegreesGoTheShortWaySmoothly) {
  const double turn = 170.0 * kPi / 180.0;
  const Vec3 p{0, 0, 0.5};
  {
    // Two keyframes: the rotation follows the geodesic, 170 deg (not 190), half way at mid-time.
    const CameraTrajectory trajectory(keyframes({yawed(0, p, 0.3), yawed(1, p, 0.3 + turn)}), SimCamera{}, 1, 1);
    // 2e-6: a 20000-step polyline on a geodesic has no chord error; rounding per step ~1e-10.
    EXPECT_NEAR(rotation_path_length(trajectory, 0, 1, 20000), turn, 2e-6);
    EXPECT_NEAR(rotation_angle_between(trajectory.T_cam_world(0), trajectory.T_cam_world(0.5)), turn / 2, 1e-12);
    EXPECT_LT(max_abs_difference(trajectory.T_cam_world(1), keyframe_pose(yawed(1, p, 0.3 + turn))), 1e-12);
  }
  {
    // Three keyframes turning ~170 deg twice the same way (~340 deg in all), with some pitch and
    // roll so that the turns are not about one axis (a single axis would hide a wrong SO(3)
    // Jacobian): the middle tangent must come from both neighbours without flipping; the path
    // passes through all three, is C1 at the middle, and never jumps between samples.
    const std::vector<SimKeyframe> frames = {yawed(0, p, 0, 0.1, 0), yawed(1, p, turn, -0.2, 0.3),
                                             yawed(1.5, p, 2 * turn, 0.15, -0.1)};
    EXPECT_GT(rotation_angle_between(keyframe_pose(frames[0]), keyframe_pose(frames[1])), 2.9);  // > 166 deg
    EXPECT_GT(rotation_angle_between(keyframe_pose(frames[1]), keyframe_pose(frames[2])), 2.9);
    const CameraTrajectory trajectory(keyframes(frames), SimCamera{}, 2, 1);
    for (const SimKeyframe& k : frames)
      EXPECT_LT(max_abs_difference(trajectory.T_cam_world(k.time_s), keyframe_pose(k)), 1e-12);
    expect_c1_at(trajectory, 1.0, 1.0);
    double largest_step = 0;
    for (int i = 0; i < 15000; ++i)
      largest_step = std::max(largest_step, rotation_angle_between(trajectory.T_cam_world(i * 1e-4),
                                                                   trajectory.T_cam_world((i + 1) * 1e-4)));
    EXPECT_LT(largest_step, 1e-3);  // < 10 rad/s everywhere: no flips
    // At least the two geodesic turns, and no detour of more than ~20 deg.
    const double turns = rotation_angle_between(keyframe_pose(frames[0]), keyframe_pose(frames[1])) +
                         rotation_angle_between(keyframe_pose(frames[1]), keyframe_pose(frames[2]));
    const double length = rotation_path_length(trajectory, 0, 1.5, 30000);
    EXPECT_GT(length, turns - 1e-6);
    EXPECT_LT(length, turns + 0.35);
  }
  {
    // Exactly 180 deg: either way round is right, but the path must be continuous and exact at the ends.
    const CameraTrajectory trajectory(keyframes({yawed(0, p, 0), yawed(1, p, kPi)}), SimCamera{}, 1, 1);
    EXPECT_LT(max_abs_difference(trajectory.T_cam_world(1), keyframe_pose(yawed(1, p, kPi))), 1e-12);
    EXPECT_NEAR(rotation_path_length(trajectory, 0, 1, 20000), kPi, 2e-6);
  }
}

TEST(CameraTrajectory, RejectsBadKeyframes) {
  EXPECT_THROW(CameraTrajectory(keyframes({}), SimCamera{}, 1, 1), std::invalid_argument);
  const Vec3 p{0, 0, 1};
  EXPECT_THROW(CameraTrajectory(keyframes({yawed(0, p, 0), yawed(0, p, 1)}), SimCamera{}, 1, 1), std::invalid_argument);
  EXPECT_THROW(CameraTrajectory(keyframes({yawed(1, p, 0), yawed(0.5, p, 1)}), SimCamera{}, 1, 1),
               std::invalid_argument);
}

// ---- random path ----

SimTrajectory random_path(double max_blur_px) {
  SimTrajectory trajectory;
  trajectory.kind = SimTrajectory::Kind::Random;
  trajectory.random.target = {0.1, -0.2, 0.0};
  trajectory.random.min_distance_m = 0.4;
  trajectory.random.max_distance_m = 0.7;
  trajectory.random.min_elevation_rad = 0.6;
  trajectory.random.max_elevation_rad = 1.3;
  trajectory.random.max_blur_px = max_blur_px;
  return trajectory;
}

SimCamera blur_camera() {
  SimCamera camera;
  camera.model = CameraModel::pinhole(600, 600, 319.5, 239.5, 640, 480);
  camera.exposure_ns = {2'000'000, 8'000'000, 4'000'000};  // the longest, 8 ms, sets the blur
  return camera;
}

// The blur measure of the brief, rebuilt from the poses alone: fx (|w_perp| + |v_perp| / distance)
// x the longest exposure, w and v by central differences (d = 1e-6 s: error ~1e-9 relative), the
// maximum over a grid of `steps` on [0, duration].
double measured_max_blur(const CameraTrajectory& trajectory, const Vec3& target, double duration, int steps) {
  const double fx = 600;
  const double exposure_s = 0.008;
  constexpr double d = 1e-6;
  double largest = 0;
  for (int i = 0; i <= steps; ++i) {
    const double t = duration * i / steps;
    const SE3 before = trajectory.T_cam_world(t - d);
    const SE3 after = trajectory.T_cam_world(t + d);
    const SE3 now = trajectory.T_cam_world(t);
    const Vec3 axis = optical_axis_in_world(now);
    // World-frame angular velocity: log(R_wc(t+d) R_wc(t-d)^T) / 2d, R_wc = R_cw^T.
    const Vec3 w = (0.5 / d) * vector_from_rotation(mat_mul(transpose(after.rotation()), before.rotation()));
    const Vec3 v = (0.5 / d) * (centre_of(after) - centre_of(before));
    const Vec3 w_perp = w - dot(w, axis) * axis;
    const Vec3 v_perp = v - dot(v, axis) * axis;
    const double distance = norm(centre_of(now) - target);
    largest = std::max(largest, fx * (norm(w_perp) + norm(v_perp) / distance) * exposure_s);
  }
  return largest;
}

TEST(CameraTrajectory, RandomPathIsSeeded) {
  const SimTrajectory path = random_path(10);
  const CameraTrajectory a(path, blur_camera(), 3.0, 17);
  const CameraTrajectory b(path, blur_camera(), 3.0, 17);
  const CameraTrajectory c(path, blur_camera(), 3.0, 18);
  double difference = 0;
  for (double t = 0; t <= 3.0; t += 0.25) {
    EXPECT_EQ(max_abs_difference(a.T_cam_world(t), b.T_cam_world(t)), 0) << t;  // bit-identical
    difference = std::max(difference, max_abs_difference(a.T_cam_world(t), c.T_cam_world(t)));
  }
  EXPECT_GT(difference, 0.05);
}

TEST(CameraTrajectory, RandomPathStaysWithinItsBounds) {
  for (const uint64_t seed : {1u, 2u, 3u, 99u}) {
    for (const double top_elevation : {1.3, kPi / 2}) {  // also right overhead: never degenerate
      SimTrajectory path = random_path(30);
      path.random.max_elevation_rad = top_elevation;
      const CameraTrajectory trajectory(path, blur_camera(), 4.0, seed);
      const Vec3& target = path.random.target;
      for (int i = 0; i <= 2000; ++i) {
        const SE3 T = trajectory.T_cam_world(4.0 * i / 2000);
        expect_rotation(T.rotation());
        const Vec3 offset = centre_of(T) - target;
        const double distance = norm(offset);
        // 1e-12: the bounds hold by construction, up to rounding.
        EXPECT_GE(distance, path.random.min_distance_m - 1e-12);
        EXPECT_LE(distance, path.random.max_distance_m + 1e-12);
        const double elevation = std::asin(offset[2] / distance);
        EXPECT_GE(elevation, path.random.min_elevation_rad - 1e-9);
        EXPECT_LE(elevation, path.random.max_elevation_rad + 1e-9);
        // Looking at the target, give or take the small wander (3% of the mean distance per axis).
        const Vec3 target_cam = T * target;
        EXPECT_LT(std::hypot(target_cam[0], target_cam[1]) / target_cam[2], 0.1);
        // World up is image up whenever it is not (nearly) along the view; the look-at wander
        // (< 0.07 rad off the target) may tilt it a little sideways.
        if (elevation < 1.4) {
          const Vec3 up = T.rotate({0, 0, 1});
          EXPECT_LT(up[1], 0);
          EXPECT_LT(std::abs(up[0]), 0.1 * std::abs(up[1]) + 0.05);
        }
      }
    }
  }
}

TEST(CameraTrajectory, RandomPathBlursByTheRequestedAmount) {
  for (const double blur : {1.0, 10.0, 40.0}) {
    for (const uint64_t seed : {4u, 5u}) {
      const SimTrajectory path = random_path(blur);
      const double duration = 2.0;
      const CameraTrajectory trajectory(path, blur_camera(), duration, seed);
      // The solver is within ~0.1% (linear interpolation on its grid, 128 steps per fastest
      // period); 1% leaves room for the two grids differing, well inside the 5% the design asks.
      EXPECT_NEAR(measured_max_blur(trajectory, path.random.target, duration, 20000), blur, 0.01 * blur)
          << "seed " << seed;
    }
  }
}

TEST(CameraTrajectory, RandomPathWithoutBlurIsStill) {
  const CameraTrajectory trajectory(random_path(0), blur_camera(), 5.0, 3);
  const SE3 start = trajectory.T_cam_world(0);
  for (double t : {0.1, 1.0, 4.9, 5.0}) EXPECT_EQ(max_abs_difference(trajectory.T_cam_world(t), start), 0);
  EXPECT_EQ(measured_max_blur(trajectory, random_path(0).random.target, 5.0, 100), 0);
}

TEST(CameraTrajectory, RejectsBadRandomPaths) {
  SimTrajectory path = random_path(10);
  path.random.min_distance_m = 0.8;  // above max
  EXPECT_THROW(CameraTrajectory(path, blur_camera(), 1, 1), std::invalid_argument);
  path = random_path(10);
  path.random.min_distance_m = 0;
  EXPECT_THROW(CameraTrajectory(path, blur_camera(), 1, 1), std::invalid_argument);
  path = random_path(10);
  path.random.max_elevation_rad = 2.0;  // past overhead
  EXPECT_THROW(CameraTrajectory(path, blur_camera(), 1, 1), std::invalid_argument);
  path = random_path(-1);
  EXPECT_THROW(CameraTrajectory(path, blur_camera(), 1, 1), std::invalid_argument);
  path = random_path(10);
  EXPECT_THROW(CameraTrajectory(path, blur_camera(), -1, 1), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe::sim
