// Tests of the GLSL program helper: a shader that does not compile, a program that does not link
// and a missing uniform each throw RenderError naming the program, with the driver's log.
#include "render/gl/gl_program.h"

#include <gtest/gtest.h>

#include <functional>

#include "render/gl/egl_context.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

constexpr const char* kVertex = "#version 300 es\nin vec4 a;\nvoid main() { gl_Position = a; }\n";
constexpr const char* kFragment =
    "#version 300 es\nprecision mediump float;\nuniform vec4 u_color;\nout vec4 c;\nvoid main() { c = u_color; }\n";

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const RenderError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected RenderError";
  return {};
}

TEST(GlProgram, WorkingProgramLinksAndFindsItsUniform) {
  EglContext context(EglPlatformRequest::Auto);
  GlProgram program("good", kVertex, kFragment);
  EXPECT_NE(program.id(), 0u);
  EXPECT_GE(program.uniform("u_color"), 0);
}

TEST(GlProgram, CompileErrorNamesTheProgramStageAndDriverLog) {
  EglContext context(EglPlatformRequest::Auto);
  const std::string message = error_of([] {
    GlProgram("object shading", kVertex, "#version 300 es\nprecision mediump float;\nout vec4 c;\nvoid main() { c = undefined_thing; }\n");
  });
  EXPECT_NE(message.find("object shading fragment shader failed to compile"), std::string::npos) << message;
  // The driver's log names the offending identifier.
  EXPECT_NE(message.find("undefined_thing"), std::string::npos) << message;
}

TEST(GlProgram, LinkErrorNamesTheProgram) {
  EglContext context(EglPlatformRequest::Auto);
  // The fragment shader reads a varying that the vertex shader never writes.
  const std::string message = error_of([] {
    GlProgram("mismatched", kVertex,
              "#version 300 es\nprecision mediump float;\nin vec3 v_missing;\nout vec4 c;\nvoid main() { c = vec4(v_missing, 1.0); }\n");
  });
  EXPECT_NE(message.find("mismatched program failed to link"), std::string::npos) << message;
}

TEST(GlProgram, MissingUniformIsNamed) {
  EglContext context(EglPlatformRequest::Auto);
  GlProgram program("good", kVertex, kFragment);
  const std::string message = error_of([&] { program.uniform("u_not_there"); });
  EXPECT_NE(message.find("good program has no uniform \"u_not_there\""), std::string::npos) << message;
}

}  // namespace
}  // namespace arpipe
