// Draws the virtual objects with per-row poses (see object_renderer.h).
#include "render/object_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "core/sh/sh_rotation.h"
#include "render/shadow/shadow_lookup_glsl.h"

namespace arpipe {
namespace {

constexpr std::string_view kShadingVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_transfer0;  // PRT transfer coefficients 0-3 (object frame)
layout(location = 3) in vec4 a_transfer1;  // 4-7
layout(location = 4) in float a_transfer2; // 8
uniform mat3 u_world_from_object_rotation;  // without the scale
uniform vec3 u_world_from_object_translation;
uniform float u_object_scale;
uniform vec3 u_prt_light[9];  // radiance SH in the object's frame
out vec3 v_normal_world;
out vec3 v_world;
out vec3 v_prt_radiance;      // the environment's outgoing radiance for albedo 1

void main() {
  gl_Position = camera_to_clip(pose_camera_point(a_position));
  // Seed 002: one dot product of light and transfer per vertex, interpolated (Gouraud).
#if WITH_PRT
  v_prt_radiance = a_transfer0.x * u_prt_light[0] + a_transfer0.y * u_prt_light[1] + a_transfer0.z * u_prt_light[2]
                 + a_transfer0.w * u_prt_light[3] + a_transfer1.x * u_prt_light[4] + a_transfer1.y * u_prt_light[5]
                 + a_transfer1.z * u_prt_light[6] + a_transfer1.w * u_prt_light[7] + a_transfer2 * u_prt_light[8];
#else
  v_prt_radiance = vec3(0.0);
#endif
  // The camera's motion does not move the object in the world, so one normal and one world
  // position serve every row.
  v_normal_world = u_world_from_object_rotation * a_normal;
  v_world = u_world_from_object_rotation * (u_object_scale * a_position) + u_world_from_object_translation;
}
)glsl";

// The variant's branches are chosen by the preprocessor (ShadingVariant), not by uniforms: a
// software rasteriser runs both sides of a uniform's branch for every pixel (llvmpipe masks
// them), which cost the lone cube 1 ms a frame.
constexpr std::string_view kShadingFragmentShaderTemplate = R"glsl(#version 300 es
{defines}
precision highp float;
in vec3 v_normal_world;
in vec3 v_world;
in vec3 v_prt_radiance;
uniform vec4 u_base_color;       // linear, straight alpha
uniform vec3 u_light_direction;  // world frame, unit, towards the light
uniform vec4 u_light_position;   // w = 1: a lamp there (the direction is per point)
uniform vec3 u_light_color;
uniform vec3 u_ambient;
uniform vec3 u_ambient_sh[9];
uniform vec3 u_radiance_sh[9];   // the environment's radiance (world), for the glossy reflection
uniform float u_specular;        // its weight
uniform vec3 u_camera_world;     // the eye, for the reflection direction
uniform float u_exposure_scale;
out vec4 out_color;              // linear, premultiplied alpha
{shadow_lookup}
{real_shadow_lookup}
// The virtual objects as spheres of their mean projected area (xyz: centre, world; w: radius).
uniform int u_sky_occluder_count;
uniform vec4 u_sky_occluders[{max_sky_occluders}];
uniform vec4 u_catcher_patch;    // the ground catcher's square: x, y min and max (world)
uniform bool u_ground_catcher;   // this draw is that square (not a proxy)

vec3 sh9_at(vec3 c[9], vec3 n) {{
  return 0.282095 * c[0] + 0.488603 * (n.y * c[1] + n.z * c[2] + n.x * c[3])
       + 1.092548 * (n.x * n.y * c[4] + n.y * n.z * c[5] + n.x * n.z * c[7])
       + 0.315392 * (3.0 * n.z * n.z - 1.0) * c[6] + 0.546274 * (n.x * n.x - n.y * n.y) * c[8];
}}

vec3 ambient_at(vec3 n) {{ return u_ambient + sh9_at(u_ambient_sh, n); }}

// A real surface's ambient: the constant ambient is a sky above the ground, seen over
// (1 + n_z) / 2 of a plane's cosine-weighted view, the lit ground over the rest. An estimate has
// neither (its SH holds both), so this is ambient_at for it.
uniform vec3 u_ground_radiance;
vec3 real_ambient_at(vec3 n) {{
  return u_ambient * (0.5 + 0.5 * n.z) + u_ground_radiance * (0.5 - 0.5 * n.z) + sh9_at(u_ambient_sh, n);
}}

// The share of a surface's ambient irradiance that the virtual objects hide: a sphere of radius r
// at distance d in direction w, a above the horizon, covers pi (r / d)^2 of solid angle, so it
// hides pi (r / d)^2 cos(a) L(w) of E(n) = pi ambient_at(n): (r / d)^2 cos(a) for a uniform sky
// (exact while the sphere is wholly above the horizon), more where the ambient light comes from.
float sky_occlusion(vec3 p, vec3 n, float ambient) {{
  const vec3 luma = vec3(0.2126, 0.7152, 0.0722);
  if (ambient <= 0.0) return 0.0;
  float hidden = 0.0;
  for (int i = 0; i < u_sky_occluder_count; ++i) {{
    vec3 d = u_sky_occluders[i].xyz - p;
    float r = u_sky_occluders[i].w, d2 = max(dot(d, d), r * r);
    vec3 w = d * inversesqrt(d2);
    float radiance = max(dot(sh9_at(u_radiance_sh, w), luma), 0.0);
    hidden += clamp(dot(n, w), 0.0, 1.0) * r * r / d2 * radiance / ambient;
  }}
  return min(hidden, 1.0);
}}

void main() {{
  vec3 normal = normalize(v_normal_world);
  if (!gl_FrontFacing) normal = -normal;  // the inside of an open mesh faces the other way
  vec3 towards_light = u_light_position.w > 0.5 ? normalize(u_light_position.xyz - v_world) : u_light_direction;
  float lambert = max(dot(normal, towards_light), 0.0);
  float visibility = shadow_visibility(v_world);  // uniform control flow: it takes derivatives
#if SHADOW_CATCHER
  // Differential rendering: the real surface's light with the virtual shadow over its light
  // without it, where the real casters already shade it as they do in the picture. One ratio
  // for all channels (the layer has one alpha), by luminance.
  // The real casters' own map: compiled in only when proxies cast (else a constant 1), since a
  // uniform's branch would still cost the lookup on a software rasteriser.
  float real_visibility = real_shadow_visibility(v_world);
  const vec3 luma = vec3(0.2126, 0.7152, 0.0722);
  float ambient = max(dot(real_ambient_at(normal), luma), 0.0);
  float direct = dot(u_light_color, luma) * lambert;
  float real_direct = direct * real_visibility;
  float occlusion = sky_occlusion(v_world, normal, ambient);
  if (u_ground_catcher) {{
    // Faded out over the last tenth of the square's half-width, so that its edge shows no step.
    vec2 inside = min(v_world.xy - u_catcher_patch.xy, u_catcher_patch.zw - v_world.xy);
    float fade_width = 0.1 * max(0.5 * (u_catcher_patch.z - u_catcher_patch.x), 1e-6);
    occlusion *= clamp(min(inside.x, inside.y) / fade_width, 0.0, 1.0);
  }}
  float lit = ambient * (1.0 - occlusion) + visibility * direct;
  float ratio = ambient + real_direct > 0.0 ? min(lit / (ambient + real_direct), 1.0) : 1.0;
#if BAKE_TO_RED
  out_color = vec4(1.0 - ratio);  // a one-channel bake (catcher_bake.h) keeps red
#else
  out_color = vec4(0.0, 0.0, 0.0, 1.0 - ratio);
#endif
#else
#if WITH_PRT
  vec3 environment = v_prt_radiance;
#else
  vec3 environment = ambient_at(normal);
#endif
  vec3 rgb = u_base_color.rgb * max(environment + u_light_color * (lambert * visibility), 0.0);
#if WITH_SPECULAR
  // Seed 002's reflection mapping, from the band-limited environment: a glossy, not a mirror, look.
  vec3 reflected = reflect(normalize(v_world - u_camera_world), normal);
  rgb += u_specular * max(sh9_at(u_radiance_sh, reflected), 0.0);
#endif
  rgb *= u_exposure_scale;
  out_color = vec4(rgb * u_base_color.a, u_base_color.a);
#endif
}}
)glsl";

