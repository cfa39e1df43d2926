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

// Per sample: the two warps output -> intraframe, already turned into gl_FragCoord -> texture
// coordinates (so the shader does one dot product per coordinate), packed into 3 vec4s
//   [fx0 fx1 fx2 fy0] [fy1 fy2 sx0 sx1] [sx2 sy0 sy1 sy2]   (f: first, s: second; u = dot(x*, (fc, 1)))
// and the weights two samples to a vec4: 3 * 50 + 25 = 175 uniform vectors, within GLES 3.0's
// guaranteed 224 (GL_MAX_FRAGMENT_UNIFORM_VECTORS). The bounds test on the texture coordinate
// ([0, 1] = pixel coordinates [-0.5, size - 0.5]) stands in for clamp-to-border, which GLES 3.0
// lacks: the edge half-texel reads the edge texel, beyond it reads transparent black.
constexpr std::string_view kFragmentShaderTemplate = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_first;
uniform highp sampler2D u_second;
uniform int u_count;
uniform vec4 u_maps[{maps}];
uniform vec4 u_weights[{weights}];
out vec4 out_color;

vec4 sample_inside(highp sampler2D image, vec2 uv) {{
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return vec4(0.0);
  return texture(image, uv);
}}

void main() {{
  vec3 at = vec3(gl_FragCoord.xy, 1.0);
  vec4 sum = vec4(0.0);
  for (int i = 0; i < u_count; ++i) {{
    vec4 a = u_maps[3 * i], b = u_maps[3 * i + 1], c = u_maps[3 * i + 2];
    vec4 w4 = u_weights[i / 2];
    vec2 w = (i % 2 == 0) ? w4.xy : w4.zw;
    if (w.x != 0.0) sum += w.x * sample_inside(u_first, vec2(dot(a.xyz, at), dot(vec3(a.w, b.xy), at)));
    if (w.y != 0.0) sum += w.y * sample_inside(u_second, vec2(dot(vec3(b.zw, c.x), at), dot(c.yzw, at)));
  }}
  out_color = sum / float(u_count);
}}
)glsl";

std::string fragment_shader() {
  return fmt::format(kFragmentShaderTemplate, fmt::arg("maps", 3 * IntraframeWarpBlurPass::kMaxSamples),
                     fmt::arg("weights", (IntraframeWarpBlurPass::kMaxSamples + 1) / 2));
}

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
    std::vector<float> maps(size_t(12 * count)), weights(size_t(4 * ((count + 1) / 2)), 0.0f);
    for (int i = 0; i < count; ++i) {
      const IntraframeWarpSample& sample = plan.samples[size_t(i)];
      const std::array<float, 6> to_first = fragcoord_to_uv(sample.first_from_output, width, height);
      const std::array<float, 6> to_second = fragcoord_to_uv(sample.second_from_output, width, height);
      std::copy(to_first.begin(), to_first.end(), maps.begin() + 12 * i);
      std::copy(to_second.begin(), to_second.end(), maps.begin() + 12 * i + 6);
      weights[size_t(2 * i)] = float(sample.weight_first);
      weights[size_t(2 * i + 1)] = float(sample.weight_second);
    }
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
    glUniform1i(program_.uniform("u_count"), count);
    glUniform4fv(program_.uniform("u_maps"), 3 * count, maps.data());
    glUniform4fv(program_.uniform("u_weights"), (count + 1) / 2, weights.data());
    glBindVertexArray(empty_vertex_array_.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
  }
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("seed blur pass");
}

}  // namespace arpipe
