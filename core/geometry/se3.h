// Rigid transforms in double precision: SE(3) with compose, inverse, exp/log and interpolation.
// Named T_to_from: T_cam_world * p_world = p_cam (docs/DESIGN.md "Space").
#pragma once

#include <array>

#include "core/geometry/vec.h"

namespace arpipe {

class SE3 {
 public:
  SE3();  // identity
  SE3(const Mat3& rotation, const Vec3& translation);  // rotation must be orthonormal, det +1

  static SE3 identity() { return SE3(); }
  // From a rotation vector (axis * angle, Rodrigues, as OpenCV's rvec and mrcal's r) and a translation.
  static SE3 from_rt(const Vec3& r, const Vec3& t);
  // Exponential map of the twist (rho, omega): omega is the rotation vector, rho the "linear" part.
  static SE3 exp(const Vec6& twist);

  const Mat3& rotation() const { return R_; }
  const Vec3& translation() const { return t_; }
  Vec3 rotation_vector() const;  // log of the rotation: axis * angle, angle in [0, pi]
  Vec6 log() const;              // inverse of exp: (rho, omega)

  SE3 inverse() const;
  SE3 operator*(const SE3& other) const;   // composition: (A*B)(p) = A(B(p))
  Vec3 operator*(const Vec3& point) const;  // transforms a point
  Vec3 rotate(const Vec3& direction) const { return mat_mul(R_, direction); }

  // Interpolation: this at s=0, other at s=1, extrapolating outside [0,1]. The "SO(3) x R3" path:
  // R = R_this * exp(s * log(R_this^T R_other)) (slerp, constant angular velocity) and t linearly
  // interpolated, so the origin of `from` moves on a straight line in `to` (for T_world_cam, the
  // camera centre moves straight at constant speed).
  SE3 interpolate(const SE3& other, double s) const;

  // Re-orthonormalises the rotation (polar decomposition); use after long chains of products.
  SE3 normalized() const;

 private:
  Mat3 R_;
  Vec3 t_;
};

// Rotation matrix from a rotation vector (Rodrigues), stable near zero angle.
Mat3 rotation_from_vector(const Vec3& r);
// Rotation vector from a rotation matrix, stable near 0 and near pi.
Vec3 vector_from_rotation(const Mat3& R);
// Angle of the relative rotation between two transforms, radians.
double rotation_angle_between(const SE3& a, const SE3& b);

}  // namespace arpipe
