#include "capture/panorama/panorama_view.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

namespace arpipe {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
// Taps across at most, per level: past that, the next level.
constexpr int kMaxTapsAcross = 8;
constexpr int kMaxBands = 16;  // threads a frame at most
// A pixel may span this many texels down before the next level serves it: bilinear taps then
// still reach every texel under it.
constexpr float kMostTexelsDown = 1.5f;

std::array<float, 3> rotate(const std::array<std::array<float, 3>, 3>& R, const std::array<float, 4>& v) {
  return {R[0][0] * v[0] + R[0][1] * v[1] + R[0][2] * v[2], R[1][0] * v[0] + R[1][1] * v[1] + R[1][2] * v[2],
          R[2][0] * v[0] + R[2][1] * v[1] + R[2][2] * v[2]};
}

std::array<std::array<float, 3>, 3> to_float(const Mat3& m) {
  std::array<std::array<float, 3>, 3> out{};
  for (size_t r = 0; r < 3; ++r)
    for (size_t c = 0; c < 3; ++c) out[r][c] = static_cast<float>(m[r][c]);
  return out;
}

double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(norm(cross(a, b)), dot(a, b)); }

}  // namespace

Mat3 panorama_view_rotation(double yaw_rad, double pitch_rad, double roll_rad) {
  const double cy = std::cos(yaw_rad), sy = std::sin(yaw_rad), cp = std::cos(pitch_rad), sp = std::sin(pitch_rad);
  const Vec3 forward{cp * sy, sp, -cp * cy};
  const Vec3 level_right{cy, 0, sy};
  const Vec3 level_up = cross(level_right, forward);
  // The roll turns right towards down (the camera's y) about forward.
  const double cr = std::cos(roll_rad), sr = std::sin(roll_rad);
  const Vec3 right = cr * level_right - sr * level_up;
  const Vec3 up = cross(right, forward);
  return {{{right[0], -up[0], forward[0]}, {right[1], -up[1], forward[1]}, {right[2], -up[2], forward[2]}}};
}

namespace {

// atan2 in single precision, a few times cheaper than libm's: Cephes' atanf (the argument reduced to
// |x| <= tan(pi / 8) and a degree-9 odd polynomial, about 1e-7 rad), then the quadrant. atan2(0, 0)
// is 0 and atan2(+-0, negative) is pi, as the lookup needs at the poles.
[[gnu::always_inline]] inline float fast_atan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const bool swap = ay > ax;  // reduce to t = small / large in [0, 1]
  const float t = ax == 0 && ay == 0 ? 0.0f : (swap ? ax / ay : ay / ax);
  float base = 0, u = t;
  if (t > 0.41421356f) {  // tan(pi / 8)
    base = kPi / 4;
    u = (t - 1) / (t + 1);
  }
  const float z = u * u;
  float a = base + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * u + u);
  if (swap) a = kPi / 2 - a;
  if (x < 0) a = kPi - a;
  return std::signbit(y) ? -a : a;
}

// Pixel position (texel centres at integers) of a panorama-frame direction in an equirectangular
// image of width x height: the float form of environment_direction_pixel.
[[gnu::always_inline]] inline std::array<float, 2> pixel_of(const std::array<float, 3>& d, int width, int height) {
  const float longitude = fast_atan2(d[0], -d[2] + 0.0f);  // + 0.0f: the poles (-0) get 0, not pi
  const float from_up = fast_atan2(std::sqrt(d[0] * d[0] + d[2] * d[2]), d[1]);
  return {(0.5f + longitude / (2 * kPi)) * float(width) - 0.5f, from_up / kPi * float(height) - 0.5f};
}

// Where a pixel's ray looks and how it is sampled there: its level-0 position, the pyramid level
// where its footprint spans at most kMostTexelsDown texels down and kMaxTapsAcross across (texels
// narrow as cos(latitude)), that footprint across at the level, and the taps spread over it.
struct RayLookup {
  std::array<float, 2> position;
  int level = 0;
  float wide_scaled = 0;
  int taps = 1;
};
[[gnu::always_inline]] inline RayLookup look_up(const std::array<std::array<float, 3>, 3>& R, const std::array<float, 4>& ray,
                                                const EquirectImage& panorama, float texel_angle, int last_level) {
  const std::array<float, 3> d = rotate(R, ray);
  RayLookup out;
  out.position = pixel_of(d, panorama.width(), panorama.height());
  // The pixel's footprint in level-0 texels: down (ray[3], its angle to its neighbours), and across.
  const float tall = ray[3] / texel_angle;
  const float wide = tall / std::max(std::sqrt(d[0] * d[0] + d[2] * d[2]), 1e-6f);
  while (out.level < last_level &&
         (tall > kMostTexelsDown * float(1 << out.level) || wide > float(kMaxTapsAcross << out.level)))
    ++out.level;
  out.wide_scaled = wide / float(1 << out.level);
  out.taps = std::clamp(static_cast<int>(std::ceil(out.wide_scaled)), 1, kMaxTapsAcross);
  return out;
}

