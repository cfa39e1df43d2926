// HdrEnvironment: lookups go world -> probe frame (R^T), then through the layout's inverse map to
// a continuous pixel position, then bilinear over texels that the layout says hold data.
#include "core/environment/hdr_environment.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/image/hdr_file.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

double determinant(const Mat3& m) {
  return dot(Vec3{m[0][0], m[0][1], m[0][2]}, cross(Vec3{m[1][0], m[1][1], m[1][2]}, Vec3{m[2][0], m[2][1], m[2][2]}));
}

bool is_rotation(const Mat3& m) {
  const Mat3 product = mat_mul(transpose(m), m);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!(std::abs(product[i][j] - (i == j ? 1.0 : 0.0)) < 1e-6)) return false;
  return determinant(m) > 0;
}

}  // namespace

Mat3 default_world_from_probe(double yaw_rad) {
  // Columns: probe +x -> world +x, probe +y -> world +z, probe +z -> world -y (forward -z -> +y).
  const Mat3 upright = {{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}};
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const Mat3 yaw = {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
  return mat_mul(yaw, upright);
}

HdrEnvironment::HdrEnvironment(HdrImage image, EnvironmentLayout layout, const Mat3& R_world_probe, double scale,
                               std::string name)
    : image_(std::move(image)), layout_(layout), R_world_probe_(R_world_probe), scale_(scale), name_(std::move(name)) {
  check_environment_dimensions(layout_, image_.width, image_.height, name_);
  check_hdr_texels(image_, name_);
  if (!(std::isfinite(scale_) && scale_ >= 0))
    throw AssetError(fmt::format("{}: radiance scale {} is not a finite number >= 0", name_, scale_));
  if (!is_rotation(R_world_probe_))
    throw AssetError(fmt::format("{}: the probe's orientation R_world_probe is not a rotation matrix", name_));
}

HdrEnvironment HdrEnvironment::load(const std::filesystem::path& file, EnvironmentLayout layout, const Mat3& R_world_probe,
                                    double scale) {
  return HdrEnvironment(read_hdr_image(file), layout, R_world_probe, scale, file.string());
}

Vec3 HdrEnvironment::texel(int x, int y) const { return scale_ * image_.at(x, y); }

Vec3 HdrEnvironment::disk_texel(int x, int y) const {
  const int n = image_.width;
  x = std::clamp(x, 0, n - 1);
  y = std::clamp(y, 0, n - 1);
  if (environment_texel_valid(layout_, n, n, x, y)) return texel(x, y);
  // Grow the search square until it holds a valid texel, then search the square that contains
  // every texel at most that far away, so the Euclidean nearest one is found.
  const auto nearest_within = [&](int radius, double& best) {
    int bx = -1, by = -1;
    for (int j = std::max(0, y - radius); j <= std::min(n - 1, y + radius); ++j)
      for (int i = std::max(0, x - radius); i <= std::min(n - 1, x + radius); ++i) {
        const double distance = std::hypot(i - x, j - y);
        if (distance < best && environment_texel_valid(layout_, n, n, i, j)) {
          best = distance;
          bx = i;
          by = j;
        }
      }
    return std::pair{bx, by};
  };
  for (int radius = 1; radius < 2 * n; radius *= 2) {
    double best = 1e300;
    if (nearest_within(radius, best).first < 0) continue;
    const int exact_radius = static_cast<int>(std::ceil(best));
    best = 1e300;
    const auto [bx, by] = nearest_within(exact_radius, best);
    return texel(bx, by);
  }
  return texel(n / 2, n / 2);  // not reached: the centre texel is always valid
}

Vec3 HdrEnvironment::radiance(const Vec3& unit_dir_world) const {
  const Vec3 d = normalized(mat_mul(transpose(R_world_probe_), unit_dir_world));
  const int w = image_.width, h = image_.height;
  const Vec2 p = environment_direction_pixel(layout_, w, h, d);
  const int x0 = static_cast<int>(std::floor(p[0])), y0 = static_cast<int>(std::floor(p[1]));
  const double fx = p[0] - x0, fy = p[1] - y0;
  std::array<Vec3, 4> taps{};  // (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1)
  switch (layout_) {
    case EnvironmentLayout::Equirectangular: {
      const auto wrap = [w](int x) { return ((x % w) + w) % w; };
      const int ya = std::clamp(y0, 0, h - 1), yb = std::clamp(y0 + 1, 0, h - 1);
      taps = {texel(wrap(x0), ya), texel(wrap(x0 + 1), ya), texel(wrap(x0), yb), texel(wrap(x0 + 1), yb)};
      break;
    }
    case EnvironmentLayout::CubeCross: {
      const int f = w / 3;
      const std::array<int, 2> cell = cube_cross_face_cell(d);
      const int left = cell[0] * f, top = cell[1] * f;
      const auto cx = [&](int x) { return std::clamp(x, left, left + f - 1); };
      const auto cy = [&](int y) { return std::clamp(y, top, top + f - 1); };
      taps = {texel(cx(x0), cy(y0)), texel(cx(x0 + 1), cy(y0)), texel(cx(x0), cy(y0 + 1)),
              texel(cx(x0 + 1), cy(y0 + 1))};
      break;
    }
    case EnvironmentLayout::AngularMap:
    case EnvironmentLayout::MirrorBall:
      taps = {disk_texel(x0, y0), disk_texel(x0 + 1, y0), disk_texel(x0, y0 + 1), disk_texel(x0 + 1, y0 + 1)};
      break;
  }
  return (1 - fy) * ((1 - fx) * taps[0] + fx * taps[1]) + fy * ((1 - fx) * taps[2] + fx * taps[3]);
}

void HdrEnvironment::for_each_texel(
    const std::function<void(const Vec3& unit_dir_world, const Vec3& radiance, double solid_angle)>& visit) const {
  const int w = image_.width, h = image_.height;
  const bool disk = layout_ == EnvironmentLayout::AngularMap || layout_ == EnvironmentLayout::MirrorBall;
  const Vec3 rim = layout_ == EnvironmentLayout::AngularMap ? Vec3{0, 0, 1} : Vec3{0, 0, -1};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double solid_angle = environment_texel_solid_angle(layout_, w, h, x, y);
      if (solid_angle <= 0) continue;
      const std::optional<Vec3> d = environment_pixel_direction(layout_, w, h, x, y);
      if (d) visit(mat_mul(R_world_probe_, *d), texel(x, y), solid_angle);
      else if (disk) visit(mat_mul(R_world_probe_, rim), disk_texel(x, y), solid_angle);
    }
}

}  // namespace arpipe
