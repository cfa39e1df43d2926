// The "accumulate" blur's running sum (see accumulation_pass.h).
#include "render/blur/accumulation_pass.h"

#include "render/gl/fullscreen_triangle.h"
#include "render/gl/gl_error.h"

namespace arpipe {
namespace {

constexpr std::string_view kAccumulateFragmentShader = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_source;
uniform float u_weight;
out vec4 out_color;

void main() { out_color = u_weight * texelFetch(u_source, ivec2(gl_FragCoord.xy), 0); }
)glsl";

GLenum sum_format(const EglContext& context) {
  const bool float32 = context.has_gl_extension("GL_EXT_color_buffer_float") &&
                       context.has_gl_extension("GL_EXT_float_blend") &&
                       context.has_gl_extension("GL_OES_texture_float_linear");
  return float32 ? GL_RGBA32F : GL_RGBA16F;
}

}  // namespace

AccumulationPass::AccumulationPass(const EglContext& context)
    : format_(sum_format(context)),
      program_("blur accumulation", kFullScreenTriangleVertexShader, kAccumulateFragmentShader),
      empty_vertex_array_(GlVertexArray::create()) {
  glUseProgram(program_.id());
  glUniform1i(program_.uniform("u_source"), 0);
}

void AccumulationPass::begin(int width, int height, const PixelRect& rect) {
  sum_.ensure(format_, width, height, false);
  sum_.begin(rect);
}

void AccumulationPass::add(GLuint texture, const PixelRect& rect, float weight) {
  glBindFramebuffer(GL_FRAMEBUFFER, sum_.framebuffer());
  glViewport(0, 0, sum_.width(), sum_.height());
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect.x, rect.y, rect.width, rect.height);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ONE);
  glUseProgram(program_.id());
  glUniform1f(program_.uniform("u_weight"), weight);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture);
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("adding a blur sample");
}

}  // namespace arpipe
