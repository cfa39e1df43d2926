// Seed 000's composite (the thesis's Algorithm 2, in closed form): the premultiplied mean of the
// blur samples, each one or both intraframes seen through its inverse affine warp.
#include "render/blur/intraframe_warp_blur_pass.h"

#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "render/gl/fullscreen_triangle.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// The samples' lookups with a weight above zero, those into the first intraframe first: a sample
// before the first intraframe reads only it, one after the second only that one, and only those
// between cross-fade both, so a plan of n samples has n + (the cross-fades) lookups, not 2n. Two
// loops over them run only those: a software rasteriser runs both sides of a branch on a
// per-sample weight whatever the weight, and a texture lookup is most of the pass's cost.
// Per lookup, its warp output -> intraframe, already turned into gl_FragCoord -> texture
// coordinates (so the shader does one dot product per coordinate), and its weight, in 2 vec4s
//   [u0 u1 u2 v0] [v1 v2 w -]   (u = dot(u*, (fc, 1)))
// 2 * 100 = 200 uniform vectors and three scalars, within GLES 3.0's guaranteed 224
// (GL_MAX_FRAGMENT_UNIFORM_VECTORS). The bounds test on the texture coordinate ([0, 1] = pixel
// coordinates [-0.5, size - 0.5]) stands in for clamp-to-border, which GLES 3.0 lacks: the edge
// half-texel reads the edge texel, beyond it reads transparent black.
constexpr std::string_view kFragmentShaderTemplate = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_first;
uniform highp sampler2D u_second;
uniform int u_first_lookups;   // u_lookups[0, u_first_lookups) read u_first
uniform int u_lookup_count;    // the rest, up to u_lookup_count, read u_second
uniform float u_samples;
uniform vec4 u_lookups[{lookups}];
out vec4 out_color;

vec4 sample_inside(highp sampler2D image, vec2 uv) {{
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return vec4(0.0);
  return texture(image, uv);
}}

void main() {{
  vec3 at = vec3(gl_FragCoord.xy, 1.0);
  vec4 sum = vec4(0.0);
  for (int i = 0; i < u_first_lookups; ++i) {{
    vec4 a = u_lookups[2 * i], b = u_lookups[2 * i + 1];
    sum += b.z * sample_inside(u_first, vec2(dot(a.xyz, at), dot(vec3(a.w, b.xy), at)));
  }}
  for (int i = u_first_lookups; i < u_lookup_count; ++i) {{
    vec4 a = u_lookups[2 * i], b = u_lookups[2 * i + 1];
    sum += b.z * sample_inside(u_second, vec2(dot(a.xyz, at), dot(vec3(a.w, b.xy), at)));
  }}
  out_color = sum / u_samples;
}}
)glsl";

constexpr int kMaxLookups = 2 * IntraframeWarpBlurPass::kMaxSamples;

std::string fragment_shader() { return fmt::format(kFragmentShaderTemplate, fmt::arg("lookups", 2 * kMaxLookups)); }

// The map output pixel p -> intraframe pixel q = M p (pixel centres at integers) as
// gl_FragCoord f = p + 0.5 -> texture coordinate (q + 0.5) / size: 6 floats, row u then row v.
std::array<float, 6> fragcoord_to_uv(const Affine2& map, int width, int height) {
  const auto& m = map.m;
  std::array<float, 6> out{};
  const double size[2] = {double(width), double(height)};
  for (int row = 0; row < 2; ++row) {
    const double a = m[size_t(3 * row)], b = m[size_t(3 * row + 1)], c = m[size_t(3 * row + 2)];
    out[size_t(3 * row)] = float(a / size[row]);
    out[size_t(3 * row + 1)] = float(b / size[row]);
    out[size_t(3 * row + 2)] = float((c - 0.5 * (a + b) + 0.5) / size[row]);
  }
  return out;
}

}  // namespace

IntraframeWarpBlurPass::IntraframeWarpBlurPass(GLenum output_format)
    : output_format_(output_format),
      program_("seed blur", kFullScreenTriangleVertexShader, fragment_shader()),
      empty_vertex_array_(GlVertexArray::create()) {
  glUseProgram(program_.id());
  glUniform1i(program_.uniform("u_first"), 0);
  glUniform1i(program_.uniform("u_second"), 1);
  check_gl("setting up the seed blur pass");
}

void IntraframeWarpBlurPass::run(GLuint first, GLuint second, int width, int height, const IntraframeWarpPlan& plan,
                       const PixelRect& rect) {
  const int count = int(plan.samples.size());
  if (count > kMaxSamples)
    throw RenderError(fmt::format("seed blur pass: {} samples, at most {} fit the shader", count, kMaxSamples));
  if (width <= 0 || height <= 0)
    throw RenderError(fmt::format("seed blur pass: image size {}x{}", width, height));
  if (width != width_ || height != height_ || !output_texture_) {
    output_texture_ = create_texel_texture(output_format_, width, height);
    output_framebuffer_ = create_framebuffer_for(output_texture_.get());
    check_framebuffer_complete("seed blur output");
    width_ = width, height_ = height;
  }

  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_.get());
  glViewport(0, 0, width, height);
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect.x, rect.y, rect.width, rect.height);
  if (count == 0 || rect.empty()) {
    glClearColor(0, 0, 0, 0);
    if (!rect.empty()) glClear(GL_COLOR_BUFFER_BIT);
  } else {
    // The lookups, those into the first intraframe first (see the shader).
    std::vector<float> lookups;
    lookups.reserve(size_t(8 * kMaxLookups));
    const auto add = [&](const Affine2& map, double weight) {
      const std::array<float, 6> uv = fragcoord_to_uv(map, width, height);
      lookups.insert(lookups.end(), uv.begin(), uv.end());
      lookups.insert(lookups.end(), {float(weight), 0.0f});
    };
    for (const IntraframeWarpSample& sample : plan.samples)
      if (sample.weight_first > 0) add(sample.first_from_output, sample.weight_first);
    const int first_lookups = int(lookups.size() / 8);
    for (const IntraframeWarpSample& sample : plan.samples)
      if (sample.weight_second > 0) add(sample.second_from_output, sample.weight_second);
    const int lookup_count = int(lookups.size() / 8);
    for (const auto& [unit, texture] : {std::pair{GL_TEXTURE0, first}, std::pair{GL_TEXTURE1, second}}) {
      glActiveTexture(GLenum(unit));
      glBindTexture(GL_TEXTURE_2D, texture);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(program_.id());
    glUniform1i(program_.uniform("u_first_lookups"), first_lookups);
    glUniform1i(program_.uniform("u_lookup_count"), lookup_count);
    glUniform1f(program_.uniform("u_samples"), float(count));
    if (lookup_count > 0) glUniform4fv(program_.uniform("u_lookups"), 2 * lookup_count, lookups.data());
    glBindVertexArray(empty_vertex_array_.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
  }
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("seed blur pass");
}

}  // namespace arpipe
