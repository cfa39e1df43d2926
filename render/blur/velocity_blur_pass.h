// The fast blur option: one render of the object at mid-exposure plus a per-pixel screen velocity,
// gathered along the dominant local velocity (in the style of McGuire, Hennessy, Bukowski and
// Osman, "A reconstruction filter for plausible motion blur", I3D 2012: tile maximum, neighbour
// maximum, then a gather whose weights say whether a sample's surface sweeps over the pixel).
// Unlike that paper the background here is not in the image: the layer is composited over the
// camera frame later, so uncovered time is transparent rather than renormalised away.
#pragma once

#include <GLES3/gl3.h>

#include "render/gl/gl_objects.h"
#include "render/gl/gl_program.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

class VelocityBlurPass {
 public:
  static constexpr int kMaxSamples = 64;

  // output_format: colour-renderable (the virtual layer's own). Compiles the shaders; needs a
  // current context. Throws RenderError.
  explicit VelocityBlurPass(GLenum output_format);

  // color: width x height, premultiplied linear, the object at mid-exposure.
  // velocity: width x height RGBA16F: rg = how far that pixel's surface point moves in the image
  //   over the whole exposure (end minus start, pixels, +x right, +y down), b = its camera depth
  //   (m, > 0), a = 1 where the object covers the pixel; all zero elsewhere.
  // rect: the pixels that can receive blur (the sharp footprint grown by half the largest motion,
  //   clipped to the image); the rest of texture() is left as it was.
  // samples: taps of the gather, clamped to [2, kMaxSamples].
  // Result in texture(): premultiplied, the time average over the exposure of the moving layer.
  void run(GLuint color, GLuint velocity, int width, int height, const PixelRect& rect, int samples);

  GLuint texture() const { return output_texture_.get(); }

 private:
  using GlSampler = GlObject<glGenSamplers, glDeleteSamplers>;

  void ensure_targets(int width, int height);

  GLenum output_format_;
  // Bilinear, clamped reads of color and velocity in the gather, without touching the caller's
  // texture state.
  GlSampler linear_sampler_;
  GlProgram tile_max_program_;
  GlProgram neighbour_max_program_;
  GlProgram gather_program_;
  GlVertexArray empty_vertex_array_;
  GlTexture tile_max_texture_;
  GlFramebuffer tile_max_framebuffer_;
  GlTexture neighbour_max_texture_;
  GlFramebuffer neighbour_max_framebuffer_;
  GlTexture output_texture_;
  GlFramebuffer output_framebuffer_;
  int width_ = 0;
  int height_ = 0;
  int tiles_x_ = 0;
  int tiles_y_ = 0;
};

}  // namespace arpipe
