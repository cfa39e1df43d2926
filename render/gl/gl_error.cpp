// Turning GL's error flag and framebuffer status into RenderError exceptions with a readable name.
#include "render/gl/gl_error.h"

#include <fmt/format.h>

#include "render/gl/render_errors.h"

namespace arpipe {

std::string gl_error_name(GLenum error) {
  switch (error) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return fmt::format("GL error 0x{:04x}", error);
  }
}

void check_gl(std::string_view where) {
  const GLenum error = glGetError();
  if (error == GL_NO_ERROR) return;
  // GL can queue several flags; drain them so the next check reports only new ones.
  while (glGetError() != GL_NO_ERROR) {
  }
  throw RenderError(fmt::format("{}: {}", where, gl_error_name(error)));
}

void check_framebuffer_complete(std::string_view what) {
  const GLenum status = glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  if (status == GL_FRAMEBUFFER_COMPLETE) return;
  std::string name;
  switch (status) {
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: name = "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT"; break;
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: name = "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT"; break;
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: name = "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE"; break;
    case GL_FRAMEBUFFER_UNSUPPORTED: name = "GL_FRAMEBUFFER_UNSUPPORTED"; break;
    default: name = fmt::format("status 0x{:04x}", status); break;
  }
  throw RenderError(fmt::format("{}: framebuffer incomplete ({})", what, name));
}

}  // namespace arpipe
