// The GL pass of render.lens = "map": samples the pinhole canvas (linear, premultiplied) bilinearly
// where a LensWarpMap points, giving the virtual layer as the real lens sees it.
#include "render/lens/lens_warp_pass.h"

#include "render/gl/fullscreen_triangle.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// GL rows are image rows in the map, the canvas and the output (lens_projection.h). Canvas
// coordinates put texel centres on integers (mrcal's convention); GL's are at +0.5. Premultiplied
// colour interpolates correctly, and an sRGB canvas is decoded before filtering.
// kTaps x kTaps bilinear taps spread evenly over the pixel's footprint on the canvas (the map's
// steps to the neighbouring pixels span it): an area average, as a sensor pixel takes,
// rather than the canvas's value at one point, which aliases once the canvas is finer than the
// image (render.lens_canvas_scale > 1). 2 x 2 taps cover a footprint of up to 4 texels a side
// (each bilinear tap spans two), all that kMaxCanvasScale makes; measured: 1 tap at scale 2 moves
// small shapes twice as far.
constexpr std::string_view kLensWarpFragmentShader = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_canvas;
uniform highp sampler2D u_map;
uniform vec2 u_canvas_size;
out vec4 out_color;

const int kTaps = 2;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  ivec2 last = textureSize(u_map, 0) - 1;
  vec2 canvas_xy = texelFetch(u_map, pixel, 0).xy;
  // The step to the next pixel (from the previous one on the last column or row).
  int dx = pixel.x < last.x ? 1 : -1, dy = pixel.y < last.y ? 1 : -1;
  vec2 along_x = float(dx) * (texelFetch(u_map, pixel + ivec2(dx, 0), 0).xy - canvas_xy);
  vec2 along_y = float(dy) * (texelFetch(u_map, pixel + ivec2(0, dy), 0).xy - canvas_xy);
  vec4 sum = vec4(0.0);
  for (int j = 0; j < kTaps; ++j)
    for (int i = 0; i < kTaps; ++i) {
      vec2 offset = (vec2(float(i), float(j)) + 0.5) / float(kTaps) - 0.5;
      vec2 at = canvas_xy + offset.x * along_x + offset.y * along_y;
      sum += texture(u_canvas, (at + 0.5) / u_canvas_size);
    }
  out_color = sum / float(kTaps * kTaps);
}
)glsl";

}  // namespace

LensWarpPass::LensWarpPass(GLenum output_format)
    : output_format_(output_format),
      program_("lens warp", kFullScreenTriangleVertexShader, kLensWarpFragmentShader),
      empty_vertex_array_(GlVertexArray::create()) {
  glUseProgram(program_.id());
  glUniform1i(program_.uniform("u_canvas"), 0);
  glUniform1i(program_.uniform("u_map"), 1);
}

void LensWarpPass::set_map(std::shared_ptr<const LensWarpMap> map) {
  if (map == map_) return;
  if (!map || map->identity()) throw RenderError("the lens warp pass needs a map that is not the identity");
  const int width = map->width(), height = map->height();
  map_texture_ = create_texel_texture(GL_RG32F, width, height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RG, GL_FLOAT, map->canvas_xy().data());
  output_texture_ = create_texel_texture(output_format_, width, height);  // the composite stage texelFetches it
  output_framebuffer_ = create_framebuffer_for(output_texture_.get());
  check_framebuffer_complete("lens warp output");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("uploading the lens warp map");
  map_ = std::move(map);
}

void LensWarpPass::run(GLuint canvas_texture, const PixelRect& rect) {
  if (!map_) throw RenderError("the lens warp pass has no map");
  const PinholeCanvas& canvas = map_->canvas();
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, map_texture_.get());
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, canvas_texture);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_.get());
  glViewport(0, 0, map_->width(), map_->height());
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect.x, rect.y, rect.width, rect.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glUseProgram(program_.id());
  glUniform2f(program_.uniform("u_canvas_size"), static_cast<float>(canvas.width), static_cast<float>(canvas.height));
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("warping the virtual layer to the lens");
}

}  // namespace arpipe