// The pixel's colour: the level-0 position (u0, v0) at `level`, one bilinear tap, or `taps` spread
// evenly across its footprint and averaged.
[[gnu::always_inline]] inline void sample_footprint(const EquirectImage& panorama, float u0, float v0, int level,
                                                    float wide_scaled, int taps, uint8_t out[3]) {
  const float scale = 1.0f / float(1 << level);
  const float u = (u0 + 0.5f) * scale - 0.5f, v = (v0 + 0.5f) * scale - 0.5f;
  if (taps == 1) {
    panorama.sample(level, u, v, out);
    return;
  }
  const float step = wide_scaled / float(taps);
  float sum[3] = {0, 0, 0};
  for (int t = 0; t < taps; ++t) {
    uint8_t s[3];
    panorama.sample(level, u + (float(t) + 0.5f) * step - 0.5f * wide_scaled, v, s);
    for (int c = 0; c < 3; ++c) sum[c] += float(s[c]);
  }
  for (int c = 0; c < 3; ++c) out[c] = static_cast<uint8_t>(sum[c] / float(taps) + 0.5f);
}

}  // namespace

PanoramaView::PanoramaView(std::shared_ptr<const CameraModel> camera) : camera_(std::move(camera)) {
  const int width = camera_->width(), height = camera_->height();
  std::vector<Vec2> pixels;
  pixels.reserve(size_t(width) * size_t(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) pixels.push_back({double(x), double(y)});
  std::vector<Vec3> rays;
  camera_->unproject(pixels, rays);
  const auto ray = [&](int x, int y) -> const Vec3& { return rays[size_t(y) * size_t(width) + size_t(x)]; };
  for (size_t i = 0; i < rays.size(); ++i)
    if (!std::isfinite(rays[i][0]) || !std::isfinite(rays[i][1]) || !std::isfinite(rays[i][2]))
      throw CameraModelError(fmt::format("the panorama's view camera ({}) cannot unproject pixel ({}, {})",
                                         camera_->lensmodel(), i % size_t(width), i / size_t(width)));
  rays_.resize(rays.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec3 r = normalized(ray(x, y));
      const double across = angle_between(r, ray(x + 1 < width ? x + 1 : x - 1, y));
      const double down = angle_between(r, ray(x, y + 1 < height ? y + 1 : y - 1));
      rays_[size_t(y) * size_t(width) + size_t(x)] = {float(r[0]), float(r[1]), float(r[2]), float(std::max(across, down))};
      widest_footprint_rad_ = std::max(widest_footprint_rad_, std::max(across, down));
      widest_ray_rad_ = std::max(widest_ray_rad_, std::acos(std::clamp(r[2], -1.0, 1.0)));
    }
}

int PanoramaView::levels_needed(const EquirectImage& panorama, const Mat3& R_pano_cam) const {
  // As render_rows chooses a level, with the largest footprint and the smallest cos(latitude) any
  // pixel can have: every ray is within widest_ray_rad_ of the optical axis, so no ray comes nearer
  // a pole (+-y) than the axis's angle from it less that. 1 % over: render_rows works in floats.
  const double texel_angle = std::numbers::pi / panorama.height();
  const double tall = 1.01 * widest_footprint_rad_ / texel_angle;
  const double axis_from_pole = std::acos(std::min(1.0, std::abs(R_pano_cam[1][2])));
  const double nearest_to_pole = std::max(0.0, axis_from_pole - widest_ray_rad_);
  const double wide = tall / std::max(std::sin(nearest_to_pole), 1e-6);
  int level = 0;
  while (level + 1 < panorama.levels() && (tall > kMostTexelsDown * double(1 << level) || wide > double(kMaxTapsAcross << level)))
    ++level;
  return level + 1;
}

PanoramaView::Turn PanoramaView::split_turn(const Mat3& R_pano_cam, int panorama_width) {
  // The forward axis's longitude (as pixel_of measures it) is the yaw; Ry(yaw) takes it to 0.
  const double yaw = std::atan2(R_pano_cam[0][2], -R_pano_cam[2][2]);
  const double c = std::cos(yaw), s = std::sin(yaw);
  const Mat3 Ry{{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};  // longitude(Ry d) = longitude(d) - yaw
  Turn turn;
  turn.rest = mat_mul(Ry, R_pano_cam);
  turn.yaw_texels = yaw / (2 * std::numbers::pi) * panorama_width;
  return turn;
}

bool PanoramaView::table_matches(const EquirectImage& panorama, const Mat3& rest) const {
  if (table_.width != panorama.width() || table_.height != panorama.height()) return false;
  for (size_t r = 0; r < 3; ++r)
    for (size_t c = 0; c < 3; ++c)
      if (std::abs(table_.rest[r][c] - rest[r][c]) > 1e-12) return false;
  return true;
}

bool PanoramaView::uses_yaw_table(const EquirectImage& panorama, const Mat3& R_pano_cam) const {
  return !table_.entries.empty() && table_.levels <= panorama.built_levels() &&
         table_matches(panorama, split_turn(R_pano_cam, panorama.width()).rest);
}

void PanoramaView::lookup_positions(const EquirectImage& panorama, const Mat3& R_pano_cam,
                                    std::vector<std::array<float, 2>>& out) const {
  out.resize(rays_.size());
  if (uses_yaw_table(panorama, R_pano_cam)) {
    const float shift = float(split_turn(R_pano_cam, panorama.width()).yaw_texels);
    const float width = float(panorama.width());
    for (size_t i = 0; i < rays_.size(); ++i) {
      float u = table_.entries[i].u + shift;
      u -= width * std::floor((u + 0.5f) / width);
      out[i] = {u, table_.entries[i].v};
    }
    return;
  }
  const auto R = to_float(R_pano_cam);
  for (size_t i = 0; i < rays_.size(); ++i) out[i] = pixel_of(rotate(R, rays_[i]), panorama.width(), panorama.height());
}

void PanoramaView::render(EquirectImage& panorama, const Mat3& R_pano_cam, uint8_t* rgb, size_t stride) const {
  const int levels = levels_needed(panorama, R_pano_cam);
  panorama.build_levels(levels);
  const Turn turn = split_turn(R_pano_cam, panorama.width());
  // Bands of rows, one a core: every pixel is looked up on its own, so the result is the same.
  const int height = camera_->height();
  const int bands = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, std::min(kMaxBands, height));
  const auto in_bands = [&](const auto& rows) {
    std::vector<std::jthread> helpers;
    for (int b = 1; b < bands; ++b) helpers.emplace_back([&, b] { rows(height * b / bands, height * (b + 1) / bands); });
    rows(0, height / bands);
  };
  if (!table_matches(panorama, turn.rest)) {  // a new tilt: looked up directly; the table waits for a second frame
    table_ = YawTable{turn.rest, panorama.width(), panorama.height(), 0, {}};
    in_bands([&](int first, int end) { render_rows(panorama, R_pano_cam, rgb, stride, first, end); });
    return;
  }
  if (table_.entries.empty() || table_.levels < levels) {
    table_.entries.resize(rays_.size());
    table_.levels = panorama.built_levels();
    in_bands([&](int first, int end) { make_table_rows(panorama, first, end); });
  }
  in_bands([&](int first, int end) { render_rows_from_table(panorama, turn.yaw_texels, rgb, stride, first, end); });
}

void PanoramaView::make_table_rows(const EquirectImage& panorama, int first_row, int end_row) const {
  const auto R = to_float(table_.rest);
  const int width = camera_->width();
  const float texel_angle = kPi / float(panorama.height());
  for (int y = first_row; y < end_row; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * size_t(width) + size_t(x);
      const RayLookup l = look_up(R, rays_[i], panorama, texel_angle, table_.levels - 1);
      table_.entries[i] = {l.position[0], l.position[1], l.wide_scaled, static_cast<uint8_t>(l.level),
                           static_cast<uint8_t>(l.taps)};
    }
}

void PanoramaView::render_rows_from_table(const EquirectImage& panorama, double yaw_texels, uint8_t* rgb, size_t stride,
                                          int first_row, int end_row) const {
  const int width = camera_->width();
  const float panorama_width = float(panorama.width());
  const float shift = float(yaw_texels);
  for (int y = first_row; y < end_row; ++y) {
    uint8_t* row = rgb + size_t(y) * stride;
    for (int x = 0; x < width; ++x) {
      const TableEntry& e = table_.entries[size_t(y) * size_t(width) + size_t(x)];
      float u0 = e.u + shift;
      u0 -= panorama_width * std::floor((u0 + 0.5f) / panorama_width);
      sample_footprint(panorama, u0, e.v, e.level, e.wide_scaled, e.taps, row + 3 * size_t(x));
    }
  }
}

void PanoramaView::render_rows(const EquirectImage& panorama, const Mat3& R_pano_cam, uint8_t* rgb, size_t stride,
                               int first_row, int end_row) const {
  const auto R = to_float(R_pano_cam);
  const int width = camera_->width();
  const float texel_angle = kPi / float(panorama.height());  // a level-0 texel's height (and width at the equator)
  const int last_level = panorama.built_levels() - 1;  // levels_needed: no pixel asks for more
  for (int y = first_row; y < end_row; ++y) {
    uint8_t* row = rgb + size_t(y) * stride;
    for (int x = 0; x < width; ++x) {
      const RayLookup l = look_up(R, rays_[size_t(y) * size_t(width) + size_t(x)], panorama, texel_angle, last_level);
      sample_footprint(panorama, l.position[0], l.position[1], l.level, l.wide_scaled, l.taps, row + 3 * size_t(x));
    }
  }
}

}  // namespace arpipe
