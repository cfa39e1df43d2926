// The virtual objects that no shadow can reach this frame. A closed convex object cannot shadow
// itself where it faces the light (its back faces get no direct light anyway), so when no other
// caster stands between it and the light, within the filter's reach, every shadow lookup on it
// returns 1. The object renderer then draws it without the lookups: on a software rasteriser the
// lookups cost as much as the rest of its shading.
#pragma once

#include <span>
#include <vector>

#include "render/shadow/shadow_frustum.h"
#include "render/shadow/shadow_map.h"
#include "render/uploaded_objects.h"

namespace arpipe {

// casters: everything drawn into the shadow map (virtual objects and proxies that cast), at the
// poses the map was drawn with. A caster qualifies when it is a virtual object (not a proxy) whose
// mesh is closed and convex, and either it is the only caster, or the light is directional and
// every other caster's box, seen along the light, misses its box grown by the lookup's reach
// (reach_m), or lies wholly farther from the light. Variance methods blend the ground into the
// map, so nothing qualifies under them.
std::vector<const UploadedObject*> unshadowed_objects(std::span<const UploadedObject* const> casters,
                                                      const ShadowFrustum& frustum, ShadowMethod method, double reach_m);

// How far from a point a lookup of this map reads (the PCSS search or the PCF kernel, a texel
// more), in metres across the map, along either of its axes (a square window).
double shadow_lookup_reach_m(const ShadowLookup& lookup, const ShadowFrustum& frustum);

}  // namespace arpipe
