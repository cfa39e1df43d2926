// The GLSL that reads a shadow map (shadow_map.h) in a shading pass: one function per method,
// `float shadow_visibility(vec3 world)`, 1 lit and 0 in shadow, and the uniforms it reads.
#pragma once

#include <string>
#include <string_view>

#include "render/gl/gl_program.h"
#include "render/shadow/shadow_map.h"

namespace arpipe {

// Method Off gives a function that returns 1 and declares no uniforms. A prefix names a second
// copy beside the first: every uniform and function it declares starts with it
// ("real_shadow_visibility", "real_u_shadow_map").
std::string shadow_lookup_glsl(ShadowMethod method, std::string_view prefix = "");
// Binds lookup.texture to texture_unit; the program must be in use. prefix: as the GLSL's.
void set_shadow_lookup_uniforms(const GlProgram& program, const ShadowLookup& lookup, int texture_unit,
                                std::string_view prefix = "");


}  // namespace arpipe
