// The directional light's shadow map (see shadow_map.h).
#include "render/shadow/shadow_map.h"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "render/gl/fullscreen_triangle.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

constexpr std::string_view kCasterVertexShader = R"glsl(#version 300 es
precision highp float;
layout(location = 0) in vec3 a_position;
uniform mat4 u_clip_from_object;
uniform vec4 u_depth_plane;  // the object-frame plane whose value is the light-space depth
out float v_depth;
void main() {
  gl_Position = u_clip_from_object * vec4(a_position, 1.0);
  v_depth = dot(u_depth_plane, vec4(a_position, 1.0));  // linear in distance along the light
}
)glsl";

constexpr std::string_view kDepthFragmentShader = R"glsl(#version 300 es
precision highp float;
in float v_depth;
void main() { gl_FragDepth = clamp(v_depth, 0.0, 1.0); }
)glsl";

// Moments with Donnelly and Lauritzen's bias of the second moment by the depth's slope across the
// texel (keeps a tilted surface from shadowing itself).
constexpr std::string_view kMomentsFragmentShader = R"glsl(#version 300 es
precision highp float;
in float v_depth;
out vec4 out_moments;
void main() {
  float dx = dFdx(v_depth), dy = dFdy(v_depth);
  vec2 moments = vec2(v_depth, v_depth * v_depth + 0.25 * (dx * dx + dy * dy));
  out_moments = vec4(moments, 0.0, 1.0);
  gl_FragDepth = clamp(v_depth, 0.0, 1.0);
}
)glsl";

// The seed's appendix B packing (16 bits each for z and z^2 in RGBA8: low byte in R and B, high
// byte in G and A), with the fixes the extraction records: values kept below 1 (fract(1) = 0),
// and base 255 instead of 256, because an 8-bit UNORM store rounds to k/255: with the seed's 256
// the high byte is off by up to 1/255 of the whole depth range, which shadows the ground itself.
constexpr std::string_view kPackedMomentsFragmentShader = R"glsl(#version 300 es
precision highp float;
in float v_depth;
out vec4 out_moments;
vec2 pack_unit(float x) {  // (low, high) with x = high + low / 255
  vec2 enc = fract(vec2(1.0, 255.0) * x);
  enc.x -= enc.y / 255.0;
  return enc.yx;
}
void main() {
  float z = clamp(v_depth, 0.0, 0.99998);
  float dx = dFdx(z), dy = dFdy(z);
  float z2 = clamp(z * z + 0.25 * (dx * dx + dy * dy), 0.0, 0.99998);
  out_moments = vec4(pack_unit(z), pack_unit(z2));
  gl_FragDepth = z;
}
)glsl";

// One direction of the separable Gaussian; the packed variant unpacks every tap, filters, packs.
constexpr std::string_view kBlurFragmentShaderTemplate = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_source;
uniform ivec2 u_step;
uniform float u_weights[16];
uniform int u_radius;
out vec4 out_moments;
{packing}
void main() {{
  ivec2 at = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(u_source, 0);
  vec2 sum = vec2(0.0);
  for (int i = -u_radius; i <= u_radius; ++i) {{
    ivec2 p = clamp(at + i * u_step, ivec2(0), size - 1);
    sum += u_weights[abs(i)] * read_moments(texelFetch(u_source, p, 0));
  }}
  out_moments = write_moments(sum);
}}
)glsl";

constexpr std::string_view kFloatPacking = R"glsl(
vec2 read_moments(vec4 t) { return t.rg; }
vec4 write_moments(vec2 m) { return vec4(m, 0.0, 1.0); }
)glsl";

constexpr std::string_view kBytePacking = R"glsl(
vec2 read_moments(vec4 t) { return vec2(dot(t.xy, vec2(1.0 / 255.0, 1.0)), dot(t.zw, vec2(1.0 / 255.0, 1.0))); }
vec2 pack_unit(float x) {
  vec2 enc = fract(vec2(1.0, 255.0) * x);
  enc.x -= enc.y / 255.0;
  return enc.yx;
}
vec4 write_moments(vec2 m) {
  m = clamp(m, 0.0, 0.99998);
  return vec4(pack_unit(m.x), pack_unit(m.y));
}
)glsl";

GLenum moments_format(const EglContext& context, ShadowMethod method) {
  if (method == ShadowMethod::VsmPacked) return GL_RGBA8;
  // Linear filtering of 32-bit floats is an extension; half floats filter everywhere in GLES 3.
  const bool float32 = context.has_gl_extension("GL_EXT_color_buffer_float") &&
                       context.has_gl_extension("GL_OES_texture_float_linear");
  return float32 ? GL_RG32F : GL_RG16F;
}

std::string blur_fragment_shader(ShadowMethod method) {
  return fmt::format(fmt::runtime(kBlurFragmentShaderTemplate),
                     fmt::arg("packing", method == ShadowMethod::VsmPacked ? kBytePacking : kFloatPacking));
}

