#include "core/light/light_hold.h"

#include <algorithm>
#include <cmath>

namespace arpipe {
namespace {

double angle_between(const Vec3& a, const Vec3& b) {
  const double na = norm(a), nb = norm(b);
  if (!(na > 0) || !(nb > 0)) return INFINITY;
  return std::acos(std::clamp(dot(a, b) / (na * nb), -1.0, 1.0));
}

double sh_norm(const ShRgb9& sh) {
  double sum = 0;
  for (const Vec3& c : sh) sum += dot(c, c);
  return std::sqrt(sum);
}

}  // namespace

bool LightHold::within_band(const LightEstimate& a, const LightEstimate& b) const {
  if (a.lights.size() != b.lights.size() || a.scene_linear != b.scene_linear) return false;
  for (size_t i = 0; i < a.lights.size(); ++i) {
    const DirectionalLight &la = a.lights[i], &lb = b.lights[i];
    if (la.local != lb.local) return false;
    const double turned = la.local ? angle_between(la.position_world - centre_, lb.position_world - centre_)
                                   : angle_between(la.direction_world, lb.direction_world);
    if (!(turned <= band_.direction_rad)) return false;
    // The source's size sets the penumbra's width: relative, like a strength.
    if (!(std::abs(la.angular_diameter_rad - lb.angular_diameter_rad) <= band_.relative_change * la.angular_diameter_rad))
      return false;
    if (!(norm(la.irradiance - lb.irradiance) <= band_.relative_change * norm(la.irradiance))) return false;
  }
  ShRgb9 difference{};
  for (size_t i = 0; i < difference.size(); ++i) difference[i] = a.ambient_sh[i] - b.ambient_sh[i];
  return sh_norm(difference) <= band_.relative_change * sh_norm(a.ambient_sh);
}

LightEstimate LightHold::apply(const LightEstimate& measured) {
  if (!band_.enabled()) return measured;
  if (measured.state == LightState::Held && kept_) {
    LightEstimate out = *kept_;
    out.state = measured.state;
    out.note = measured.note;
    out.frames_since_measured = measured.frames_since_measured;
    out.confidence = measured.confidence;
    return out;
  }
  if (measured.state != LightState::Estimated) {
    kept_.reset();
    return measured;
  }
  if (kept_ && within_band(*kept_, measured)) {
    ++kept_->frames_kept;
    return *kept_;
  }
  kept_ = measured;
  kept_->frames_kept = 0;
  return *kept_;
}

}  // namespace arpipe
