// SE(3) in double precision: Rodrigues and its inverse through unit quaternions, which stay
// well conditioned at every angle, and the closed-form SE(3) exp/log with series near zero.
#include "core/geometry/se3.h"

#include <algorithm>
#include <cmath>

namespace arpipe {

namespace {

// Below this angle the closed forms lose digits to cancellation; the series are exact to
// double precision there (next term ~ theta^6 < 1e-18).
constexpr double kSmallAngle = 1e-3;

Mat3 skew(const Vec3& w) { return {{{0, -w[2], w[1]}, {w[2], 0, -w[0]}, {-w[1], w[0], 0}}}; }

Mat3 add(const Mat3& a, const Mat3& b) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = a[i][j] + b[i][j];
  return r;
}

Mat3 scale(double s, const Mat3& a) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = s * a[i][j];
  return r;
}

// I + a*W + b*W^2 with W = skew(w): the shape of the rotation, of V and of V^-1.
Mat3 identity_plus_skew_terms(const Vec3& w, double a, double b) {
  const Mat3 W = skew(w);
  return add(identity3(), add(scale(a, W), scale(b, mat_mul(W, W))));
}

struct Quaternion {
  double w, x, y, z;
};

// Shepperd's method: divides by the largest of the four candidate components, so no
// cancellation at any angle (the trace form alone fails near pi).
Quaternion quaternion_from_rotation(const Mat3& R) {
  const double trace = R[0][0] + R[1][1] + R[2][2];
  Quaternion q{};
  if (trace >= R[0][0] && trace >= R[1][1] && trace >= R[2][2]) {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + trace));
    q = {0.25 * s, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s};
  } else if (R[0][0] >= R[1][1] && R[0][0] >= R[2][2]) {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + R[0][0] - R[1][1] - R[2][2]));
    q = {(R[2][1] - R[1][2]) / s, 0.25 * s, (R[0][1] + R[1][0]) / s, (R[0][2] + R[2][0]) / s};
  } else if (R[1][1] >= R[2][2]) {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + R[1][1] - R[0][0] - R[2][2]));
    q = {(R[0][2] - R[2][0]) / s, (R[0][1] + R[1][0]) / s, 0.25 * s, (R[1][2] + R[2][1]) / s};
  } else {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + R[2][2] - R[0][0] - R[1][1]));
    q = {(R[1][0] - R[0][1]) / s, (R[0][2] + R[2][0]) / s, (R[1][2] + R[2][1]) / s, 0.25 * s};
  }
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};  // the hemisphere with angle in [0, pi]
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// 3x3 inverse by cofactors; only used by the polar iteration on near-rotations.
Mat3 inverse3(const Mat3& m) {
  Mat3 c{};
  c[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  c[0][1] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
  c[0][2] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
  c[1][0] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  c[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
  c[1][2] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
  c[2][0] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  c[2][1] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
  c[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  const double det = m[0][0] * c[0][0] + m[0][1] * c[1][0] + m[0][2] * c[2][0];
  return scale(1.0 / det, c);
}

}  // namespace

Mat3 rotation_from_vector(const Vec3& r) {
  const double theta2 = dot(r, r);
  const double theta = std::sqrt(theta2);
  double a;  // sin(theta)/theta
  double b;  // (1 - cos(theta))/theta^2
  if (theta < kSmallAngle) {
    a = 1.0 - theta2 / 6.0 + theta2 * theta2 / 120.0;
    b = 0.5 - theta2 / 24.0 + theta2 * theta2 / 720.0;
  } else {
    a = std::sin(theta) / theta;
    // 2 sin^2(theta/2) instead of 1 - cos(theta): no cancellation for small theta.
    const double h = std::sin(0.5 * theta);
    b = 2.0 * h * h / theta2;
  }
  return identity_plus_skew_terms(r, a, b);
}

Vec3 vector_from_rotation(const Mat3& R) {
  const Quaternion q = quaternion_from_rotation(R);
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);  // sin(theta/2)
  // theta = 2 atan2(n, w); r = axis * theta = (x, y, z) * theta / n.
  double factor;
  if (n < kSmallAngle) {
    // 2 atan(n/w)/n = (2/w) (1 - (n/w)^2/3 + (n/w)^4/5 ...)
    const double u2 = (n / q.w) * (n / q.w);
    factor = 2.0 / q.w * (1.0 - u2 / 3.0 + u2 * u2 / 5.0);
  } else {
    factor = 2.0 * std::atan2(n, q.w) / n;
  }
  return {factor * q.x, factor * q.y, factor * q.z};
}

double rotation_angle_between(const SE3& a, const SE3& b) {
  return norm(vector_from_rotation(mat_mul(transpose(a.rotation()), b.rotation())));
}

SE3::SE3() : R_(identity3()), t_{0, 0, 0} {}

SE3::SE3(const Mat3& rotation, const Vec3& translation) : R_(rotation), t_(translation) {}

SE3 SE3::from_rt(const Vec3& r, const Vec3& t) { return SE3(rotation_from_vector(r), t); }

SE3 SE3::exp(const Vec6& twist) {
  const Vec3 rho{twist[0], twist[1], twist[2]};
  const Vec3 omega{twist[3], twist[4], twist[5]};
  const double theta2 = dot(omega, omega);
  const double theta = std::sqrt(theta2);
  double b;  // (1 - cos)/theta^2
  double c;  // (theta - sin)/theta^3
  if (theta < kSmallAngle) {
    b = 0.5 - theta2 / 24.0 + theta2 * theta2 / 720.0;
    c = 1.0 / 6.0 - theta2 / 120.0 + theta2 * theta2 / 5040.0;
  } else {
    const double h = std::sin(0.5 * theta);
    b = 2.0 * h * h / theta2;
    c = (theta - std::sin(theta)) / (theta2 * theta);
  }
  const Mat3 V = identity_plus_skew_terms(omega, b, c);
  return SE3(rotation_from_vector(omega), mat_mul(V, rho));
}

Vec3 SE3::rotation_vector() const { return vector_from_rotation(R_); }

Vec6 SE3::log() const {
  const Vec3 omega = vector_from_rotation(R_);
  const double theta2 = dot(omega, omega);
  const double theta = std::sqrt(theta2);
  // V^-1 = I - W/2 + d W^2, d = (1 - theta sin / (2 (1 - cos))) / theta^2
  //      = (1 - (theta/2) cot(theta/2)) / theta^2, finite up to and including pi.
  double d;
  if (theta < kSmallAngle) {
    d = 1.0 / 12.0 + theta2 / 720.0 + theta2 * theta2 / 30240.0;
  } else {
    const double half = 0.5 * theta;
    d = (1.0 - half * std::cos(half) / std::sin(half)) / theta2;
  }
  const Vec3 rho = mat_mul(identity_plus_skew_terms(omega, -0.5, d), t_);
  return {rho[0], rho[1], rho[2], omega[0], omega[1], omega[2]};
}

SE3 SE3::inverse() const {
  const Mat3 Rt = transpose(R_);
  return SE3(Rt, -1.0 * mat_mul(Rt, t_));
}

SE3 SE3::operator*(const SE3& other) const {
  return SE3(mat_mul(R_, other.R_), mat_mul(R_, other.t_) + t_);
}

Vec3 SE3::operator*(const Vec3& point) const { return mat_mul(R_, point) + t_; }

SE3 SE3::interpolate(const SE3& other, double s) const {
  const Vec3 relative = vector_from_rotation(mat_mul(transpose(R_), other.R_));
  const Mat3 R = mat_mul(R_, rotation_from_vector(s * relative));
  return SE3(R, (1.0 - s) * t_ + s * other.t_);
}

SE3 SE3::normalized() const {
  // Newton's iteration for the orthogonal polar factor, X <- (X + X^-T)/2: quadratic
  // convergence, so a drifted rotation (error ~1e-12) is exact after two or three steps.
  Mat3 X = R_;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Mat3 next = scale(0.5, add(X, transpose(inverse3(X))));
    double change = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) change = std::max(change, std::abs(next[i][j] - X[i][j]));
    X = next;
    if (change < 1e-15) break;
  }
  return SE3(X, t_);
}

}  // namespace arpipe
