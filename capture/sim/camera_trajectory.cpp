// Where the simulated camera is at any instant: a C1 spline through keyframes (Hermite in
// position, Hermite in each segment's tangent space of SO(3)), or a seeded random orbit whose
// time scale is solved so that the worst motion blur over the capture is the requested one.
#include "capture/sim/camera_trajectory.h"
#include "core/geometry/math_constants.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "capture/sim/sample_rng.h"

namespace arpipe::sim {

namespace {


Mat3 from_columns(const Vec3& x, const Vec3& y, const Vec3& z) {
  return {{{x[0], y[0], z[0]}, {x[1], y[1], z[1]}, {x[2], y[2], z[2]}}};
}

Vec3 column(const Mat3& m, int c) { return {m[0][c], m[1][c], m[2][c]}; }

Vec3 without_component_along(const Vec3& v, const Vec3& unit_axis) { return v - dot(v, unit_axis) * unit_axis; }

// T_cam_world of a camera at `centre` whose axes (world frame) are the columns of R_world_cam.
SE3 pose_from(const Mat3& R_world_cam, const Vec3& centre) {
  const Mat3 R_cam_world = transpose(R_world_cam);
  return SE3(R_cam_world, -1.0 * mat_mul(R_cam_world, centre));
}

// Camera axes looking along `forward` (unit) with image up as close to `up` as possible; world +y,
// then +x, stand in when `up` is too close to the viewing direction.
Mat3 look_rotation(const Vec3& forward, const Vec3& up) {
  Vec3 up_across = without_component_along(up, forward);
  // 1e-6 rad from straight along the axis: the image's up would be ill-determined by rounding.
  if (!(norm(up_across) > 1e-6 * norm(up))) up_across = without_component_along({0, 1, 0}, forward);
  if (!(norm(up_across) > 1e-6)) up_across = without_component_along({1, 0, 0}, forward);
  const Vec3 y = -1.0 * normalized(up_across);  // camera y points down the image
  const Vec3 x = cross(y, forward);
  return from_columns(x, y, forward);
}

// Inverse right Jacobian of SO(3): d/dt exp(phi) = exp(phi) [J_r(phi) phi']_x, so J_r^-1 maps a
// body angular velocity at exp(phi) back to a rate of phi. Finite for |phi| <= pi.
Vec3 inverse_right_jacobian_times(const Vec3& phi, const Vec3& v) {
  const double theta2 = dot(phi, phi);
  const double theta = std::sqrt(theta2);
  double d;  // (1 - (theta/2) cot(theta/2)) / theta^2
  if (theta < 1e-3) {
    d = 1.0 / 12.0 + theta2 / 720.0 + theta2 * theta2 / 30240.0;  // next term ~1e-18: exact
  } else {
    const double half = 0.5 * theta;
    d = (1.0 - half * std::cos(half) / std::sin(half)) / theta2;
  }
  const Vec3 phi_x_v = cross(phi, v);
  return v + 0.5 * phi_x_v + d * cross(phi, phi_x_v);
}

struct Hermite {  // cubic Hermite basis on u in [0, 1]
  double h00, h10, h01, h11;
  explicit Hermite(double u) {
    const double u2 = u * u;
    const double u3 = u2 * u;
    h00 = 2 * u3 - 3 * u2 + 1;
    h10 = u3 - 2 * u2 + u;
    h01 = -2 * u3 + 3 * u2;
    h11 = u3 - u2;
  }
};

// The slope at the middle of three samples from the secant slopes on either side: that of the
// parabola through them, exact for quadratics and right for uneven spacing (the plain Catmull-Rom
// average is not).
Vec3 three_point_slope(const Vec3& back_secant, double h_back, const Vec3& ahead_secant, double h_ahead) {
  return (1.0 / (h_back + h_ahead)) * (h_back * ahead_secant + h_ahead * back_secant);
}

class KeyframePath {
 public:
  explicit KeyframePath(const std::vector<SimKeyframe>& keyframes) {
    if (keyframes.empty()) throw std::invalid_argument("trajectory.keyframes: at least one keyframe needed");
    for (size_t i = 0; i < keyframes.size(); ++i) {
      const SimKeyframe& k = keyframes[i];
      if (!std::isfinite(k.time_s))
        throw std::invalid_argument("trajectory.keyframes[" + std::to_string(i) + "].time_s: not a number");
      if (i > 0 && !(k.time_s > keyframes[i - 1].time_s))
        throw std::invalid_argument("trajectory.keyframes[" + std::to_string(i) +
                                    "].time_s: must be later than the keyframe before it");
      if (!(norm(k.look_at - k.position) > 0))
        throw std::invalid_argument("trajectory.keyframes[" + std::to_string(i) + "]: position and look_at coincide");
      Knot knot;
      knot.t = k.time_s;
      knot.centre = k.position;
      knot.R_world_cam = transpose(keyframe_pose(k).rotation());
      knots_.push_back(knot);
    }
    const size_t n = knots_.size();
    // Interior tangents from the neighbours; the ends stay at rest (zero velocity), which is what
    // makes holding the first and last pose outside the keyframe times C1.
    for (size_t i = 1; i + 1 < n; ++i) {
      Knot& k = knots_[i];
      const double h_back = k.t - knots_[i - 1].t;
      const double h_ahead = knots_[i + 1].t - k.t;
      k.velocity = three_point_slope((1.0 / h_back) * (k.centre - knots_[i - 1].centre), h_back,
                                     (1.0 / h_ahead) * (knots_[i + 1].centre - k.centre), h_ahead);
      // Both neighbours seen from this knot's own tangent space (body frame): log(R_i^T R_j).
      const Vec3 to_back = vector_from_rotation(mat_mul(transpose(k.R_world_cam), knots_[i - 1].R_world_cam));
      const Vec3 to_ahead = vector_from_rotation(mat_mul(transpose(k.R_world_cam), knots_[i + 1].R_world_cam));
      k.omega_body = three_point_slope((-1.0 / h_back) * to_back, h_back, (1.0 / h_ahead) * to_ahead, h_ahead);
    }
    for (size_t i = 0; i + 1 < n; ++i) {
      Knot& k = knots_[i];
      k.delta = vector_from_rotation(mat_mul(transpose(k.R_world_cam), knots_[i + 1].R_world_cam));
      k.end_phi_rate = inverse_right_jacobian_times(k.delta, knots_[i + 1].omega_body);
    }
  }

