// Omnidirectional stereo: the eye of each ray, and the point as the eye's panorama holds it.
#include "core/geometry/ods_projection.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arpipe {

std::string_view eye_name(Eye eye) {
  switch (eye) {
    case Eye::Left: return "left";
    case Eye::Right: return "right";
    case Eye::Pair: return "pair";
    case Eye::Mono: break;
  }
  return "mono";
}

namespace {

double eye_sign(Eye eye) { return eye == Eye::Left ? 1.0 : eye == Eye::Right ? -1.0 : 0.0; }

}  // namespace

double ods_eye_radius(const OdsRig& rig, double elevation_rad) {
  const double a = std::abs(elevation_rad), half = 0.5 * rig.ipd_m;
  if (a <= rig.pole_merge_from_rad) return half;
  if (a >= rig.pole_merge_to_rad) return 0;
  const double f = (a - rig.pole_merge_from_rad) / (rig.pole_merge_to_rad - rig.pole_merge_from_rad);
  return half * 0.5 * (1 + std::cos(std::numbers::pi * f));
}

Vec3 ods_eye_origin(const OdsRig& rig, Eye eye, const Vec3& up, const Vec3& d) {
  const double sign = eye_sign(eye);
  if (sign == 0) return {0, 0, 0};
  const Vec3 side = cross(up, d);  // horizontal, left of d, |d_h| long
  const double length = norm(side);
  if (!(length > 1e-12)) return {0, 0, 0};
  const double elevation = std::atan2(dot(d, up), length);
  return (sign * ods_eye_radius(rig, elevation) / length) * side;
}

Vec3 ods_eye_point(const OdsRig& rig, Eye eye, const Vec3& up, const Vec3& p) {
  const double sign = eye_sign(eye);
  const double h = dot(p, up);
  const Vec3 horizontal = p - h * up;
  const double rho2 = dot(horizontal, horizontal);
  if (sign == 0 || !(rho2 > 1e-24)) return p;
  // r depends on the elevation of the ray, which depends on r: a contraction for any point
  // outside the eye's circle by more than a few millimetres.
  double r = ods_eye_radius(rig, std::atan2(h, std::sqrt(rho2)));
  for (int round = 0; round < kOdsIterations; ++round)
    r = ods_eye_radius(rig, std::atan2(h, std::sqrt(std::max(rho2 - r * r, 0.0))));
  r = std::min(r, std::sqrt(rho2));
  const double along = std::sqrt(std::max(rho2 - r * r, 0.0));
  // o = (r^2 horizontal + sign r along (up x horizontal)) / rho^2 (docs: the header's derivation).
  const Vec3 o = (r * r / rho2) * horizontal + (sign * r * along / rho2) * cross(up, horizontal);
  return p - o;
}

std::string_view ods_projection_glsl() {
  return R"glsl(
uniform vec3 u_ods_up;     // the panorama's vertical axis in the camera frame
uniform float u_ods_eye;   // + ipd / 2 (left eye), - ipd / 2 (right), 0: a mono view
uniform vec2 u_ods_merge;  // pole merge from, to (radians)
float ods_eye_radius(float elevation) {
  float a = abs(elevation);
  float f = clamp((a - u_ods_merge.x) / max(u_ods_merge.y - u_ods_merge.x, 1e-6), 0.0, 1.0);
  return a >= u_ods_merge.y ? 0.0 : abs(u_ods_eye) * 0.5 * (1.0 + cos(3.14159265358979 * f));
}
vec3 ods_eye_point(vec3 p) {
  float h = dot(p, u_ods_up);
  vec3 horizontal = p - h * u_ods_up;
  float rho2 = dot(horizontal, horizontal);
  if (u_ods_eye == 0.0 || rho2 <= 1e-24) return p;
  float r = ods_eye_radius(atan(h, sqrt(rho2)));
  for (int round = 0; round < 3; ++round) r = ods_eye_radius(atan(h, sqrt(max(rho2 - r * r, 0.0))));
  r = min(r, sqrt(rho2));
  float along = sqrt(max(rho2 - r * r, 0.0));
  vec3 o = (r * r / rho2) * horizontal + (sign(u_ods_eye) * r * along / rho2) * cross(u_ods_up, horizontal);
  return p - o;
}
)glsl";
}

}  // namespace arpipe