// A proxy that only hides: its depth and a transparent layer, nothing shaded (the shading
// program would run its shadow lookups for pixels that show the camera anyway).
constexpr std::string_view kOccluderVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
void main() { gl_Position = camera_to_clip(pose_camera_point(a_position)); }
)glsl";

constexpr std::string_view kOccluderFragmentShader = R"glsl(#version 300 es
precision mediump float;
out vec4 out_color;
void main() { out_color = vec4(0.0); }
)glsl";

// The ground catcher's ratio baked over its square (render/shadow/catcher_bake.h): the shading
// program's fragment shader, its point placed on the bake texture instead of the camera image,
// so each texel holds what the catcher would draw at that ground point.
constexpr std::string_view kCatcherBakeVertexShader = R"glsl(
precision highp float;
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat3 u_world_from_object_rotation;
uniform vec3 u_world_from_object_translation;
uniform float u_object_scale;
uniform vec4 u_bake_square;  // world x, y min and max: the texture's extent
out vec3 v_normal_world;
out vec3 v_world;
out vec3 v_prt_radiance;

void main() {
  v_normal_world = u_world_from_object_rotation * a_normal;
  v_world = u_world_from_object_rotation * (u_object_scale * a_position) + u_world_from_object_translation;
  v_prt_radiance = vec3(0.0);
  gl_Position = vec4(2.0 * (v_world.xy - u_bake_square.xy) / (u_bake_square.zw - u_bake_square.xy) - 1.0, 0.0, 1.0);
}
)glsl";

