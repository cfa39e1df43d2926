// Turning GL's error flag and framebuffer status into RenderError exceptions with a readable name.
#pragma once

#include <GLES3/gl3.h>

#include <string>
#include <string_view>

namespace arpipe {

std::string gl_error_name(GLenum error);
// Throws RenderError naming `where` and the GL error when the error flag is set (and clears it).
void check_gl(std::string_view where);
// Throws RenderError naming `what` when the bound draw framebuffer is incomplete.
void check_framebuffer_complete(std::string_view what);

}  // namespace arpipe
