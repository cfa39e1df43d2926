// The virtual objects that no shadow can reach this frame (see unshadowed_objects.h).
#include "render/shadow/unshadowed_objects.h"

#include <algorithm>
#include <cmath>

namespace arpipe {
namespace {

// A caster's box in the light's frame: x, y across the light, z towards it.
struct LightBox {
  Vec3 min{INFINITY, INFINITY, INFINITY};
  Vec3 max{-INFINITY, -INFINITY, -INFINITY};
};

LightBox light_box(const UploadedObject& object, const Mat3& R_light_world) {
  LightBox box;
  for (const Vec3& corner : box_corners(object.bounds)) {
    const Vec3 p = mat_mul(R_light_world, object.T_world_object * corner);
    for (size_t k = 0; k < 3; ++k) box.min[k] = std::min(box.min[k], p[k]), box.max[k] = std::max(box.max[k], p[k]);
  }
  return box;
}

// Whether `other` can darken any point of `target` through a lookup that reads reach_m around it.
bool may_shadow(const LightBox& other, const LightBox& target, double reach_m) {
  if (other.max[2] <= target.min[2]) return false;  // wholly farther from the light
  for (size_t k = 0; k < 2; ++k)
    if (other.max[k] < target.min[k] - reach_m || other.min[k] > target.max[k] + reach_m) return false;
  return true;
}

}  // namespace

double shadow_lookup_reach_m(const ShadowLookup& lookup, const ShadowFrustum& frustum) {
  // PCSS searches and filters over at most the penumbra a blocker at the light's end of the depth
  // range would cast (a directional light's is per_depth texels: depths lie in [0, 1]), and never
  // beyond max_search_texels.
  double pcss = lookup.max_search_texels;
  if (!lookup.local) pcss = std::min(pcss, std::max(double(lookup.penumbra_texels_per_depth), 1.0));
  const double texels = 1.0 + std::max(lookup.method == ShadowMethod::Pcss ? pcss : 0.0,
                                       lookup.method == ShadowMethod::Pcf ? double(lookup.pcf_radius_texels) : 0.0);
  return texels * double(lookup.texel) * frustum.width_m();
}

std::vector<const UploadedObject*> unshadowed_objects(std::span<const UploadedObject* const> casters,
                                                      const ShadowFrustum& frustum, ShadowMethod method, double reach_m) {
  std::vector<const UploadedObject*> out;
  if (method == ShadowMethod::Off || is_variance_method(method)) return out;
  std::vector<LightBox> boxes;
  if (!frustum.local) {
    boxes.reserve(casters.size());
    for (const UploadedObject* caster : casters) boxes.push_back(light_box(*caster, frustum.R_light_world));
  }
  for (size_t i = 0; i < casters.size(); ++i) {
    const UploadedObject& object = *casters[i];
    if (object.proxy || object.shadow_catcher || !object.closed_convex) continue;
    bool alone = true;
    for (size_t j = 0; j < casters.size() && alone; ++j)
      if (j != i) alone = !frustum.local && !may_shadow(boxes[j], boxes[i], reach_m);
    if (alone) out.push_back(&object);
  }
  return out;
}

}  // namespace arpipe