// The ground catcher drawn from its bake: one filtered lookup per pixel instead of the shadow filter.
constexpr std::string_view kBakedCatcherVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
uniform mat3 u_world_from_object_rotation;  // without the scale
uniform vec3 u_world_from_object_translation;
uniform float u_object_scale;
out vec2 v_ground;  // world x, y

void main() {
  gl_Position = camera_to_clip(pose_camera_point(a_position));
  v_ground = (u_world_from_object_rotation * (u_object_scale * a_position) + u_world_from_object_translation).xy;
}
)glsl";

constexpr std::string_view kBakedCatcherFragmentShader = R"glsl(#version 300 es
precision highp float;
in vec2 v_ground;
uniform highp sampler2D u_catcher_ratio;  // red: 1 - ratio, as the shading program bakes it
uniform vec4 u_bake_square;
out vec4 out_color;

void main() {
  out_color = vec4(0.0, 0.0, 0.0, texture(u_catcher_ratio, (v_ground - u_bake_square.xy) / (u_bake_square.zw - u_bake_square.xy)).r);
}
)glsl";

constexpr std::string_view kVelocityVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
out vec2 v_motion_px;
out float v_depth;

vec2 clip_to_pixel(vec4 clip) {  // pixel coordinates, centres at integers
  return (clip.xy / clip.w * 0.5 + 0.5) * u_image_size - 0.5;
}

void main() {
  vec3 mid = mid_camera_point(a_position);
  gl_Position = camera_to_clip(mid);
  vec4 start_clip = camera_to_clip(start_camera_point(a_position));
  vec4 end_clip = camera_to_clip(end_camera_point(a_position));
  // A point behind the camera at either end has no image path; it gets no blur rather than an
  // unbounded one.
  v_motion_px = start_clip.w > 0.0 && end_clip.w > 0.0 ? clip_to_pixel(end_clip) - clip_to_pixel(start_clip) : vec2(0.0);
  v_depth = mid.z;
}
)glsl";

constexpr std::string_view kVelocityFragmentShader = R"glsl(#version 300 es
precision highp float;
in vec2 v_motion_px;
in float v_depth;
out vec4 out_velocity;

void main() { out_velocity = vec4(v_motion_px, v_depth, 1.0); }
)glsl";

// Column-major, as glUniformMatrix3fv wants it without transposing.
std::array<float, 9> column_major(const Mat3& m) {
  std::array<float, 9> out{};
  for (size_t col = 0; col < 3; ++col)
    for (size_t row = 0; row < 3; ++row) out[col * 3 + row] = static_cast<float>(m[row][col]);
  return out;
}

