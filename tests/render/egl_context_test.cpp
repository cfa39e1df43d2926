// Tests of the headless EGL context: each platform this EGL offers comes up with a GLES 3 context,
// and a request that cannot be met fails with a message saying what was tried.
#include "render/gl/egl_context.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include "core/config/config.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

void expect_working_gles3(const EglContext& context) {
  EXPECT_TRUE(context.is_current());
  EXPECT_FALSE(context.gl_renderer().empty());
  EXPECT_NE(context.gl_version().find("OpenGL ES 3"), std::string::npos) << context.gl_version();
  // The context really renders: clear an FBO and read the colour back.
  GLuint texture = 0, framebuffer = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 4, 4);
  glGenFramebuffers(1, &framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
  glClearColor(1.0f, 0.0f, 1.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  unsigned char pixel[4] = {};
  glReadPixels(1, 2, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
  EXPECT_EQ(pixel[0], 255);
  EXPECT_EQ(pixel[1], 0);
  EXPECT_EQ(pixel[2], 255);
  EXPECT_EQ(pixel[3], 255);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  glDeleteFramebuffers(1, &framebuffer);
  glDeleteTextures(1, &texture);
}

TEST(EglContext, SurfacelessPlatformComesUp) {
  if (!EglContext::platform_available(EglPlatform::Surfaceless)) GTEST_SKIP() << "no EGL_MESA_platform_surfaceless";
  EglContext context(EglPlatformRequest::Surfaceless);
  EXPECT_EQ(context.platform(), EglPlatform::Surfaceless);
  std::cout << "surfaceless: GL_RENDERER = " << context.gl_renderer() << ", GL_VERSION = " << context.gl_version() << "\n";
  expect_working_gles3(context);
}

TEST(EglContext, DevicePlatformComesUp) {
  if (!EglContext::platform_available(EglPlatform::Device)) GTEST_SKIP() << "no EGL device";
  EglContext context(EglPlatformRequest::Device);
  EXPECT_EQ(context.platform(), EglPlatform::Device);
  EXPECT_FALSE(context.device_description().empty());
  std::cout << "device (" << context.device_description() << "): GL_RENDERER = " << context.gl_renderer() << "\n";
  expect_working_gles3(context);
}

TEST(EglContext, AutoPrefersADevice) {
  EglContext context(EglPlatformRequest::Auto);
  const EglPlatform expected =
      EglContext::platform_available(EglPlatform::Device) ? EglPlatform::Device : EglPlatform::Surfaceless;
  EXPECT_EQ(context.platform(), expected);
  expect_working_gles3(context);
}

TEST(EglContext, TwoContextsOnOnePlatformLiveAndDieIndependently) {
  // Both share the EGL display; destroying one must not terminate the display under the other.
  auto first = std::make_unique<EglContext>(EglPlatformRequest::Auto);
  EglContext second(EglPlatformRequest::Auto);
  first.reset();
  second.make_current();
  expect_working_gles3(second);
}

// The name is checked where the config is read (render.egl_platform); the context takes the enum.
TEST(EglContext, UnknownPlatformNameIsRejected) {
  try {
    parse_config("[render]\negl_platform = \"wayland\"\n", "egl.toml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("\"wayland\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("surfaceless"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arpipe