  SE3 T_cam_world(double t) const {
    // Before the first time (and NaN): the first pose; at or after the last: the last pose.
    if (!(t > knots_.front().t)) return pose_from(knots_.front().R_world_cam, knots_.front().centre);
    if (t >= knots_.back().t) return pose_from(knots_.back().R_world_cam, knots_.back().centre);
    const auto after = std::upper_bound(knots_.begin(), knots_.end(), t,
                                        [](double time, const Knot& knot) { return time < knot.t; });
    const Knot& a = *(after - 1);
    const Knot& b = *after;
    const double h = b.t - a.t;
    const Hermite basis((t - a.t) / h);
    const Vec3 centre = basis.h00 * a.centre + (basis.h10 * h) * a.velocity + basis.h01 * b.centre +
                        (basis.h11 * h) * b.velocity;
    // phi(0) = 0, phi(1) = log(R_a^T R_b); slopes: a's body angular velocity at 0, b's mapped
    // into this segment's tangent space at 1. u = 0 gives R_a exactly.
    const Vec3 phi = (basis.h10 * h) * a.omega_body + basis.h01 * a.delta + (basis.h11 * h) * a.end_phi_rate;
    return pose_from(mat_mul(a.R_world_cam, rotation_from_vector(phi)), centre);
  }