// Radiance SH (world) as seen in the object's frame: the function turned by R_object_world.
std::array<float, 27> object_frame_light(const std::array<Vec3, 9>& radiance_sh_world, const Mat3& R_world_object) {
  ShRgb world(3);
  std::copy(radiance_sh_world.begin(), radiance_sh_world.end(), world.c.begin());
  const ShRgb object = ShRotation(transpose(R_world_object), 3).apply(world);
  std::array<float, 27> out{};
  for (size_t i = 0; i < 9; ++i)
    for (size_t c = 0; c < 3; ++c) out[i * 3 + c] = static_cast<float>(object.c[i][c]);
  return out;
}

void set_vec3(GLint location, const Vec3& v) {
  glUniform3f(location, static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
}

std::string vertex_source(std::initializer_list<std::string_view> tables, std::string_view body,
                          std::string_view defines = {}) {
  std::string source = fmt::format("#version 300 es\n{}\nprecision highp float;\n{}\n", defines, lens_projection_glsl());
  bool first = true;
  for (std::string_view table : tables) {
    source += row_poses_glsl(table, first);
    first = false;
  }
  source += body;
  return source;
}

// Image rows run down GL's y axis (lens_projection.h), which mirrors the winding: a triangle
// counter-clockwise seen from outside is clockwise in window coordinates.
void set_depth_state() {
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CW);
}

// A closed convex mesh's back faces are always hidden behind its front faces: culled, they cost
// no rasterising or shading (half a sphere's triangles), and cannot tie with a front face in depth
// along the silhouette, where the depth interpolation's rounding would pick either. An open or
// concave mesh keeps them: its inside can show.
void cull_back_faces_of(const UploadedObject& object) {
  if (object.closed_convex) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  } else {
    glDisable(GL_CULL_FACE);
  }
}

}  // namespace

ObjectRenderer::ObjectRenderer()
    : velocity_("object velocity", vertex_source({"mid", "start", "end"}, kVelocityVertexShader), kVelocityFragmentShader),
      occluder_("proxy occluder", vertex_source({"pose"}, kOccluderVertexShader), kOccluderFragmentShader),
      baked_catcher_("baked ground catcher", vertex_source({"pose"}, kBakedCatcherVertexShader), kBakedCatcherFragmentShader) {
  prepare(ShadowMethod::Off);
}

void ObjectRenderer::prepare(ShadowMethod method) {
  shading({ShadowMethod::Off, false, false, false, false});  // a surface no shadow reaches
  if (method != ShadowMethod::Off) shading({method, false, true, false, false});  // the ground catcher
}

namespace {

std::string variant_defines(const ShadingVariant& variant) {
  return fmt::format("#define SHADOW_CATCHER {:d}\n#define WITH_PRT {:d}\n#define WITH_SPECULAR {:d}", variant.catcher,
                     variant.prt, variant.specular);
}

// bake: the ground catcher's bake, which keeps its alpha in a one-channel texture's red.
std::string shading_fragment_source(const ShadingVariant& variant, bool bake) {
  return fmt::format(fmt::runtime(kShadingFragmentShaderTemplate),
                     fmt::arg("defines", fmt::format("{}\n#define BAKE_TO_RED {:d}", variant_defines(variant), bake)),
                     fmt::arg("shadow_lookup", shadow_lookup_glsl(variant.method)),
                     fmt::arg("real_shadow_lookup",
                              shadow_lookup_glsl(variant.real_shadow ? variant.method : ShadowMethod::Off, "real_")),
                     fmt::arg("max_sky_occluders", Lighting::kMaxSkyOccluders));
}

std::string shading_program_name(std::string_view what, const ShadingVariant& variant) {
  return fmt::format("{} ({}; {} shadows{}{}{})", what, variant.catcher ? "shadow catcher" : "surface",
                     shadow_method_name(variant.method), variant.real_shadow ? ", real casters" : "",
                     variant.prt ? ", PRT" : "", variant.specular ? ", specular" : "");
}

// The program of `programs` for this variant, compiled on first use with the shading fragment
// shader and the vertex shader `vertex` makes from the variant's defines.
const GlProgram& program_for_variant(std::map<ShadingVariant, GlProgram>& programs, std::string_view what,
                                     const std::function<std::string(std::string_view)>& vertex,
                                     const ShadingVariant& variant, bool bake = false) {
  auto found = programs.find(variant);
  if (found == programs.end())
    found = programs
                .emplace(variant, GlProgram(shading_program_name(what, variant), vertex(variant_defines(variant)),
                                            shading_fragment_source(variant, bake)))
                .first;
  return found->second;
}

}  // namespace

