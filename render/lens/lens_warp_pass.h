// The GL pass of render.lens = "map": samples the pinhole canvas (linear, premultiplied) bilinearly
// where a LensWarpMap points, giving the virtual layer as the real lens sees it.
#pragma once

#include <GLES3/gl3.h>

#include <memory>

#include "render/gl/gl_objects.h"
#include "render/gl/gl_program.h"
#include "render/lens/lens_warp_map.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

class LensWarpPass {
 public:
  // output_format: a colour-renderable format for the warped layer (the virtual layer's own).
  // Compiles the shader; needs a current context. Throws RenderError.
  explicit LensWarpPass(GLenum output_format);

  // Uploads the map (one RG32F texel per lens pixel) and allocates the output at the lens image's
  // size, unless this map is already the current one. The map must not be the identity.
  void set_map(std::shared_ptr<const LensWarpMap> map);
  // Fills `rect` (lens image pixels) of texture() from canvas_texture, a texture of the map's
  // canvas size whose filter this sets to linear. The rest of texture() is left as it was.
  void run(GLuint canvas_texture, const PixelRect& rect);

  GLuint texture() const { return output_texture_.get(); }
  const LensWarpMap* map() const { return map_.get(); }

 private:
  GLenum output_format_;
  GlProgram program_;
  GlVertexArray empty_vertex_array_;
  std::shared_ptr<const LensWarpMap> map_;
  GlTexture map_texture_;
  GlTexture output_texture_;
  GlFramebuffer output_framebuffer_;
};

}  // namespace arpipe