std::array<float, 16> multiply(const std::array<float, 16>& a, const std::array<float, 16>& b) {
  std::array<float, 16> out{};
  for (size_t col = 0; col < 4; ++col)
    for (size_t row = 0; row < 4; ++row) {
      float sum = 0;
      for (size_t k = 0; k < 4; ++k) sum += a[k * 4 + row] * b[col * 4 + k];
      out[col * 4 + row] = sum;
    }
  return out;
}

std::array<float, 16> world_from_object(const UploadedObject& object) {
  std::array<float, 16> m{};
  const Mat3& R = object.T_world_object.rotation();
  const Vec3& t = object.T_world_object.translation();
  for (size_t col = 0; col < 3; ++col) {
    for (size_t row = 0; row < 3; ++row) m[col * 4 + row] = static_cast<float>(R[row][col] * object.scale);
    m[12 + col] = static_cast<float>(t[col]);
  }
  m[15] = 1;
  return m;
}

GlTexture allocate(GLenum format, int size, bool linear) {
  GlTexture texture = create_texel_texture(format, size, size);
  const GLint filter = linear ? GL_LINEAR : GL_NEAREST;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return texture;
}

void attach_color(GLuint framebuffer, GLuint texture) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
}

void check_complete(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw RenderError(fmt::format("the shadow map's {} framebuffer is incomplete (status 0x{:x})", what, status));
}

}  // namespace

ShadowMapPass::ShadowMapPass(const EglContext& context, const ShadowConfig& config)
    : config_(config), method_(config.method), empty_vertex_array_(GlVertexArray::create()) {
  if (method_ == ShadowMethod::Off) return;
  const int size = config.map_size;
  framebuffer_ = GlFramebuffer::create();
  if (is_variance_method(method_)) {
    moments_format_ = moments_format(context, method_);
    const bool packed = method_ == ShadowMethod::VsmPacked;
    moments_program_ = GlProgram("shadow moments", kCasterVertexShader,
                                 packed ? kPackedMomentsFragmentShader : kMomentsFragmentShader);
    blur_program_ = GlProgram("shadow moments blur", kFullScreenTriangleVertexShader, blur_fragment_shader(method_));
    // Packed texels must never be interpolated: the lookup fetches and unpacks them one by one.
    map_ = allocate(moments_format_, size, !packed);
    blur_scratch_ = allocate(moments_format_, size, false);
    depth_buffer_ = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, depth_buffer_.get());
    // The seed's 16-bit depth buffer with packing; 24 bits otherwise.
    glRenderbufferStorage(GL_RENDERBUFFER, packed ? GL_DEPTH_COMPONENT16 : GL_DEPTH_COMPONENT24, size, size);
    attach_color(framebuffer_.get(), map_.get());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_buffer_.get());
    check_complete("moments");
    scratch_framebuffer_ = GlFramebuffer::create();
    attach_color(scratch_framebuffer_.get(), blur_scratch_.get());
    check_complete("blur");
  } else {
    depth_program_ = GlProgram("shadow depth", kCasterVertexShader, kDepthFragmentShader);
    map_ = allocate(GL_DEPTH_COMPONENT32F, size, false);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, map_.get(), 0);
    const GLenum none = GL_NONE;
    glDrawBuffers(1, &none);
    glReadBuffer(GL_NONE);
    check_complete("depth");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("creating the shadow map");
}