const GlProgram& ObjectRenderer::shading(const ShadingVariant& variant) {
  return program_for_variant(
      shading_, "object shading",
      [](std::string_view defines) { return vertex_source({"pose"}, kShadingVertexShader, defines); }, variant);
}

const GlProgram& ObjectRenderer::baking(ShadowMethod method, bool real_shadow) {
  return program_for_variant(
      baking_, "ground catcher bake",
      [](std::string_view defines) { return fmt::format("#version 300 es\n{}\n{}", defines, kCatcherBakeVertexShader); },
      ShadingVariant{method, real_shadow, true, false, false}, true);
}

namespace {

// Whether a cluster's box (object frame, scaled) can reach into the rectangle at any of the item's
// row poses, through the pinhole canvas; a box reaching behind the near plane, or a lens applied
// per vertex, counts as in.
bool cluster_in_rect(const Bounds& box, const RowPoses& poses, const LensUniforms& lens, const PixelRect& rect) {
  if (lens.distorted) return true;
  constexpr double kMarginPx = 2.0;
  const auto [fx, fy, cx, cy] = lens.focal_center;
  for (const SE3& T_cam_object : poses.T_cam_object) {
    double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (const Vec3& corner : box_corners(box)) {
      const Vec3 p = T_cam_object * corner;
      if (p[2] <= kNearPlaneM) return true;
      const double u = fx * p[0] / p[2] + cx, v = fy * p[1] / p[2] + cy;
      u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
    }
    if (u1 + kMarginPx >= rect.x - 0.5 && u0 - kMarginPx <= rect.right() - 0.5 && v1 + kMarginPx >= rect.y - 0.5 &&
        v0 - kMarginPx <= rect.bottom() - 0.5)
      return true;
  }
  return false;
}

// Draws the object's mesh: whole, or the clusters of a large proxy that reach into the rectangle.
void draw_mesh(const ObjectAtInstant& item, const LensUniforms& lens, const PixelRect& cull_rect,
               const std::function<void(const MeshPart&)>& before_part) {
  const UploadedObject& object = *item.object;
  if (object.cluster_bounds.empty() || object.cluster_bounds.size() != object.mesh->part_count()) {
    object.mesh->draw(before_part);
    return;
  }
  // Clusters share the proxy's one colour: set it once.
  before_part(MeshPart{0, 0, object.base_color ? *object.base_color : std::array<float, 4>{0, 0, 0, 0}});
  object.mesh->draw_parts([&](size_t part) { return cluster_in_rect(object.cluster_bounds[part], item.poses, lens, cull_rect); });
}

// Draws the ground catcher in each of lighting.ground_catcher_rects (all of cull_rect without
// them), leaving the scissor at cull_rect.
void within_ground_rects(const Lighting& lighting, const PixelRect& cull_rect, const std::function<void()>& draw) {
  if (!lighting.ground_catcher_rects) {
    draw();
    return;
  }
  for (const PixelRect& rect : *lighting.ground_catcher_rects) {
    const PixelRect r = rect.intersected(cull_rect);
    if (r.empty()) continue;
    glScissor(r.x, r.y, r.width, r.height);
    draw();
  }
  glScissor(cull_rect.x, cull_rect.y, cull_rect.width, cull_rect.height);
}

// The coarsest occluder level of the item's proxy that strays at most tolerance_px at the nearest
// corner of its box over the item's row poses; null: the full mesh (no level fits, the box reaches
// the near plane, or the lens is applied per vertex, which long edges would not follow).
const GpuMesh* occluder_level_for(const ObjectAtInstant& item, const LensUniforms& lens, double tolerance_px) {
  const UploadedObject& object = *item.object;
  if (object.occluder_levels.empty() || lens.distorted || !(tolerance_px > 0)) return nullptr;
  double nearest = INFINITY;
  for (const SE3& T_cam_object : item.poses.T_cam_object)
    for (const Vec3& corner : box_corners(object.bounds)) nearest = std::min(nearest, (T_cam_object * corner)[2]);
  if (!(nearest > kNearPlaneM)) return nullptr;
  const int chosen = coarsest_occluder_level(object.occluder_level_errors_m,
                                             std::max(lens.focal_center[0], lens.focal_center[1]), nearest, tolerance_px);
  return chosen < 0 ? nullptr : object.occluder_levels[size_t(chosen)].get();
}

}  // namespace

