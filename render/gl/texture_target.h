// A texture to draw into (with an optional depth buffer): the blur methods' intermediate images
// (a copy of an intraframe, the velocity image, the accumulated average).
#pragma once

#include <GLES3/gl3.h>

#include "render/gl/gl_objects.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

// Keeps a texture transparent outside the rectangle last drawn (warped and gathered samples read
// beyond it): clears what of `written` (what `framebuffer`'s colour attachment may hold) lies
// outside `keep`, which the caller is about to cover, then records `keep` as written.
void clear_written_outside(GLuint framebuffer, PixelRect& written, const PixelRect& keep);

class TextureTarget {
 public:
  // (Re)allocates when the format, size or depth need changes; the contents are then undefined.
  void ensure(GLenum color_format, int width, int height, bool with_depth);
  // Binds the framebuffer with viewport = whole texture, scissor = rect (left enabled), and clears
  // the rect to transparent black (and far depth), together with whatever earlier frames wrote
  // outside it: the whole texture stays transparent outside rect, so passes that read beyond it
  // (warped or gathered samples) read nothing rather than old frames.
  void begin(const PixelRect& rect);
  // Copies rect of another framebuffer's colour attachment 0 (same size) into this texture,
  // after clearing what earlier frames left outside it.
  void copy_from(GLuint read_framebuffer, const PixelRect& rect);

  GLuint texture() const { return texture_.get(); }
  GLuint framebuffer() const { return framebuffer_.get(); }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void clear_outside(const PixelRect& keep);
  GLenum format_ = 0;
  int width_ = 0;
  int height_ = 0;
  bool with_depth_ = false;
  PixelRect written_;  // what may hold something: all of it after allocation
  GlTexture texture_;
  GlRenderbuffer depth_;
  GlFramebuffer framebuffer_;
};

}  // namespace arpipe
