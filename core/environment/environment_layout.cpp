// Pixel <-> direction maps and texel solid angles of the four light-probe layouts (conventions in
// the header). Inverses use atan2 forms so that directions near the poles keep full precision.
#include "core/environment/environment_layout.h"
#include "core/geometry/math_constants.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/scene/asset_error.h"

namespace arpipe {
namespace {


// ---- disk layouts ----------------------------------------------------------------------------

Vec2 pixel_to_disk(int n, double px, double py) { return {2 * (px + 0.5) / n - 1, 1 - 2 * (py + 0.5) / n}; }
Vec2 disk_to_pixel(int n, double u, double v) { return {(u + 1) * n / 2 - 0.5, (1 - v) * n / 2 - 0.5}; }

Vec3 angular_direction(double u, double v) {
  const double r = std::hypot(u, v);
  if (r == 0) return {0, 0, -1};
  const double s = std::sin(kPi * r) / r;
  return {u * s, v * s, -std::cos(kPi * r)};
}

Vec2 angular_disk_point(const Vec3& d) {
  const double lateral = std::hypot(d[0], d[1]);
  const double r = std::atan2(lateral, -d[2]) / kPi;
  if (lateral == 0) return d[2] > 0 ? Vec2{0, -1} : Vec2{0, 0};
  return {d[0] / lateral * r, d[1] / lateral * r};
}

Vec3 mirror_direction(double u, double v) {
  const double r2 = u * u + v * v;
  const double s = std::sqrt(std::max(0.0, 1 - r2));
  return {2 * u * s, 2 * v * s, 1 - 2 * r2};
}

Vec2 mirror_disk_point(const Vec3& d) {
  const double lateral = std::hypot(d[0], d[1]);
  const double r = std::sin(0.5 * std::atan2(lateral, d[2]));
  if (lateral == 0) return d[2] < 0 ? Vec2{0, -1} : Vec2{0, 0};
  return {d[0] / lateral * r, d[1] / lateral * r};
}

// The pieces of [u0, u1] (clipped to [-1, 1]) between which the chord of the unit disk clipped to
// [v0, v1] has one smooth formula: split where the circle crosses v = v0 and v = v1.
std::vector<double> chord_breaks(double u0, double u1, double v0, double v1) {
  std::vector<double> breaks = {std::max(u0, -1.0), std::min(u1, 1.0)};
  if (breaks[0] < 0 && breaks[1] > 0) breaks.push_back(0);  // so no piece reaches both u = -1 and u = 1
  for (double c : {v0, v1})
    if (std::abs(c) < 1) {
      const double w = std::sqrt(1 - c * c);
      for (double b : {-w, w})
        if (b > breaks[0] && b < breaks[1]) breaks.push_back(b);
    }
  std::sort(breaks.begin(), breaks.end());
  return breaks;
}

double half_chord(double u) { return std::sqrt(std::max(0.0, 1 - u * u)); }

// Area of [u0, u1] x [v0, v1] inside the unit disk, in closed form: on each piece the chord's ends
// are v0 or -s(u) below and v1 or s(u) above, with s = sqrt(1 - u^2), S = integral of s.
double rect_disk_area(double u0, double u1, double v0, double v1) {
  const auto S = [](double u) { return 0.5 * (u * half_chord(u) + std::asin(std::clamp(u, -1.0, 1.0))); };
  const std::vector<double> breaks = chord_breaks(u0, u1, v0, v1);
  double area = 0;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k], b = breaks[k + 1];
    if (b <= a) continue;
    // Between breaks the circle is wholly above or below each edge; at the midpoint it can only
    // touch an edge at |v| = 1, where the circle is the limit (hence <= and >=).
    const double mid = half_chord(0.5 * (a + b));
    const bool top_is_circle = mid <= v1, bottom_is_circle = -mid >= v0;
    const double top = top_is_circle ? mid : v1, bottom = bottom_is_circle ? -mid : v0;
    if (top <= bottom) continue;
    const double upper = top_is_circle ? S(b) - S(a) : v1 * (b - a);
    const double lower = bottom_is_circle ? -(S(b) - S(a)) : v0 * (b - a);
    area += upper - lower;
  }
  return std::max(0.0, area);
}