void ObjectRenderer::set_frame_uniforms(const GlProgram& program, const LensUniforms& lens, const RowProjection& rows,
                                        const Lighting& lighting) const {
  set_lens_uniforms(program, lens);  // binds the program
  set_row_projection(program, rows);
  set_light_uniforms(program, lighting);
}

void ObjectRenderer::set_light_uniforms(const GlProgram& program, const Lighting& lighting) const {
  glUseProgram(program.id());
  // Each variant's compiler drops the uniforms it does not read (a PRT surface's ambient, a
  // catcher's exposure, the lookups of a program without them): their location is -1, which
  // glUniform ignores.
  const auto location = [&](const char* name) { return glGetUniformLocation(program.id(), name); };
  set_vec3(location("u_light_direction"), lighting.direction);
  glUniform4f(location("u_light_position"), static_cast<float>(lighting.position[0]),
              static_cast<float>(lighting.position[1]), static_cast<float>(lighting.position[2]), lighting.local ? 1.0f : 0.0f);
  set_vec3(location("u_light_color"), lighting.color);
  set_vec3(location("u_ambient"), lighting.ambient);
  std::array<float, 27> sh{};
  for (size_t i = 0; i < 9; ++i)
    for (size_t c = 0; c < 3; ++c) sh[i * 3 + c] = static_cast<float>(lighting.ambient_sh[i][c]);
  glUniform3fv(location("u_ambient_sh"), 9, sh.data());
  for (size_t i = 0; i < 9; ++i)
    for (size_t c = 0; c < 3; ++c) sh[i * 3 + c] = static_cast<float>(lighting.radiance_sh[i][c]);
  glUniform3fv(location("u_radiance_sh"), 9, sh.data());
  glUniform1f(location("u_exposure_scale"), static_cast<float>(lighting.exposure_scale));
  if (lighting.shadow && location("u_shadow_map") >= 0) set_shadow_lookup_uniforms(program, *lighting.shadow, 1);
  if (lighting.shadow && lighting.real_shadow && location("real_u_shadow_map") >= 0)
    set_shadow_lookup_uniforms(program, *lighting.real_shadow, 2, "real_");
  const int sky_occluders = static_cast<int>(std::min(lighting.sky_occluders.size(), Lighting::kMaxSkyOccluders));
  glUniform1i(location("u_sky_occluder_count"), sky_occluders);
  if (sky_occluders > 0) glUniform4fv(location("u_sky_occluders"), sky_occluders, lighting.sky_occluders[0].data());
  glUniform4fv(location("u_catcher_patch"), 1, lighting.catcher_patch.data());
  set_vec3(location("u_ground_radiance"), lighting.ground_radiance);
}

void ObjectRenderer::draw_ground_catcher_under(const LensUniforms& lens, const RowProjection& rows,
                                               const Lighting& lighting, const ObjectAtInstant& catcher,
                                               const PixelRect& cull_rect) {
  draw_items(lens, rows, lighting, std::span<const ObjectAtInstant>(&catcher, 1), cull_rect, 0, true);
}

void ObjectRenderer::draw_ground_catcher_depth(const LensUniforms& lens, const RowProjection& rows,
                                               const ObjectAtInstant& catcher) {
  set_depth_state();
  set_lens_uniforms(occluder_, lens);  // binds it
  set_row_projection(occluder_, rows);
  set_row_poses(occluder_, "pose", catcher.poses, catcher.object->scale);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_TRUE);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  catcher.object->mesh->draw([](const MeshPart&) {});
  glDisable(GL_POLYGON_OFFSET_FILL);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void ObjectRenderer::draw(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
                          std::span<const ObjectAtInstant> objects, const PixelRect& cull_rect, double occluder_lod_px) {
  draw_items(lens, rows, lighting, objects, cull_rect, occluder_lod_px, false);
}