 private:
  struct Knot {
    double t = 0;
    Vec3 centre{};
    Mat3 R_world_cam{};
    Vec3 velocity{0, 0, 0};    // m/s, world
    Vec3 omega_body{0, 0, 0};  // rad/s, camera frame
    Vec3 delta{0, 0, 0};         // log(R_this^T R_next)
    Vec3 end_phi_rate{0, 0, 0};  // J_r^-1(delta) * next.omega_body
  };
  std::vector<Knot> knots_;
};

// A sum of a few sinusoids with amplitudes summing to 1, so it stays within [-1, 1].
struct Wander {
  static constexpr int kWaves = 3;
  std::array<double, kWaves> amplitude{};
  std::array<double, kWaves> frequency{};  // cycles per unit of path time
  std::array<double, kWaves> phase{};

  // Frequencies in [0.05, 0.25] cycles per path unit: the time scale is solved later, so only
  // their ratios (a factor 5) shape the path.
  static constexpr double kMinFrequency = 0.05;
  static constexpr double kMaxFrequency = 0.25;

  static Wander random(SampleRng& rng) {
    Wander w;
    double total = 0;
    for (int k = 0; k < kWaves; ++k) {
      w.amplitude[k] = 0.2 + 0.8 * rng.uniform();
      w.frequency[k] = kMinFrequency + (kMaxFrequency - kMinFrequency) * rng.uniform();
      w.phase[k] = kTwoPi * rng.uniform();
      total += w.amplitude[k];
    }
    for (double& a : w.amplitude) a /= total;
    return w;
  }

  double operator()(double s) const {
    double sum = 0;
    for (int k = 0; k < kWaves; ++k) sum += amplitude[k] * std::sin(kTwoPi * frequency[k] * s + phase[k]);
    return std::clamp(sum, -1.0, 1.0);  // rounding must not step outside the bounds
  }
};

class RandomOrbitPath {
 public:
  RandomOrbitPath(const SimRandomPath& random, const SimCamera& camera, double duration_s, uint64_t seed)
      : random_(random) {
    check(random, duration_s);
    // Stream "orbit": a stream of its own, so other users of the scene seed draw unrelated numbers.
    SampleRng rng(seed, 0x6f72626974ULL);
    azimuth_start_ = kTwoPi * rng.uniform();
    azimuth_drift_ = (rng.uniform() < 0.5 ? -1.0 : 1.0) * (0.02 + 0.04 * rng.uniform());  // cycles per unit
    azimuth_swing_ = 0.5 + 0.7 * rng.uniform();                                           // radians
    azimuth_ = Wander::random(rng);
    distance_ = Wander::random(rng);
    elevation_ = Wander::random(rng);
    for (Wander& w : look_wander_) w = Wander::random(rng);
    // The look-at point wanders by up to 3% of the mean distance on each axis: the target stays
    // near the image centre without sitting exactly on the optical axis.
    look_wander_m_ = 0.015 * (random.min_distance_m + random.max_distance_m);
    if (random.max_blur_px > 0) solve_time_scale(random.max_blur_px, camera, duration_s);
  }

  SE3 T_cam_world(double t) const {
    const Orbit o = orbit(time_scale_ * t);
    return pose_from(o.R_world_cam, o.centre);
  }

 private:
  struct Orbit {
    Vec3 centre;
    Mat3 R_world_cam;
  };

  static void check(const SimRandomPath& r, double duration_s) {
    if (!(r.min_distance_m > 0) || !(r.max_distance_m >= r.min_distance_m) || !std::isfinite(r.max_distance_m))
      throw std::invalid_argument("trajectory.random: need 0 < min_distance <= max_distance");
    const double right_angle = 0.5 * std::numbers::pi;
    if (!(r.min_elevation_rad >= -right_angle) || !(r.max_elevation_rad >= r.min_elevation_rad) ||
        !(r.max_elevation_rad <= right_angle))
      throw std::invalid_argument("trajectory.random: need -90 deg <= min_elevation <= max_elevation <= 90 deg");
    if (!(r.max_blur_px >= 0) || !std::isfinite(r.max_blur_px))
      throw std::invalid_argument("trajectory.random.max_blur_px: must be zero or positive");
    if (!(duration_s >= 0) || !std::isfinite(duration_s))
      throw std::invalid_argument("trajectory: the capture duration must be zero or positive");
  }

