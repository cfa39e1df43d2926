// Shadow-map lookups per method (see shadow_lookup_glsl.h).
#include "render/shadow/shadow_lookup_glsl.h"

#include <fmt/format.h>

#include <cctype>
#include <string>

namespace arpipe {
namespace {

constexpr std::string_view kCommon = R"glsl(
uniform highp sampler2D u_shadow_map;
uniform mat4 u_shadow_clip_from_world;
uniform vec4 u_shadow_depth_plane;
uniform float u_shadow_local;
uniform float u_shadow_near;
uniform float u_shadow_range;
uniform float u_shadow_texel;
uniform float u_shadow_bias;
uniform float u_pcf_radius;
uniform float u_penumbra_per_depth;
uniform float u_max_search;
uniform float u_vsm_min_variance;
uniform float u_vsm_bleed;

// (u, v, depth) in [0, 1]; outside the map counts as lit (nothing there casts).
vec3 shadow_coordinates(vec3 world) {
  vec4 clip = u_shadow_clip_from_world * vec4(world, 1.0);
  return vec3(clip.xy / clip.w * 0.5 + 0.5, dot(u_shadow_depth_plane, vec4(world, 1.0)));
}
bool outside_map(vec3 p) { return any(lessThan(p.xy, vec2(0.0))) || any(greaterThan(p.xy, vec2(1.0))) || p.z >= 1.0; }
float lit_at(vec2 uv, float depth) { return depth - u_shadow_bias <= texture(u_shadow_map, uv).r ? 1.0 : 0.0; }
// Receiver-plane depth bias (Isidoro 2006): how the surface's own depth changes across the map,
// from the screen-space derivatives, so that taps away from the centre compare with the
// surface's depth there and a tilted surface does not shadow itself. Call in uniform control flow.
vec2 receiver_depth_gradient(vec3 p) {
  vec3 dx = dFdx(p), dy = dFdy(p);
  float det = dx.x * dy.y - dx.y * dy.x;
  if (abs(det) < 1e-14) return vec2(0.0);
  vec2 g = vec2(dy.y * dx.z - dx.y * dy.z, dx.x * dy.z - dy.x * dx.z) / det;
  return clamp(g, vec2(-8.0), vec2(8.0));  // grazing surfaces: keep it finite
}
)glsl";

// The seed's binary test.
constexpr std::string_view kHard = R"glsl(
float shadow_visibility(vec3 world) {
  vec3 p = shadow_coordinates(world);
  if (outside_map(p)) return 1.0;
  return lit_at(p.xy, p.z);
}
)glsl";

// Percentage-closer filtering (Reeves et al.): the mean of k x k binary tests around the point,
// box weights, centred (an even k puts the taps between texel centres).
constexpr std::string_view kPcf = R"glsl(
float shadow_visibility(vec3 world) {
  vec3 p = shadow_coordinates(world);
  vec2 g = receiver_depth_gradient(p);
  if (outside_map(p)) return 1.0;
  float sum = 0.0, count = 0.0;
  for (float y = -u_pcf_radius; y <= u_pcf_radius + 0.001; y += 1.0)
    for (float x = -u_pcf_radius; x <= u_pcf_radius + 0.001; x += 1.0) {
      vec2 offset = vec2(x, y) * u_shadow_texel;
      sum += lit_at(p.xy + offset, p.z + dot(g, offset));
      count += 1.0;
    }
  return sum / count;
}
)glsl";