void ObjectRenderer::draw_items(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
                                std::span<const ObjectAtInstant> objects, const PixelRect& cull_rect,
                                double occluder_lod_px, bool under) {
  const ShadowMethod method = lighting.shadow ? lighting.shadow->method : ShadowMethod::Off;
  const bool real = lighting.shadow && lighting.real_shadow;
  set_depth_state();
  if (under) {
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE_MINUS_DST_ALPHA, GL_ONE);
  }
  // A proxy shades only to catch a shadow; without one this frame it hides (depth only) or is
  // not drawn at all.
  const auto shades = [&](const UploadedObject& object) { return !object.proxy || (object.shadow_catcher && lighting.shadow); };
  const auto unshadowed = [&](const UploadedObject& object) {
    return std::find(lighting.unshadowed.begin(), lighting.unshadowed.end(), &object) != lighting.unshadowed.end();
  };
  const bool any_occluder = std::any_of(objects.begin(), objects.end(), [&](const ObjectAtInstant& item) {
    return !shades(*item.object) && item.object->writes_depth;
  });
  if (any_occluder) {
    set_lens_uniforms(occluder_, lens);
    set_row_projection(occluder_, rows);
  }
  // The programs this draw uses, each given the frame's uniforms and its per-object uniforms'
  // locations on first use. A location the variant's compiler dropped is -1, which glUniform ignores.
  struct InUse {
    const GlProgram* program = nullptr;
    GLint rotation = -1, translation = -1, scale = -1, ground_catcher = -1, specular = -1, camera_world = -1,
          prt_light = -1, base_color = -1;
  };
  std::map<ShadingVariant, InUse> in_use_by_variant;
  const auto program_for = [&](const ShadingVariant& variant) -> const InUse& {
    InUse& in_use = in_use_by_variant[variant];
    if (!in_use.program) {
      const GlProgram& program = shading(variant);
      set_frame_uniforms(program, lens, rows, lighting);
      const auto location = [&](const char* name) { return glGetUniformLocation(program.id(), name); };
      in_use = {&program,
                program.uniform("u_world_from_object_rotation"),
                program.uniform("u_world_from_object_translation"),
                program.uniform("u_object_scale"),
                location("u_ground_catcher"),
                location("u_specular"),
                location("u_camera_world"),
                location("u_prt_light"),
                location("u_base_color")};
    }
    glUseProgram(in_use.program->id());
    return in_use;
  };
  const auto baked_ground_catcher = [&](const UploadedObject& object) {
    return object.shadow_catcher && !object.proxy && lighting.shadow && lighting.baked_catcher.texture != 0;
  };
  bool baked_catcher_ready = false;
  for (const ObjectAtInstant& item : objects) {
    if (baked_ground_catcher(*item.object)) {
      if (!baked_catcher_ready) {
        set_lens_uniforms(baked_catcher_, lens);
        set_row_projection(baked_catcher_, rows);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, lighting.baked_catcher.texture);
        glActiveTexture(GL_TEXTURE0);
        glUniform1i(baked_catcher_.uniform("u_catcher_ratio"), 3);
        glUniform4fv(baked_catcher_.uniform("u_bake_square"), 1, lighting.baked_catcher.square.data());
        baked_catcher_ready = true;
      }
      glUseProgram(baked_catcher_.id());
      set_row_poses(baked_catcher_, "pose", item.poses, item.object->scale);
      set_object_placement(baked_catcher_, *item.object);
      glDepthMask(item.object->writes_depth ? GL_TRUE : GL_FALSE);  // as the per-pixel path
      cull_back_faces_of(*item.object);
      within_ground_rects(lighting, cull_rect, [&] { item.object->mesh->draw([](const MeshPart&) {}); });
      continue;
    }
    if (!shades(*item.object)) {
      if (!item.object->writes_depth) continue;
      glUseProgram(occluder_.id());
      set_row_poses(occluder_, "pose", item.poses, item.object->scale);
      glDepthMask(GL_TRUE);
      cull_back_faces_of(*item.object);
      if (const GpuMesh* level = occluder_level_for(item, lens, occluder_lod_px)) level->draw([](const MeshPart&) {});
      else draw_mesh(item, lens, cull_rect, [](const MeshPart&) {});
      continue;
    }
    const UploadedObject& object = *item.object;
    ShadingVariant variant;
    if (method != ShadowMethod::Off && !unshadowed(object)) variant.method = method, variant.real_shadow = real;
    variant.catcher = object.shadow_catcher;  // shades() draws a proxy only as a catcher
    variant.prt = !variant.catcher && object.mesh->has_transfer();
    variant.specular = !variant.catcher && object.specular > 0;
    const InUse& in_use = program_for(variant);
    set_row_poses(*in_use.program, "pose", item.poses, object.scale);
    const std::array<float, 9> rotation = column_major(object.T_world_object.rotation());
    glUniformMatrix3fv(in_use.rotation, 1, GL_FALSE, rotation.data());
    set_vec3(in_use.translation, object.T_world_object.translation());
    glUniform1f(in_use.scale, static_cast<float>(object.scale));
    glUniform1i(in_use.ground_catcher, object.shadow_catcher && !object.proxy ? 1 : 0);
    glDepthMask(object.writes_depth ? GL_TRUE : GL_FALSE);
    if (variant.specular && !item.poses.T_cam_object.empty()) {
      glUniform1f(in_use.specular, static_cast<float>(object.specular));
      // The eye of the middle row: rows differ by far less than the reflection's blur.
      const SE3& T_cam_object = item.poses.T_cam_object[item.poses.T_cam_object.size() / 2];
      set_vec3(in_use.camera_world, object.T_world_object * T_cam_object.inverse().translation());
    }
    if (variant.prt) {
      // The transfer lives in the object's frame: turn the world's light into it.
      const std::array<float, 27> light = object_frame_light(lighting.radiance_sh, object.T_world_object.rotation());
      glUniform3fv(in_use.prt_light, 9, light.data());
    }
    const GLint base_color = in_use.base_color;
    cull_back_faces_of(object);
    const auto draw_it = [&] {
      draw_mesh(item, lens, cull_rect, [&](const MeshPart& part) {
        const std::array<float, 4>& color = item.object->base_color ? *item.object->base_color : part.base_color;
        glUniform4f(base_color, color[0], color[1], color[2], color[3]);
      });
    };
    if (object.shadow_catcher && !object.proxy) within_ground_rects(lighting, cull_rect, draw_it);
    else draw_it();
  }
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
}

