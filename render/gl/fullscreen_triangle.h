// The vertex shader of the full-image passes (composite, lens warp): one triangle that covers the
// whole viewport, drawn with glDrawArrays(GL_TRIANGLES, 0, 3) and no vertex buffer; a scissor
// rectangle limits it to the part of the image that needs work.
#pragma once

#include <string_view>

namespace arpipe {

inline constexpr std::string_view kFullScreenTriangleVertexShader = R"glsl(#version 300 es
void main() {
  vec2 corner = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
  gl_Position = vec4(corner - 1.0, 0.0, 1.0);
}
)glsl";

}  // namespace arpipe