// PCSS (Fernando 2005): the mean depth of the blockers found around the point sets the penumbra
// width that the light's angular size gives, and a PCF of that width follows. 6 x 6 taps each.
constexpr std::string_view kPcss = R"glsl(
// Penumbra radius in texels for a receiver and a blocker at these depths (shadow_map.cpp).
float penumbra_radius(float receiver, float blocker) {
  if (u_shadow_local < 0.5) return u_penumbra_per_depth * (receiver - blocker);
  float zr = u_shadow_near + receiver * u_shadow_range, zb = max(u_shadow_near + blocker * u_shadow_range, 1e-4);
  return u_penumbra_per_depth * (zr - zb) / (zb * zr);
}
float shadow_visibility(vec3 world) {
  vec3 p = shadow_coordinates(world);
  vec2 g = receiver_depth_gradient(p);
  if (outside_map(p)) return 1.0;
  float search = clamp(penumbra_radius(p.z, 0.0), 1.0, u_max_search);
  float blockers = 0.0, blocker_depth = 0.0;
  for (float y = -2.5; y <= 2.5; y += 1.0)
    for (float x = -2.5; x <= 2.5; x += 1.0) {
      vec2 offset = vec2(x, y) * (search / 2.5) * u_shadow_texel;
      float d = texture(u_shadow_map, p.xy + offset).r;
      if (d < p.z + dot(g, offset) - u_shadow_bias) { blockers += 1.0; blocker_depth += d; }
    }
  if (blockers == 0.0) return 1.0;
  blocker_depth /= blockers;
  float radius = clamp(penumbra_radius(p.z, blocker_depth), 0.5, u_max_search);
  float sum = 0.0;
  for (float y = -2.5; y <= 2.5; y += 1.0)
    for (float x = -2.5; x <= 2.5; x += 1.0) {
      vec2 offset = vec2(x, y) * (radius / 2.5) * u_shadow_texel;
      sum += lit_at(p.xy + offset, p.z + dot(g, offset));
    }
  return sum / 36.0;
}
)glsl";

// Variance shadow maps (Donnelly and Lauritzen): Chebyshev's one-tailed bound on the filtered
// moments, with a variance floor and the light-bleeding cut.
constexpr std::string_view kChebyshev = R"glsl(
float chebyshev(vec2 moments, float depth) {
  if (depth <= moments.x) return 1.0;
  float variance = max(moments.y - moments.x * moments.x, u_vsm_min_variance);
  float d = depth - moments.x;
  float p = variance / (variance + d * d);
  return clamp((p - u_vsm_bleed) / (1.0 - u_vsm_bleed), 0.0, 1.0);
}
)glsl";

constexpr std::string_view kVsm = R"glsl(
float shadow_visibility(vec3 world) {
  vec3 p = shadow_coordinates(world);
  if (outside_map(p)) return 1.0;
  return chebyshev(texture(u_shadow_map, p.xy).rg, p.z);
}
)glsl";

// Packed moments cannot be interpolated: four texels are fetched, unpacked and blended by hand.
constexpr std::string_view kVsmPacked = R"glsl(
vec2 unpack_moments(vec4 t) { return vec2(dot(t.xy, vec2(1.0 / 255.0, 1.0)), dot(t.zw, vec2(1.0 / 255.0, 1.0))); }
float shadow_visibility(vec3 world) {
  vec3 p = shadow_coordinates(world);
  if (outside_map(p)) return 1.0;
  vec2 size = vec2(textureSize(u_shadow_map, 0));
  vec2 at = p.xy * size - 0.5;
  ivec2 base = ivec2(floor(at));
  vec2 f = at - floor(at);
  ivec2 top = ivec2(size) - 1;
  vec2 m00 = unpack_moments(texelFetch(u_shadow_map, clamp(base, ivec2(0), top), 0));
  vec2 m10 = unpack_moments(texelFetch(u_shadow_map, clamp(base + ivec2(1, 0), ivec2(0), top), 0));
  vec2 m01 = unpack_moments(texelFetch(u_shadow_map, clamp(base + ivec2(0, 1), ivec2(0), top), 0));
  vec2 m11 = unpack_moments(texelFetch(u_shadow_map, clamp(base + ivec2(1, 1), ivec2(0), top), 0));
  return chebyshev(mix(mix(m00, m10, f.x), mix(m01, m11, f.x), f.y), p.z);
}
)glsl";

}  // namespace