void ObjectRenderer::bake_ground_catcher(const Lighting& lighting, const UploadedObject& catcher,
                                         const std::array<float, 4>& square) {
  const ShadowMethod method = lighting.shadow ? lighting.shadow->method : ShadowMethod::Off;
  const GlProgram& program = baking(method, lighting.shadow && lighting.real_shadow);
  set_light_uniforms(program, lighting);  // binds it
  set_object_placement(program, catcher);
  glUniform4fv(program.uniform("u_bake_square"), 1, square.data());
  glUniform1i(glGetUniformLocation(program.id(), "u_ground_catcher"), 1);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);  // seen from above with x right and y up, the square winds counter-clockwise
  catcher.mesh->draw([](const MeshPart&) {});
  glFrontFace(GL_CW);
}

void ObjectRenderer::set_object_placement(const GlProgram& program, const UploadedObject& object) const {
  const std::array<float, 9> rotation = column_major(object.T_world_object.rotation());
  glUniformMatrix3fv(program.uniform("u_world_from_object_rotation"), 1, GL_FALSE, rotation.data());
  set_vec3(program.uniform("u_world_from_object_translation"), object.T_world_object.translation());
  glUniform1f(program.uniform("u_object_scale"), static_cast<float>(object.scale));
}

void ObjectRenderer::draw_velocity(const LensUniforms& lens, const RowProjection& rows,
                                   std::span<const ObjectOverExposure> objects) const {
  set_depth_state();
  set_lens_uniforms(velocity_, lens);
  set_row_projection(velocity_, rows);
  for (const ObjectOverExposure& item : objects) {
    set_row_poses(velocity_, "start", item.start, item.object->scale);
    set_row_poses(velocity_, "mid", item.mid, item.object->scale);
    set_row_poses(velocity_, "end", item.end, item.object->scale);
    cull_back_faces_of(*item.object);
    item.object->mesh->draw([](const MeshPart&) {});
  }
  glDisable(GL_CULL_FACE);
}

}  // namespace arpipe
