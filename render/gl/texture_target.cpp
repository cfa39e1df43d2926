// A texture to draw into (see texture_target.h).
#include "render/gl/texture_target.h"

#include "render/gl/gl_error.h"

namespace arpipe {

void TextureTarget::ensure(GLenum color_format, int width, int height, bool with_depth) {
  if (texture_ && color_format == format_ && width == width_ && height == height_ && with_depth == with_depth_) return;
  texture_ = create_texel_texture(color_format, width, height);
  framebuffer_ = create_framebuffer_for(texture_.get());
  depth_.reset();
  if (with_depth) {
    depth_ = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, depth_.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
  }
  check_framebuffer_complete("blur intermediate texture");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("allocating a blur intermediate texture");
  format_ = color_format;
  width_ = width;
  height_ = height;
  with_depth_ = with_depth;
  written_ = PixelRect::full(width, height);
}

void clear_written_outside(GLuint framebuffer, PixelRect& written, const PixelRect& keep) {
  if (!written.empty() && !(written == keep)) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glEnable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const GLfloat transparent[4] = {0, 0, 0, 0};
    const auto clear = [&](int x0, int y0, int x1, int y1) {
      if (x1 <= x0 || y1 <= y0) return;
      glScissor(x0, y0, x1 - x0, y1 - y0);
      glClearBufferfv(GL_COLOR, 0, transparent);
    };
    // Only what lies outside keep: a software rasteriser's clear costs per pixel, and from one
    // frame to the next the rectangle moves by a few pixels.
    const PixelRect both = written.intersected(keep);
    if (both.empty()) {
      clear(written.x, written.y, written.right(), written.bottom());
    } else {
      clear(written.x, written.y, written.right(), both.y);                 // the rows above
      clear(written.x, both.bottom(), written.right(), written.bottom());   // the rows below
      clear(written.x, both.y, both.x, both.bottom());                      // left, beside keep
      clear(both.right(), both.y, written.right(), both.bottom());          // right, beside keep
    }
  }
  written = keep;
}

void TextureTarget::clear_outside(const PixelRect& keep) { clear_written_outside(framebuffer_.get(), written_, keep); }

void TextureTarget::begin(const PixelRect& rect) {
  clear_outside(rect);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  glViewport(0, 0, width_, height_);
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect.x, rect.y, rect.width, rect.height);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  const GLfloat transparent[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, transparent);
  if (with_depth_) {
    glDepthMask(GL_TRUE);
    const GLfloat far_depth = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
  }
}

void TextureTarget::copy_from(GLuint read_framebuffer, const PixelRect& rect) {
  clear_outside(rect);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, read_framebuffer);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer_.get());
  glDisable(GL_SCISSOR_TEST);
  glBlitFramebuffer(rect.x, rect.y, rect.right(), rect.bottom(), rect.x, rect.y, rect.right(), rect.bottom(),
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace arpipe