  Orbit orbit(double s) const {
    const double mid_distance = 0.5 * (random_.min_distance_m + random_.max_distance_m);
    const double distance = mid_distance + 0.5 * (random_.max_distance_m - random_.min_distance_m) * distance_(s);
    const double mid_elevation = 0.5 * (random_.min_elevation_rad + random_.max_elevation_rad);
    const double elevation =
        mid_elevation + 0.5 * (random_.max_elevation_rad - random_.min_elevation_rad) * elevation_(s);
    const double azimuth = azimuth_start_ + kTwoPi * azimuth_drift_ * s + azimuth_swing_ * azimuth_(s);
    const Vec3 outward{std::cos(azimuth), std::sin(azimuth), 0};  // horizontal, target to camera
    const double ce = std::cos(elevation);
    const double se = std::sin(elevation);
    const Vec3 centre = random_.target + distance * Vec3{ce * outward[0], ce * outward[1], se};
    const Vec3 look_at =
        random_.target + look_wander_m_ * Vec3{look_wander_[0](s), look_wander_[1](s), look_wander_[2](s)};
    const Vec3 forward = normalized(look_at - centre);
    // World +z projected across the line of sight, written so that it never degenerates: at
    // elevation 90 deg it is the horizontal direction away from the camera.
    const Vec3 up_hint{-se * outward[0], -se * outward[1], ce};
    return {centre, look_rotation(forward, up_hint)};
  }

  // fx (|w_perp| + |v_perp| / distance) per unit of path time, by central differences (h = 1e-5
  // units against periods of at least 4 units: truncation ~1e-11, rounding ~1e-11, relative).
  double image_speed_per_unit(double s, double fx) const {
    constexpr double h = 1e-5;
    const Orbit before = orbit(s - h);
    const Orbit after = orbit(s + h);
    const Orbit now = orbit(s);
    const Vec3 axis = column(now.R_world_cam, 2);
    const Vec3 omega =
        (0.5 / h) * vector_from_rotation(mat_mul(after.R_world_cam, transpose(before.R_world_cam)));
    const Vec3 velocity = (0.5 / h) * (after.centre - before.centre);
    const double distance = norm(now.centre - random_.target);
    return fx * (norm(without_component_along(omega, axis)) +
                 norm(without_component_along(velocity, axis)) / distance);
  }

  static double focal_length_px(const CameraModel& model) {
    if (model.has_core()) return model.fx();
    // Other models: the image-centre magnification, from two projections 1e-4 rad apart.
    const auto centre = model.project({0, 0, 1});
    const auto aside = model.project({1e-4, 0, 1});
    if (!centre || !aside) throw std::invalid_argument("camera model: cannot project near the optical axis");
    return norm(Vec2{(*aside)[0] - (*centre)[0], (*aside)[1] - (*centre)[1]}) / 1e-4;
  }

