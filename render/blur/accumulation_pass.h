// The "accumulate" blur's running sum: textures added with a weight into a float target, so that
// N renders spread over the exposure average into one premultiplied image.
#pragma once

#include <GLES3/gl3.h>

#include "render/gl/egl_context.h"
#include "render/gl/gl_objects.h"
#include "render/gl/gl_program.h"
#include "core/image/pixel_rect.h"
#include "render/gl/texture_target.h"

namespace arpipe {

class AccumulationPass {
 public:
  // Sums in RGBA32F where the context can render to, blend and filter it (hundreds of samples of
  // weight 1/N lose nothing), else RGBA16F (about 3 decimal digits: enough for tens of samples).
  // Compiles the shader; needs a current context. Throws RenderError.
  explicit AccumulationPass(const EglContext& context);

  // Allocates width x height (when changed) and clears rect to zero.
  void begin(int width, int height, const PixelRect& rect);
  // Adds weight x texture (same size, texel for texel) inside rect.
  void add(GLuint texture, const PixelRect& rect, float weight);

  GLuint texture() const { return sum_.texture(); }
  GLenum format() const { return format_; }

 private:
  GLenum format_;
  GlProgram program_;
  GlVertexArray empty_vertex_array_;
  TextureTarget sum_;
};

}  // namespace arpipe