// 16-point Gauss-Legendre nodes and weights on [-1, 1] (positive half; symmetric).
constexpr std::array<double, 8> kGaussX = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274,
                                           0.6178762444026438, 0.7554044083550030, 0.8656312023878318,
                                           0.9445750230732326, 0.9894009349916499};
constexpr std::array<double, 8> kGaussW = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025,
                                           0.1495959888165767, 0.1246289712555339, 0.0951585116824928,
                                           0.0622535239386479, 0.0271524594117541};

template <class F>
double gauss16(double a, double b, const F& f) {
  const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
  double sum = 0;
  for (size_t i = 0; i < kGaussX.size(); ++i) sum += kGaussW[i] * (f(mid - half * kGaussX[i]) + f(mid + half * kGaussX[i]));
  return sum * half;
}

// Solid-angle density of the angular map in (u, v): pi sin(pi r) / r (pi^2 at the centre).
double angular_density(double u, double v) {
  const double r = std::hypot(u, v);
  return r < 1e-8 ? kPi * kPi : kPi * std::sin(kPi * r) / r;
}

// Gauss-Legendre nodes and weights on [-1, 1] for 4 and 8 points (positive halves).
constexpr std::array<double, 2> kGauss4X = {0.3399810435848563, 0.8611363115940526};
constexpr std::array<double, 2> kGauss4W = {0.6521451548625461, 0.3478548451374538};
constexpr std::array<double, 4> kGauss8X = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                            0.9602898564975363};
constexpr std::array<double, 4> kGauss8W = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                            0.1012285362903763};

// A texel wholly inside the disk: tensor Gauss-Legendre on the square. The density is entire with
// k-th derivatives ~ pi^(k+1), so the n-point rule's remainder on a square of side h is about
// h^(2n+1) (n!)^4 / ((2n + 1) ((2n)!)^3) pi^(2n+1) per unit area: below 1e-13 relative for n = 4
// when h <= 0.05 (N >= 40) and for n = 8 when h <= 2.
template <size_t M>
double tensor_gauss(double u0, double u1, double v0, double v1, const std::array<double, M>& nodes,
                    const std::array<double, M>& weights) {
  const double hu = 0.5 * (u1 - u0), mu = 0.5 * (u0 + u1), hv = 0.5 * (v1 - v0), mv = 0.5 * (v0 + v1);
  double sum = 0;
  for (size_t i = 0; i < M; ++i)
    for (double su : {-1.0, 1.0})
      for (size_t j = 0; j < M; ++j)
        for (double sv : {-1.0, 1.0})
          sum += weights[i] * weights[j] * angular_density(mu + su * hu * nodes[i], mv + sv * hv * nodes[j]);
  return sum * hu * hv;
}

double angular_rect_solid_angle(double u0, double u1, double v0, double v1) {
  const auto inside = [](double u, double v) { return u * u + v * v <= 1; };
  if (inside(u0, v0) && inside(u0, v1) && inside(u1, v0) && inside(u1, v1))
    return u1 - u0 <= 0.05 ? tensor_gauss(u0, u1, v0, v1, kGauss4X, kGauss4W)
                           : tensor_gauss(u0, u1, v0, v1, kGauss8X, kGauss8W);
  const auto chord_integral = [&](double u) {
    const double s = half_chord(u);
    const double lo = std::max(v0, -s), hi = std::min(v1, s);
    if (hi <= lo) return 0.0;
    return gauss16(lo, hi, [u](double v) { return angular_density(u, v); });
  };
  const std::vector<double> breaks = chord_breaks(u0, u1, v0, v1);
  double total = 0;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k], b = breaks[k + 1];
    if (b <= a) continue;
    // Where a piece ends at u = +-1 the chord shrinks like sqrt(1 - |u|); u = end -+ (b - a) w^2
    // makes the integrand smooth in w again.
    if (b == 1.0 || a == -1.0) {
      const double end = b == 1.0 ? 1.0 : -1.0, sign = b == 1.0 ? -1.0 : 1.0, length = b - a;
      total += gauss16(0.0, 1.0, [&](double w) { return chord_integral(end + sign * length * w * w) * 2 * length * w; });
    } else {
      total += gauss16(a, b, chord_integral);
    }
  }
  return total;
}

