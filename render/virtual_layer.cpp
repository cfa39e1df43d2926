// The off-screen image that the render stage draws virtual objects into: linear, premultiplied
// alpha, at the camera's size, multisampled when asked and resolved into a texture to composite.
#include "render/virtual_layer.h"

#include <algorithm>

#include "core/log.h"
#include "render/gl/gl_error.h"
#include "render/gl/texture_target.h"

namespace arpipe {

VirtualLayer::VirtualLayer(const EglContext& context)
    : color_format_(context.has_gl_extension("GL_EXT_color_buffer_float") ||
                            context.has_gl_extension("GL_EXT_color_buffer_half_float")
                        ? GL_RGBA16F
                        : GL_SRGB8_ALPHA8) {
  GLint max_samples = 1;
  glGetInternalformativ(GL_RENDERBUFFER, color_format_, GL_SAMPLES, 1, &max_samples);  // the list starts with the largest
  if (glGetError() != GL_NO_ERROR) max_samples = 1;
  max_samples_ = std::max(1, static_cast<int>(max_samples));
}

void VirtualLayer::ensure(int width, int height, int msaa_samples) {
  if (width == width_ && height == height_ && msaa_samples == requested_samples_) return;
  const int samples = std::clamp(msaa_samples, 1, max_samples_);
  if (msaa_samples > max_samples_)
    log::warn("render: msaa_samples = {} is more than this GL supports for the virtual layer; using {}", msaa_samples,
              max_samples_);

  resolved_texture_ = create_texel_texture(color_format_, width, height);  // the composite stage texelFetches it
  resolved_framebuffer_ = create_framebuffer_for(resolved_texture_.get());
  check_framebuffer_complete("virtual layer (resolved)");

  depth_ = GlRenderbuffer::create();
  glBindRenderbuffer(GL_RENDERBUFFER, depth_.get());
  draw_framebuffer_ = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_.get());
  if (samples > 1) {
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    multisample_color_ = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, multisample_color_.get());
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, color_format_, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, multisample_color_.get());
  } else {
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    multisample_color_.reset();
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolved_texture_.get(), 0);
  }
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
  check_framebuffer_complete("virtual layer (drawing)");
  check_gl("allocating the virtual layer");

  width_ = width;
  height_ = height;
  requested_samples_ = msaa_samples;
  samples_ = samples;
  resolved_written_ = PixelRect::full(width, height);
}

void VirtualLayer::begin(const PixelRect& rect) {
  const GLfloat transparent[4] = {0, 0, 0, 0};
  glEnable(GL_SCISSOR_TEST);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  clear_written_outside(resolved_framebuffer_.get(), resolved_written_, rect);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_.get());
  glViewport(0, 0, width_, height_);
  // GL rows are image rows (see lens_projection.h), so the rectangle needs no flip.
  glScissor(rect.x, rect.y, rect.width, rect.height);
  glDepthMask(GL_TRUE);
  glClearBufferfv(GL_COLOR, 0, transparent);
  const GLfloat far_depth = 1.0f;
  glClearBufferfv(GL_DEPTH, 0, &far_depth);
}

void VirtualLayer::resolve(const PixelRect& rect) {
  if (samples_ <= 1) return;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved_framebuffer_.get());
  // A multisample resolve must copy to the identical rectangle.
  glBlitFramebuffer(rect.x, rect.y, rect.right(), rect.bottom(), rect.x, rect.y, rect.right(), rect.bottom(),
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace arpipe
