// Direction sampling for the simulator's lighting.
#include "capture/sim/light_sampling.h"
#include "core/geometry/math_constants.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arpipe::sim {

namespace {
}

Frame3 frame_around(const Vec3& n) {
  const double sign = std::copysign(1.0, n[2]);
  const double a = -1.0 / (sign + n[2]);
  const double b = n[0] * n[1] * a;
  return {{1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]}, {b, sign + n[1] * n[1] * a, -n[1]}, n};
}

double one_minus_cos(double half_angle_rad) {
  const double s = std::sin(0.5 * half_angle_rad);
  return 2 * s * s;
}

double cone_solid_angle(double one_minus_cos_half_angle) { return kTwoPi * one_minus_cos_half_angle; }

Vec3 sample_cone(const Frame3& frame, double one_minus_cos_half_angle, double u1, double u2) {
  // 1 - cos(theta) is uniform in [0, 1 - cos(alpha)]; sin^2 = (1 - cos)(1 + cos) keeps tiny cones exact.
  const double omc = u1 * one_minus_cos_half_angle;
  const double cos_theta = 1.0 - omc;
  const double sin_theta = std::sqrt(std::max(0.0, omc * (2.0 - omc)));
  const double phi = kTwoPi * u2;
  return frame.to_world(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
}

Vec3 sample_cosine_hemisphere(const Frame3& frame, double u1, double u2) {
  // Malley's method: uniform on the unit disc, lifted onto the hemisphere.
  const double r = std::sqrt(u1);
  const double phi = kTwoPi * u2;
  return frame.to_world(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1)));
}

SphereCone sphere_cone(const Vec3& point, const Vec3& centre, double radius) {
  SphereCone cone;
  const Vec3 to_centre = centre - point;
  cone.distance = norm(to_centre);
  if (!(cone.distance > radius)) return cone;
  cone.axis = (1.0 / cone.distance) * to_centre;
  const double sin2 = (radius / cone.distance) * (radius / cone.distance);
  cone.one_minus_cos = sin2 / (1.0 + std::sqrt(1.0 - sin2));  // 1 - sqrt(1 - s^2) without cancellation
  cone.outside = true;
  return cone;
}

}  // namespace arpipe::sim