// ---- cube cross ------------------------------------------------------------------------------

enum Face { kPosX, kNegX, kPosY, kNegY, kPosZ, kNegZ };
constexpr std::array<std::array<int, 2>, 6> kFaceCell = {{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 3}, {1, 1}}};

int face_at_cell(int column, int row) {
  for (int f = 0; f < 6; ++f)
    if (kFaceCell[f][0] == column && kFaceCell[f][1] == row) return f;
  return -1;
}

Vec3 face_direction(int face, double a, double b) {
  switch (face) {
    case kPosY: return {a, 1, b};
    case kNegX: return {-1, b, -a};
    case kNegZ: return {a, b, -1};
    case kPosX: return {1, b, a};
    case kNegY: return {a, -1, -b};
    default: return {a, -b, 1};  // kPosZ: the back face, upside down
  }
}

int face_of(const Vec3& d) {
  const double ax = std::abs(d[0]), ay = std::abs(d[1]), az = std::abs(d[2]);
  if (ax >= ay && ax >= az) return d[0] > 0 ? kPosX : kNegX;
  if (ay >= az) return d[1] > 0 ? kPosY : kNegY;
  return d[2] > 0 ? kPosZ : kNegZ;
}

// Inverse of face_direction: (a, b) on the face's tangent plane.
Vec2 face_coordinates(int face, const Vec3& d) {
  switch (face) {
    case kPosX: return {d[2] / d[0], d[1] / d[0]};
    case kNegX: return {d[2] / d[0], -d[1] / d[0]};  // t = -Dx: a = -Dz / t, b = Dy / t
    case kPosY: return {d[0] / d[1], d[2] / d[1]};
    case kNegY: return {-d[0] / d[1], d[2] / d[1]};  // t = -Dy: a = Dx / t, b = -Dz / t
    case kPosZ: return {d[0] / d[2], -d[1] / d[2]};
    default: return {-d[0] / d[2], -d[1] / d[2]};     // kNegZ, t = -Dz
  }
}

// Solid angle of [a0, a1] x [b0, b1] on a cube face's tangent plane at distance 1.
double face_rect_solid_angle(double a0, double a1, double b0, double b1) {
  const auto A = [](double x, double y) { return std::atan2(x * y, std::sqrt(x * x + y * y + 1)); };
  return A(a1, b1) - A(a0, b1) - A(a1, b0) + A(a0, b0);
}

std::optional<Vec3> cube_direction(int width, double px, double py) {
  const int f = width / 3;
  const double tx = (px + 0.5) / f, ty = (py + 0.5) / f;
  // A position on a face's border may be on a blank square's border too: try both cells.
  for (double cx : {std::floor(tx), std::floor(tx) - 1})
    for (double cy : {std::floor(ty), std::floor(ty) - 1}) {
      if (tx < cx || tx > cx + 1 || ty < cy || ty > cy + 1) continue;
      const int face = face_at_cell(static_cast<int>(cx), static_cast<int>(cy));
      if (face < 0) continue;
      return normalized(face_direction(face, 2 * (tx - cx) - 1, 1 - 2 * (ty - cy)));
    }
  return std::nullopt;
}

}  // namespace

