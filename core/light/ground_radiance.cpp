// The ground's brightness around the anchor (see ground_radiance.h).
#include "core/light/ground_radiance.h"
#include "core/geometry/math_constants.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/sh/sh_irradiance.h"

namespace arpipe {
namespace {

// A ring far enough out to miss the anchor tag and near enough to be the ground the objects
// stand on; the median copes with real objects and shadows on part of it.
constexpr double kRingInner = 0.09, kRingOuter = 0.25;
constexpr int kRingSamples = 96;

}  // namespace

std::optional<Vec3> GroundRadiance::measure(const Frame& frame, const CameraModel& camera, const SE3& T_cam_world,
                                            const CameraResponse& response) {
  pixels_.clear();
  for (int i = 0; i < kRingSamples; ++i) {
    const double angle = 2 * kPi * i / kRingSamples;
    const double radius = kRingInner + (kRingOuter - kRingInner) * ((i * 7) % kRingSamples) / double(kRingSamples);
    const Vec3 cam = T_cam_world * Vec3{radius * std::cos(angle), radius * std::sin(angle), 0};
    if (cam[2] <= 0) continue;
    if (const std::optional<Vec2> q = camera.project(cam))
      if ((*q)[0] >= 0 && (*q)[1] >= 0 && (*q)[0] <= camera.width() - 1 && (*q)[1] <= camera.height() - 1)
        if (const int x = int(std::lround((*q)[0])), y = int(std::lround((*q)[1])); x < frame.width && y < frame.height)
          pixels_.push_back({x, y});
  }
  if (int(pixels_.size()) < kRingSamples / 4) return std::nullopt;
  // The ring's pixels alone: a rectangle around it would decode most of the frame.
  if (!decode_linear_pixels(frame, pixels_, response)) return std::nullopt;
  std::vector<std::array<float, 3>> values;
  for (const LinearPixel& p : pixels_)
    if (!p.clipped) values.push_back({p.rgb[0], p.rgb[1], p.rgb[2]});
  if (int(values.size()) < kRingSamples / 4) return std::nullopt;
  Vec3 median{};
  for (size_t c = 0; c < 3; ++c) {
    std::vector<float> channel;
    for (const auto& v : values) channel.push_back(v[c]);
    std::nth_element(channel.begin(), channel.begin() + ptrdiff_t(channel.size() / 2), channel.end());
    median[c] = channel[channel.size() / 2];
  }
  return median;
}

bool light_from_ground(DirectionalLight& light, const ShRgb9& ambient_sh, const Vec3& ground_radiance,
                       const Vec3& ground_albedo) {
  const double cos_ground = light.direction_world[2];
  if (cos_ground < 0.1) return false;
  // Irradiance on an upward surface from the ambient SH (only the zonal terms A_l L_l0 Y_l0(up) are
  // not zero there).
  const Vec3 ambient = sh_irradiance(from_sh9(ambient_sh), {0, 0, 1});
  Vec3 solved{};
  for (size_t c = 0; c < 3; ++c)
    solved[c] = std::max(0.0, (kPi * ground_radiance[c] / ground_albedo[c] - ambient[c]) / cos_ground);
  const auto luminance = [](const Vec3& v) { return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; };
  if (luminance(solved) <= luminance(light.irradiance)) return false;
  light.irradiance = solved;
  return true;
}

}  // namespace arpipe
