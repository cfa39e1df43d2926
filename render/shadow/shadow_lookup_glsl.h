// The GLSL that reads a shadow map (shadow_map.h) in a shading pass: one function per method,
// `float shadow_visibility(vec3 world)`, 1 lit and 0 in shadow, and the uniforms it reads.
#pragma once

#include <string>

#include "render/gl/gl_program.h"
#include "render/shadow/shadow_map.h"

namespace arpipe {

// Method Off gives a function that returns 1 and declares no uniforms.
std::string shadow_lookup_glsl(ShadowMethod method);
// Binds lookup.texture to texture_unit; the program must be in use.
void set_shadow_lookup_uniforms(const GlProgram& program, const ShadowLookup& lookup, int texture_unit);

// The visibility of the real casters alone (proxies with the cast_shadows role), from a depth map
// of them (a ShadowMapPass with method pcf): `float real_shadow_visibility(vec3 world)`, a 3 x 3
// percentage-closer test; 1 when no map is bound. The shadow catcher divides by it, so that a real
// shadow already in the camera's picture is not darkened a second time (differential rendering).
std::string real_shadow_lookup_glsl();
// lookup nullptr: no real casters (the function returns 1). Binds the map to texture_unit.
void set_real_shadow_uniforms(const GlProgram& program, const ShadowLookup* lookup, int texture_unit);

}  // namespace arpipe