std::optional<Vec3> environment_pixel_direction(EnvironmentLayout layout, int width, int height, double px, double py) {
  if (!(px >= -0.5 && px <= width - 0.5 && py >= -0.5 && py <= height - 0.5)) return std::nullopt;
  switch (layout) {
    case EnvironmentLayout::AngularMap:
    case EnvironmentLayout::MirrorBall: {
      const Vec2 uv = pixel_to_disk(width, px, py);
      if (uv[0] * uv[0] + uv[1] * uv[1] > 1) return std::nullopt;
      return layout == EnvironmentLayout::AngularMap ? angular_direction(uv[0], uv[1]) : mirror_direction(uv[0], uv[1]);
    }
    case EnvironmentLayout::Equirectangular: {
      const double phi = 2 * kPi * ((px + 0.5) / width - 0.5), theta = kPi * (py + 0.5) / height;
      return Vec3{std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
    }
    case EnvironmentLayout::CubeCross: return cube_direction(width, px, py);
  }
  return std::nullopt;
}

Vec2 environment_direction_pixel(EnvironmentLayout layout, int width, int height, const Vec3& d) {
  switch (layout) {
    case EnvironmentLayout::AngularMap: {
      const Vec2 uv = angular_disk_point(d);
      return disk_to_pixel(width, uv[0], uv[1]);
    }
    case EnvironmentLayout::MirrorBall: {
      const Vec2 uv = mirror_disk_point(d);
      return disk_to_pixel(width, uv[0], uv[1]);
    }
    case EnvironmentLayout::Equirectangular: {
      const double phi = std::atan2(d[0], -d[2] + 0.0);  // + 0.0: the poles (-0) get phi = 0, not pi
      const double theta = std::atan2(std::hypot(d[0], d[2]), d[1]);
      return {(0.5 + phi / (2 * kPi)) * width - 0.5, theta / kPi * height - 0.5};
    }
    case EnvironmentLayout::CubeCross: {
      const int face = face_of(d), f = width / 3;
      const Vec2 ab = face_coordinates(face, d);
      return {kFaceCell[face][0] * f + (ab[0] + 1) * f / 2 - 0.5, kFaceCell[face][1] * f + (1 - ab[1]) * f / 2 - 0.5};
    }
  }
  return {0, 0};
}

double environment_texel_solid_angle(EnvironmentLayout layout, int width, int height, int x, int y) {
  if (x < 0 || y < 0 || x >= width || y >= height) return 0;
  switch (layout) {
    case EnvironmentLayout::AngularMap:
    case EnvironmentLayout::MirrorBall: {
      const double u0 = 2.0 * x / width - 1, u1 = 2.0 * (x + 1) / width - 1;
      const double v0 = 1 - 2.0 * (y + 1) / width, v1 = 1 - 2.0 * y / width;
      return layout == EnvironmentLayout::MirrorBall ? 4 * rect_disk_area(u0, u1, v0, v1)
                                               : angular_rect_solid_angle(u0, u1, v0, v1);
    }
    case EnvironmentLayout::Equirectangular: {
      const double theta0 = kPi * y / height, theta1 = kPi * (y + 1) / height;
      // cos theta0 - cos theta1 without cancellation
      return 2 * kPi / width * 2 * std::sin(0.5 * (theta0 + theta1)) * std::sin(0.5 * (theta1 - theta0));
    }
    case EnvironmentLayout::CubeCross: {
      const int f = width / 3;
      if (face_at_cell(x / f, y / f) < 0) return 0;
      const int i = x % f, j = y % f;
      return face_rect_solid_angle(2.0 * i / f - 1, 2.0 * (i + 1) / f - 1, 1 - 2.0 * (j + 1) / f, 1 - 2.0 * j / f);
    }
  }
  return 0;
}

bool environment_texel_valid(EnvironmentLayout layout, int width, int height, int x, int y) {
  if (x < 0 || y < 0 || x >= width || y >= height) return false;
  return environment_pixel_direction(layout, width, height, x, y).has_value();
}

void check_environment_dimensions(EnvironmentLayout layout, int width, int height, const std::string& name) {
  const std::string_view layout_name = environment_layout_name(layout);
  switch (layout) {
    case EnvironmentLayout::AngularMap:
    case EnvironmentLayout::MirrorBall:
      if (width >= 1 && width == height) return;
      throw AssetError(fmt::format("{}: layout \"{}\" needs a square image, but it is {} x {}", name, layout_name,
                                   width, height));
    case EnvironmentLayout::Equirectangular:
      if (height >= 1 && width == 2 * height) return;
      throw AssetError(fmt::format("{}: layout \"{}\" needs an image twice as wide as tall (2H x H), but it is {} x {}",
                                   name, layout_name, width, height));
    case EnvironmentLayout::CubeCross:
      if (width >= 3 && width % 3 == 0 && height == width / 3 * 4) return;
      throw AssetError(fmt::format("{}: layout \"{}\" needs 3 faces across and 4 down (3F x 4F, F >= 1), but it is "
                                   "{} x {}",
                                   name, layout_name, width, height));
  }
}

std::array<int, 2> cube_cross_face_cell(const Vec3& unit_dir_probe) { return kFaceCell[face_of(unit_dir_probe)]; }

}  // namespace arpipe
