// The ground catcher's ratio baked into a texture (see catcher_bake.h).
#include "render/shadow/catcher_bake.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/log.h"
#include "core/probe/brightest_components.h"
#include "render/gl/gl_error.h"
#include "render/layer_reuse.h"

namespace arpipe {
namespace {

void push(std::vector<float>& key, const Vec3& v) {
  for (double x : v) key.push_back(static_cast<float>(x));
}

void push(std::vector<float>& key, const ShadowLookup* lookup) {
  if (!lookup) {
    key.push_back(-1);
    return;
  }
  key.push_back(static_cast<float>(lookup->method));
  key.push_back(static_cast<float>(lookup->texture));
  key.insert(key.end(), lookup->clip_from_world.begin(), lookup->clip_from_world.end());
  key.insert(key.end(), lookup->depth_plane.begin(), lookup->depth_plane.end());
  key.insert(key.end(), {lookup->local ? 1.0f : 0.0f, lookup->near_m, lookup->range_m, lookup->texel, lookup->bias,
                         lookup->pcf_radius_texels, lookup->penumbra_texels_per_depth, lookup->max_search_texels,
                         lookup->vsm_min_variance, lookup->vsm_bleed_reduction});
}

// The catcher's square (world x, y min and max): it stands unrotated (shadow_receiver.h).
std::array<float, 4> square_of(const UploadedObject& catcher) {
  const Vec3 centre = catcher.T_world_object.translation();
  const double half = 0.5 * catcher.scale;
  return {static_cast<float>(centre[0] - half), static_cast<float>(centre[1] - half),
          static_cast<float>(centre[0] + half), static_cast<float>(centre[1] + half)};
}

// Rec. 709 luminance, the weights the catcher's shader takes.
double luminance(const Vec3& rgb) { return rec709_luminance(rgb[0], rgb[1], rgb[2]); }

// The ground catcher's ambient luminance: its normal is up, where the sky-above-the-ground model
// gives the whole constant ambient, and the SH's terms are those of Y_0, Y_1,0 and Y_2,0 (the
// shader's constants).
double ground_ambient_luminance(const Lighting& l) {
  return luminance(l.ambient) + 0.282095 * luminance(l.ambient_sh[0]) + 0.488603 * luminance(l.ambient_sh[2]) +
         0.315392 * 2.0 * luminance(l.ambient_sh[6]);
}

// The reach (CatcherBake::reach_of) of the bake in the bound framebuffer, read a band of rows at a
// time (its values as floats: the format every float colour buffer can be read in). The whole
// square if the read fails.
std::array<float, 4> read_reach(int size, const std::array<float, 4>& square) {
  constexpr int kBandRows = 64;
  std::vector<float> red(size_t(size) * size_t(size)), band(size_t(size) * kBandRows * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  for (int y = 0; y < size; y += kBandRows) {
    const int rows = std::min(kBandRows, size - y);
    glReadPixels(0, y, size, rows, GL_RGBA, GL_FLOAT, band.data());
    for (size_t i = 0; i < size_t(rows) * size_t(size); ++i) red[size_t(y) * size_t(size) + i] = band[4 * i];
  }
  if (glGetError() != GL_NO_ERROR) return square;
  return CatcherBake::reach_of(red, size, square);
}

}  // namespace

// The luminance of the direct light the catcher compares: for a light infinitely far, what falls
// on the ground (its normal is up), the only way its direction reaches the ratio (the shadow maps
// are compared apart); for a lamp, whose direction changes across the square, its colour's.
double ground_direct_luminance(const Lighting& l) {
  return l.local ? luminance(l.color) : luminance(l.color) * std::max(l.direction[2], 0.0);
}

bool same_catcher_light(const Lighting& a, const Lighting& b) {
  if (a.local != b.local || a.shadow != b.shadow || a.real_shadow != b.real_shadow) return false;
  // A lamp's place changes its cosine point by point; a far light's direction is left to its cosine
  // on the ground below (the sun turns 1e-4 rad in 1.4 s: compared by angle, it was baked anew every
  // 40 frames at 30 frames/s while the ratio moved by far less than 1/1000).
  if (a.local && (std::acos(std::clamp(dot(a.direction, b.direction), -1.0, 1.0)) > LayerReuse::kMaxLightTurnRad ||
                  norm(a.position - b.position) > LayerReuse::kMaxLightTurnRad))
    return false;
  const double direct_a = ground_direct_luminance(a), direct_b = ground_direct_luminance(b);
  const double ambient_a = ground_ambient_luminance(a), ambient_b = ground_ambient_luminance(b);
  const double tolerance = kCatcherBakeLightChange * std::max({std::abs(direct_a), std::abs(direct_b), std::abs(ambient_a),
                                                               std::abs(ambient_b)});
  if (std::abs(direct_a - direct_b) > tolerance || std::abs(ambient_a - ambient_b) > tolerance) return false;
  if (a.sky_occluders.empty() && b.sky_occluders.empty()) return true;
  // The sky occlusion weighs the ambient radiance by direction.
  double largest = 0;
  for (size_t i = 0; i < a.radiance_sh.size(); ++i)
    largest = std::max({largest, std::abs(luminance(a.radiance_sh[i])), std::abs(luminance(b.radiance_sh[i]))});
  for (size_t i = 0; i < a.radiance_sh.size(); ++i)
    if (std::abs(luminance(a.radiance_sh[i]) - luminance(b.radiance_sh[i])) > kCatcherBakeLightChange * largest) return false;
  return true;
}

std::array<float, 4> CatcherBake::reach_of(std::span<const float> red, int size, const std::array<float, 4>& square) {
  int x0 = size, x1 = -1, y0 = size, y1 = -1;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (red[size_t(y) * size_t(size) + size_t(x)] != 0.0f) {
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
  if (x1 < 0) return {square[2], square[3], square[0], square[1]};  // nothing drawn anywhere
  // A bilinear lookup at texture coordinate u reads the texels whose centres lie within one texel
  // of u: zero beyond one texel of the outermost nonzero centre. One texel more covers the
  // rounding of the lookup's coordinate, which the catcher computes from its pixel's ground point.
  const auto edge = [&](int texel, float margin, int axis) {
    const double side = double(square[size_t(axis + 2)]) - double(square[size_t(axis)]);
    const double at = double(square[size_t(axis)]) + (double(texel) + 0.5 + margin) / double(size) * side;
    return float(std::clamp(at, double(square[size_t(axis)]), double(square[size_t(axis + 2)])));
  };
  return {edge(x0, -2, 0), edge(y0, -2, 1), edge(x1, 2, 0), edge(y1, 2, 1)};
}

double catcher_texels_needed(const UploadedObject& catcher, std::span<const SE3> T_cam_world, double focal_px) {
  const Vec3 centre = catcher.T_world_object.translation();
  const double half = 0.5 * catcher.scale;
  double nearest = INFINITY;
  for (const SE3& pose : T_cam_world) {
    const Vec3 eye = pose.inverse().translation();
    const double dx = std::max(std::abs(eye[0] - centre[0]) - half, 0.0);
    const double dy = std::max(std::abs(eye[1] - centre[1]) - half, 0.0);
    nearest = std::min(nearest, std::sqrt(dx * dx + dy * dy + (eye[2] - centre[2]) * (eye[2] - centre[2])));
  }
  return nearest > 0 ? kCatcherBakeTexelsPerPixel * catcher.scale * focal_px / nearest : INFINITY;
}

CatcherBake::Key CatcherBake::key_of(const Lighting& lighting, const UploadedObject& catcher) const {
  Key key;
  key.valid = true;
  key.light = lighting;
  std::vector<float>& exact = key.exact;
  exact.reserve(80);
  for (const std::array<float, 4>& sphere : lighting.sky_occluders) exact.insert(exact.end(), sphere.begin(), sphere.end());
  exact.insert(exact.end(), lighting.catcher_patch.begin(), lighting.catcher_patch.end());
  push(exact, lighting.shadow);
  push(exact, lighting.real_shadow);
  const std::array<float, 4> square = square_of(catcher);
  exact.insert(exact.end(), square.begin(), square.end());
  push(exact, catcher.T_world_object.translation());
  exact.push_back(static_cast<float>(shadow_generation_));
  return key;
}

bool CatcherBake::Key::matches(const Key& other) const {
  return valid && other.valid && exact == other.exact && same_catcher_light(light, other.light);
}

Lighting::BakedCatcher CatcherBake::for_frame(ObjectRenderer& renderer, const Lighting& lighting,
                                              const UploadedObject& catcher, double texels_needed, bool shadow_redrawn) {
  if (shadow_redrawn) ++shadow_generation_;
  Key key = key_of(lighting, catcher);
  const bool changed = !key.matches(last_key_);
  const bool churning = changed && changed_last_frame_;
  changed_last_frame_ = changed;
  last_key_ = key;
  if (!float_target_ || !lighting.shadow || !(texels_needed <= kMaxCatcherBakeTexels)) return {};
  if (key.matches(baked_key_) && texels_needed <= size_) return {target_.texture(), square_of(catcher), reach_};
  if (churning) return {};

  const int size = std::clamp(static_cast<int>(std::bit_ceil(static_cast<unsigned>(std::ceil(texels_needed)))),
                              kMinCatcherBakeTexels, kMaxCatcherBakeTexels);
  // One channel: the catcher draws alpha alone, and a quarter of the memory is a quarter of what
  // each frame's lookups bring through the caches.
  target_.ensure(GL_R16F, size, size, false);
  glBindTexture(GL_TEXTURE_2D, target_.texture());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D, 0);
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, target_.framebuffer());
  glViewport(0, 0, size, size);
  const std::array<float, 4> square = square_of(catcher);
  renderer.bake_ground_catcher(lighting, catcher, square);
  reach_ = read_reach(size, square);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("baking the ground catcher");
  size_ = size;
  baked_key_ = std::move(key);
  ++bakes_;
  log::debug("render: ground catcher baked at {} x {} texels over {:.3f} m ({} texels needed; bake {})", size, size,
             catcher.scale, texels_needed, bakes_);
  return {target_.texture(), square, reach_};
}

}  // namespace arpipe