namespace {

// Every name the lookups declare, so that a second copy can live beside the first under a prefix.
constexpr std::string_view kLookupNames[] = {
    "u_shadow_map", "u_shadow_clip_from_world", "u_shadow_depth_plane", "u_shadow_local", "u_shadow_near",
    "u_shadow_range", "u_shadow_texel", "u_shadow_bias", "u_pcf_radius", "u_penumbra_per_depth", "u_max_search",
    "u_vsm_min_variance", "u_vsm_bleed", "shadow_coordinates", "outside_map", "lit_at", "receiver_depth_gradient",
    "penumbra_radius", "shadow_visibility", "chebyshev", "unpack_moments"};

bool identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Each whole-word occurrence of the lookup's names gets the prefix.
std::string prefixed(const std::string& source, std::string_view prefix) {
  std::string out;
  out.reserve(source.size() + 1024);
  size_t i = 0;
  while (i < source.size()) {
    bool replaced = false;
    if (!identifier_char(source[i]) || i == 0 || !identifier_char(source[i - 1]))
      for (std::string_view name : kLookupNames)
        if (source.compare(i, name.size(), name) == 0 &&
            (i + name.size() == source.size() || !identifier_char(source[i + name.size()]))) {
          out += prefix;
          out += name;
          i += name.size();
          replaced = true;
          break;
        }
    if (!replaced) out += source[i++];
  }
  return out;
}

std::string lookup_source(ShadowMethod method) {
  switch (method) {
    case ShadowMethod::Off: return "float shadow_visibility(vec3 world) { return 1.0; }\n";
    case ShadowMethod::Hard: return std::string(kCommon) + std::string(kHard);
    case ShadowMethod::Pcf: return std::string(kCommon) + std::string(kPcf);
    case ShadowMethod::Pcss: return std::string(kCommon) + std::string(kPcss);
    case ShadowMethod::Vsm: return std::string(kCommon) + std::string(kChebyshev) + std::string(kVsm);
    case ShadowMethod::VsmPacked: return std::string(kCommon) + std::string(kChebyshev) + std::string(kVsmPacked);
  }
  return {};
}

}  // namespace

std::string shadow_lookup_glsl(ShadowMethod method, std::string_view prefix) {
  const std::string source = lookup_source(method);
  return prefix.empty() ? source : prefixed(source, prefix);
}

void set_shadow_lookup_uniforms(const GlProgram& program, const ShadowLookup& lookup, int texture_unit,
                                std::string_view prefix) {
  if (lookup.method == ShadowMethod::Off) return;
  const auto name = [&](const char* n) { return std::string(prefix) + n; };
  glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + texture_unit));
  glBindTexture(GL_TEXTURE_2D, lookup.texture);
  glUniform1i(program.uniform(name("u_shadow_map").c_str()), texture_unit);
  glUniformMatrix4fv(program.uniform(name("u_shadow_clip_from_world").c_str()), 1, GL_FALSE, lookup.clip_from_world.data());
  glUniform4fv(program.uniform(name("u_shadow_depth_plane").c_str()), 1, lookup.depth_plane.data());
  // The compiler drops the uniforms a method does not read; only those it reads are set.
  const auto set = [&](const char* n, float value) {
    const GLint location = glGetUniformLocation(program.id(), name(n).c_str());
    if (location >= 0) glUniform1f(location, value);
  };
  set("u_shadow_texel", lookup.texel);
  set("u_shadow_local", lookup.local ? 1.0f : 0.0f);
  set("u_shadow_near", lookup.near_m);
  set("u_shadow_range", lookup.range_m);
  set("u_shadow_bias", lookup.bias);
  set("u_pcf_radius", lookup.pcf_radius_texels);
  set("u_penumbra_per_depth", lookup.penumbra_texels_per_depth);
  set("u_max_search", lookup.max_search_texels);
  set("u_vsm_min_variance", lookup.vsm_min_variance);
  set("u_vsm_bleed", lookup.vsm_bleed_reduction);
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace arpipe
