// Reads a float-renderable texture back to the CPU for the render tests: RGBA as floats, image
// row v first at index v (GL rows are image rows in this project).
#pragma once

#include <GLES3/gl3.h>

#include <vector>

#include "render/gl/gl_error.h"
#include "render/gl/gl_objects.h"

namespace arpipe::render_test {

inline std::vector<float> read_rgba_float(GLuint texture, int width, int height) {
  GlFramebuffer framebuffer = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  std::vector<float> pixels(size_t(width) * height * 4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, pixels.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("reading a texture back");
  return pixels;
}

}  // namespace arpipe::render_test
