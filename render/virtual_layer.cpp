// The off-screen image that the render stage draws virtual objects into: linear, premultiplied
// alpha, at the camera's size, multisampled when asked and resolved into a texture to composite.
#include "render/virtual_layer.h"

#include <algorithm>

#include "core/log.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"
#include "render/gl/texture_target.h"

namespace arpipe {
namespace {

GlRenderbuffer multisample_storage(GLenum format, int samples, int width, int height) {
  GlRenderbuffer buffer = GlRenderbuffer::create();
  glBindRenderbuffer(GL_RENDERBUFFER, buffer.get());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
  return buffer;
}

// The bound framebuffer (within the scissor, when on) to transparent black and far depth.
void clear_to_transparent_and_far() {
  const GLfloat transparent[4] = {0, 0, 0, 0};
  const GLfloat far_depth = 1.0f;
  glDepthMask(GL_TRUE);
  glClearBufferfv(GL_COLOR, 0, transparent);
  glClearBufferfv(GL_DEPTH, 0, &far_depth);
}

}  // namespace

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

  draw_framebuffer_ = GlFramebuffer::create();
  if (samples > 1) {
    depth_ = multisample_storage(GL_DEPTH_COMPONENT24, samples, width, height);
    multisample_color_ = multisample_storage(color_format_, samples, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_.get());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, multisample_color_.get());
  } else {
    depth_ = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, depth_.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    multisample_color_.reset();
    glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolved_texture_.get(), 0);
  }
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
  check_framebuffer_complete("virtual layer (drawing)");
  check_gl("allocating the virtual layer");

  width_ = width;
  height_ = height;
  requested_samples_ = msaa_samples;
  samples_ = samples;
  objects_width_ = objects_height_ = 0;  // the objects' image follows the sample count
  resolved_written_ = PixelRect::full(width, height);
}

void VirtualLayer::begin(const PixelRect& rect) {
  glEnable(GL_SCISSOR_TEST);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  clear_written_outside(resolved_framebuffer_.get(), resolved_written_, rect);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_.get());
  glViewport(0, 0, width_, height_);
  // GL rows are image rows (see lens_projection.h), so the rectangle needs no flip.
  glScissor(rect.x, rect.y, rect.width, rect.height);
  clear_to_transparent_and_far();
}

void VirtualLayer::ensure_objects_image(int width, int height) {
  if (width == objects_width_ && height == objects_height_ && objects_framebuffer_.get() != 0) return;
  objects_color_ = multisample_storage(color_format_, samples_, width, height);
  objects_depth_ = multisample_storage(GL_DEPTH_COMPONENT24, samples_, width, height);
  objects_framebuffer_ = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, objects_framebuffer_.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, objects_color_.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, objects_depth_.get());
  check_framebuffer_complete("virtual layer (the objects' image)");
  objects_resolved_ = create_texel_texture(color_format_, width, height);
  objects_resolved_framebuffer_ = create_framebuffer_for(objects_resolved_.get());
  check_framebuffer_complete("virtual layer (the objects' image, resolved)");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("allocating the objects' image");
  objects_width_ = width;
  objects_height_ = height;
}

void VirtualLayer::begin_objects(const WorkArea& area, const PixelRect& objects_rect) {
  if (samples_ <= 1) throw RenderError("the objects' own image needs multisampling");
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  ensure_objects_image(area.width, area.height);
  objects_area_ = area;
  objects_rect_ = objects_rect;
  glBindFramebuffer(GL_FRAMEBUFFER, objects_framebuffer_.get());
  glDisable(GL_SCISSOR_TEST);  // a whole clear: see work_area.h
  clear_to_transparent_and_far();
  glViewport(-area.x, -area.y, width_, height_);
  const PixelRect local = area.local(objects_rect);
  glEnable(GL_SCISSOR_TEST);
  glScissor(local.x, local.y, local.width, local.height);
}

void VirtualLayer::resolve_objects(const PixelRect& rect) {
  const PixelRect local = objects_area_.local(objects_rect_);
  const PixelRect& to = objects_rect_;
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, objects_framebuffer_.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, objects_resolved_framebuffer_.get());
  glBlitFramebuffer(local.x, local.y, local.right(), local.bottom(), local.x, local.y, local.right(), local.bottom(),
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  // A plain copy to its place (a multisample resolve may not move it).
  glBindFramebuffer(GL_READ_FRAMEBUFFER, objects_resolved_framebuffer_.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved_framebuffer_.get());
  glBlitFramebuffer(local.x, local.y, local.right(), local.bottom(), to.x, to.y, to.right(), to.bottom(),
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  // The rest of the layer's rectangle, and what earlier frames left outside it, cleared after the
  // copy rather than before: the clears then join what is drawn there next (the catcher) in one
  // pass of a software rasteriser over its tiles, instead of a pass of their own.
  clear_written_outside(resolved_framebuffer_.get(), resolved_written_, rect);
  PixelRect around_objects = rect;
  clear_written_outside(resolved_framebuffer_.get(), around_objects, to);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void VirtualLayer::begin_resolved(const PixelRect& rect) {
  glBindFramebuffer(GL_FRAMEBUFFER, resolved_framebuffer_.get());
  glViewport(0, 0, width_, height_);
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect.x, rect.y, rect.width, rect.height);
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
