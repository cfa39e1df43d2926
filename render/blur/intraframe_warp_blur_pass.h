// Seed 000's composite (the thesis's Algorithm 2, in closed form): every blur sample is one of the
// two rendered intraframes, or a cross-fade of both, seen through its affine warp; the output is
// their premultiplied average. With a static background that average composited "over" the camera
// frame is exactly the thesis's coverage-count rule (full coverage: the mean colour; partial: a
// lerp towards the camera pixel by the covered fraction; none: the camera pixel).
#pragma once

#include <GLES3/gl3.h>

#include "core/motion/intraframe_warp_plan.h"
#include "render/gl/gl_objects.h"
#include "render/gl/gl_program.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

class IntraframeWarpBlurPass {
 public:
  static constexpr int kMaxSamples = kMaxInterframes + 2;

  // output_format: colour-renderable (the virtual layer's own). Compiles the shader; needs a
  // current context. Throws RenderError.
  explicit IntraframeWarpBlurPass(GLenum output_format);

  // Fills `rect` of texture() (width x height, allocated on first use or when the size changes)
  // with the premultiplied mean over plan.samples of
  //   weight_first * first(first_from_output(p)) + weight_second * second(second_from_output(p)),
  // p = the output pixel's centre in pixel coordinates (centres at integers, as mrcal's). first
  // and second are width x height premultiplied linear textures (this sets their filter to
  // linear); samples falling outside them read transparent black. The rest of texture() is left
  // as it was. Throws RenderError for more than kMaxSamples samples; an empty plan clears rect.
  void run(GLuint first, GLuint second, int width, int height, const IntraframeWarpPlan& plan, const PixelRect& rect);

  GLuint texture() const { return output_texture_.get(); }

 private:
  GLenum output_format_;
  GlProgram program_;
  GlVertexArray empty_vertex_array_;
  GlTexture output_texture_;
  GlFramebuffer output_framebuffer_;
  int width_ = 0;
  int height_ = 0;
};

}  // namespace arpipe
