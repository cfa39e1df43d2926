// The off-screen image that the render stage draws virtual objects into: linear, premultiplied
// alpha, at the camera's size, multisampled when asked and resolved into a texture to composite.
#pragma once

#include "render/gl/egl_context.h"
#include "render/gl/gl_objects.h"
#include "core/image/pixel_rect.h"
#include "render/work_area.h"

namespace arpipe {

class VirtualLayer {
 public:
  // Chooses the colour format: GL_RGBA16F where the context can render to half floats, else
  // GL_SRGB8_ALPHA8 (8 bits but sRGB-encoded, so dark linear values keep their precision).
  explicit VirtualLayer(const EglContext& context);

  // (Re)allocates when the size or sample count changes; samples <= 1 means no multisampling, and
  // a count above what the format supports is lowered to that (with a warning).
  void ensure(int width, int height, int msaa_samples);
  // Binds the framebuffer to draw into with viewport = whole image, scissor = rect (left enabled),
  // and clears the rect to transparent black and far depth. What earlier frames resolved outside
  // rect is cleared too, so texture() is transparent everywhere but rect (the blur passes sample
  // beyond it).
  void begin(const PixelRect& rect);
  // Makes what was drawn inside rect available in texture().
  void resolve(const PixelRect& rect);

  // For objects drawn apart from what follows them (the ground catcher): binds a multisampled
  // image of `area` alone (work_area.h), cleared whole, to draw into with viewport = the canvas
  // placed so that canvas pixel (area.x, area.y) lands on its texel (0, 0), scissor = objects_rect
  // (canvas pixels, within area) seen there. Needs samples() > 1.
  void begin_objects(const WorkArea& area, const PixelRect& objects_rect);
  // Resolves what was drawn since begin_objects, copies it to its place in texture(), and clears
  // the rest of texture() inside rect (and what earlier frames left outside it, as begin).
  void resolve_objects(const PixelRect& rect);
  // Binds texture()'s framebuffer to draw into, viewport = whole image, scissor = rect.
  void begin_resolved(const PixelRect& rect);

  GLuint texture() const { return resolved_texture_.get(); }
  GLuint resolved_framebuffer() const { return resolved_framebuffer_.get(); }  // texture()'s
  GLenum color_format() const { return color_format_; }
  int samples() const { return samples_; }  // 1 when not multisampled
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  GLenum color_format_;
  int max_samples_ = 1;
  int width_ = 0;
  int height_ = 0;
  int requested_samples_ = -1;
  int samples_ = 1;
  GlTexture resolved_texture_;
  GlFramebuffer resolved_framebuffer_;
  GlRenderbuffer multisample_color_;
  GlRenderbuffer depth_;
  GlFramebuffer draw_framebuffer_;
  // The objects' image over a work area: multisampled colour and depth, and its resolve.
  void ensure_objects_image(int width, int height);
  int objects_width_ = 0;
  int objects_height_ = 0;
  GlRenderbuffer objects_color_;
  GlRenderbuffer objects_depth_;
  GlFramebuffer objects_framebuffer_;
  GlTexture objects_resolved_;
  GlFramebuffer objects_resolved_framebuffer_;
  WorkArea objects_area_;
  PixelRect objects_rect_;
  PixelRect resolved_written_;  // what texture() may hold: all of it after allocation  // the multisampled one, or resolved_framebuffer_'s twin with depth
};

}  // namespace arpipe