  // Path time runs at time_scale_ units per second. Blur(scale) = scale x exposure x the largest
  // image speed per unit over [0, scale x duration] grows continuously and without bound with the
  // scale, so bisection finds the scale that gives max_blur_px.
  void solve_time_scale(double max_blur_px, const SimCamera& camera, double duration_s) {
    if (camera.exposure_ns.empty()) throw std::invalid_argument("camera.exposure: at least one exposure time needed");
    const int64_t longest_ns = *std::max_element(camera.exposure_ns.begin(), camera.exposure_ns.end());
    if (longest_ns <= 0) throw std::invalid_argument("camera.exposure: must be positive");
    const double fx = focal_length_px(camera.model);
    const double wanted_speed = max_blur_px / (double(longest_ns) * 1e-9);  // px/s

    // The speed on a grid of 128 steps per period of the fastest wave; in between it is linearly
    // interpolated (error ~(pi/128)^2/2 ~ 0.03% of its swing), so the running maximum is a
    // continuous function of the range's end.
    const double step = 1.0 / (128.0 * Wander::kMaxFrequency);
    constexpr size_t kMaxSamples = 4'000'000;  // ~2 s of work; beyond that the path is absurd
    std::vector<double> speed;
    std::vector<double> running_max;
    const auto max_speed_up_to = [&](double s_end) {
      const double position = s_end / step;
      const auto needed = size_t(position) + 2;
      if (needed > kMaxSamples)
        throw std::invalid_argument("trajectory.random: max_blur_px too large for this capture's duration");
      while (speed.size() < needed) {
        const double v = image_speed_per_unit(double(speed.size()) * step, fx);
        speed.push_back(v);
        running_max.push_back(running_max.empty() ? v : std::max(running_max.back(), v));
      }
      const auto j = size_t(position);
      const double fraction = position - double(j);
      return std::max(running_max[j], speed[j] + fraction * (speed[j + 1] - speed[j]));
    };
    const auto speed_at_scale = [&](double scale) { return scale * max_speed_up_to(scale * duration_s); };

    // A first guess from the speed over one slowest period, then doubling / halving to bracket.
    double typical = 0;
    const auto slowest_period_steps = int(1.0 / (Wander::kMinFrequency * step));
    for (int j = 0; j <= slowest_period_steps; ++j) typical = std::max(typical, image_speed_per_unit(j * step, fx));
    if (!(typical > 0))
      throw std::invalid_argument("trajectory.random: this orbit does not move the image (elevation 90 deg?)");
    double low = wanted_speed / typical;
    double high = low;
    for (int doubling = 0; speed_at_scale(high) < wanted_speed; ++doubling) {
      if (doubling > 200) throw std::invalid_argument("trajectory.random: cannot reach max_blur_px");
      high *= 2;
    }
    while (speed_at_scale(low) > wanted_speed) low *= 0.5;
    for (int iteration = 0; iteration < 100 && high - low > 1e-12 * high; ++iteration) {
      const double middle = 0.5 * (low + high);
      (speed_at_scale(middle) < wanted_speed ? low : high) = middle;
    }
    time_scale_ = 0.5 * (low + high);
  }

  SimRandomPath random_;
  double azimuth_start_ = 0;
  double azimuth_drift_ = 0;
  double azimuth_swing_ = 0;
  Wander azimuth_;
  Wander distance_;
  Wander elevation_;
  std::array<Wander, 3> look_wander_;
  double look_wander_m_ = 0;
  double time_scale_ = 0;  // path units per second; 0: a still camera at the start pose
};

}  // namespace

struct CameraTrajectory::Path {
  std::variant<KeyframePath, RandomOrbitPath> path;
};

SE3 keyframe_pose(const SimKeyframe& keyframe) {
  const Vec3 sight = keyframe.look_at - keyframe.position;
  if (!(norm(sight) > 0)) throw std::invalid_argument("trajectory keyframe: position and look_at coincide");
  const Mat3 level = look_rotation(normalized(sight), keyframe.up);
  // Roll about the camera's own z: x turns towards y.
  const double c = std::cos(keyframe.roll_rad);
  const double s = std::sin(keyframe.roll_rad);
  const Vec3 x = column(level, 0);
  const Vec3 y = column(level, 1);
  return pose_from(from_columns(c * x + s * y, c * y - s * x, column(level, 2)), keyframe.position);
}

CameraTrajectory::CameraTrajectory(const SimTrajectory& trajectory, const SimCamera& camera, double duration_s,
                                   uint64_t seed) {
  if (trajectory.kind == SimTrajectory::Kind::Keyframes)
    path_ = std::make_shared<const Path>(Path{KeyframePath(trajectory.keyframes)});
  else
    path_ = std::make_shared<const Path>(Path{RandomOrbitPath(trajectory.random, camera, duration_s, seed)});
}

SE3 CameraTrajectory::T_cam_world(double t_s) const {
  return std::visit([t_s](const auto& path) { return path.T_cam_world(t_s); }, path_->path);
}

}  // namespace arpipe::sim