bool ShadowMapPass::render(const ShadowFrustum& frustum, std::span<const UploadedObject* const> casters,
                           double angular_diameter_rad) {
  if (method_ == ShadowMethod::Off) return false;
  Key key{frustum.R_light_world, frustum.min, frustum.max, {}, angular_diameter_rad};
  key.local = {frustum.light_position[0], frustum.light_position[1], frustum.light_position[2], frustum.near_m,
               frustum.far_m, frustum.tan_half_angle};
  for (const UploadedObject* object : casters) {
    const Vec3 t = object->T_world_object.translation(), r = object->T_world_object.rotation_vector();
    key.casters.push_back({t[0], t[1], t[2], r[0], r[1], r[2], object->scale});
  }
  if (have_key_ && key == key_) return false;

  const int size = config_.map_size;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  glViewport(0, 0, size, size);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  // Both faces: the objects may be open meshes, and the bias handles the acne of front faces.
  glDisable(GL_CULL_FACE);
  if (is_variance_method(method_)) {
    // Empty texels are as far as the map goes: fully lit, with no variance.
    if (method_ == ShadowMethod::VsmPacked) glClearColor(1.0f, 1.0f, 1.0f, 1.0f);  // just below 1 when unpacked
    else glClearColor(1.0f, 1.0f, 0.0f, 1.0f);
    glClearDepthf(1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    draw_casters(moments_program_, frustum, casters);
    blur_moments();
  } else {
    glClearDepthf(1.0f);
    glClear(GL_DEPTH_BUFFER_BIT);
    draw_casters(depth_program_, frustum, casters);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("rendering the shadow map");

  // Lookup parameters. A texel is width_m / size wide; the bias covers a slope of about 45
  // degrees across depth_bias_texels texels, in depth units.
  const double texel_m = frustum.width_m() / size;
  lookup_.method = method_;
  lookup_.texture = map_.get();
  lookup_.clip_from_world = frustum.clip_from_world();
  lookup_.depth_plane = frustum.depth_plane();
  lookup_.local = frustum.local;
  lookup_.near_m = static_cast<float>(frustum.near_m);
  lookup_.range_m = static_cast<float>(frustum.depth_range_m());
  lookup_.texel = 1.0f / static_cast<float>(size);
  lookup_.bias = static_cast<float>(config_.depth_bias_texels * texel_m / frustum.depth_range_m());
  lookup_.pcf_radius_texels = 0.5f * static_cast<float>(config_.pcf_kernel - 1);
  // A blocker d metres above a receiver under a light of angular diameter a casts a penumbra
  // d * tan(a) wide: its radius in texels per unit of map depth is below.
  // Local light of radius R seen across angular_diameter from the scene: a blocker at distance
  // z_b over a receiver at z_r casts a penumbra of radius R (z_r - z_b) / z_b metres there, where
  // a texel is 2 z_r tan(half angle) / size wide: radius = k (z_r - z_b) / (z_b z_r) texels.
  if (frustum.local) {
    const double light_radius = 0.5 * (frustum.near_m + frustum.far_m) * std::tan(0.5 * angular_diameter_rad);
    lookup_.penumbra_texels_per_depth = static_cast<float>(light_radius * size / (2 * frustum.tan_half_angle));
  } else {
    lookup_.penumbra_texels_per_depth =
        static_cast<float>(0.5 * frustum.depth_range_m() * std::tan(angular_diameter_rad) / texel_m);
  }
  lookup_.max_search_texels = 32.0f;
  // The variance one texel's depth spread gives; below it the Chebyshev bound flickers.
  lookup_.vsm_min_variance = method_ == ShadowMethod::VsmPacked ? 1e-5f : 1e-7f;
  lookup_.vsm_bleed_reduction = static_cast<float>(config_.vsm_bleed_reduction);
  key_ = std::move(key);
  have_key_ = true;
  return true;
}

void ShadowMapPass::draw_casters(const GlProgram& program, const ShadowFrustum& frustum,
                                 std::span<const UploadedObject* const> casters) {
  glUseProgram(program.id());
  const GLint location = program.uniform("u_clip_from_object");
  const GLint depth_plane_location = program.uniform("u_depth_plane");
  const std::array<float, 16> clip_from_world = frustum.clip_from_world();
  const std::array<float, 4> plane = frustum.depth_plane();
  for (const UploadedObject* object : casters) {
    const std::array<float, 16> world = world_from_object(*object);
    const std::array<float, 16> m = multiply(clip_from_world, world);
    glUniformMatrix4fv(location, 1, GL_FALSE, m.data());
    // plane . (M x) = (M^T plane) . x
    std::array<float, 4> object_plane{};
    for (size_t col = 0; col < 4; ++col)
      for (size_t row = 0; row < 4; ++row) object_plane[col] += world[col * 4 + row] * plane[row];
    glUniform4fv(depth_plane_location, 1, object_plane.data());
    object->mesh->draw([](const MeshPart&) {});
  }
}

void ShadowMapPass::blur_moments() {
  const int radius = config_.vsm_blur / 2;
  if (radius == 0) return;
  // A Gaussian whose +-2 sigma spans the kernel, normalised over its taps.
  const double sigma = std::max(0.5, radius / 2.0);
  std::array<float, 16> weights{};
  double total = 0;
  for (int i = 0; i <= radius; ++i) {
    weights[static_cast<size_t>(i)] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
    total += (i == 0 ? 1 : 2) * weights[static_cast<size_t>(i)];
  }
  for (int i = 0; i <= radius; ++i) weights[static_cast<size_t>(i)] = static_cast<float>(weights[static_cast<size_t>(i)] / total);

  glDisable(GL_DEPTH_TEST);
  glUseProgram(blur_program_.id());
  glUniform1i(blur_program_.uniform("u_source"), 0);
  glUniform1fv(blur_program_.uniform("u_weights"), 16, weights.data());
  glUniform1i(blur_program_.uniform("u_radius"), radius);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(empty_vertex_array_.get());
  // map -> scratch across, scratch -> map down.
  glBindFramebuffer(GL_FRAMEBUFFER, scratch_framebuffer_.get());
  glUniform2i(blur_program_.uniform("u_step"), 1, 0);
  glBindTexture(GL_TEXTURE_2D, map_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  glUniform2i(blur_program_.uniform("u_step"), 0, 1);
  glBindTexture(GL_TEXTURE_2D, blur_scratch_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
}

}  // namespace arpipe
