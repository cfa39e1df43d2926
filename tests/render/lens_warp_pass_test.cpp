// Tests of the lens warp's GL pass: a canvas whose texels hold their own coordinates, warped,
// must give every lens pixel its map value (orientation, pixel centres and bilinear sampling all
// checked at once), only inside the rectangle asked for; and the pass's cost at 640x480.
#include "render/lens/lens_warp_pass.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <iostream>

#include "render/gl/egl_context.h"
#include "render/gl/gl_error.h"
#include "tests/render/gl_readback.h"

namespace arpipe {
namespace {

constexpr int kWidth = 640, kHeight = 480;

CameraModel strong_opencv8() {
  return CameraModel("LENSMODEL_OPENCV8",
                     {400, 400, 322.3, 236.8, -0.30, 0.10, 0.001, -0.0008, -0.01, 0.0, 0.0, 0.0}, kWidth, kHeight);
}

const std::shared_ptr<const LensWarpMap>& strong_map() {
  static const auto map = std::make_shared<const LensWarpMap>(strong_opencv8());
  return map;
}

EglContext& context() {
  static EglContext instance(EglPlatformRequest::Auto);
  return instance;
}

// An RGBA32F canvas texel (i, j) = (i + offset, j + offset, 0, 1): texel i is centred on canvas
// coordinate i, so bilinear sampling at c returns c (+ offset) exactly, a linear function.
GlTexture coordinate_canvas(const PinholeCanvas& canvas, float offset) {
  std::vector<float> texels(size_t(canvas.width) * canvas.height * 4);
  for (int j = 0; j < canvas.height; ++j)
    for (int i = 0; i < canvas.width; ++i) {
      float* t = texels.data() + (size_t(j) * canvas.width + i) * 4;
      t[0] = float(i) + offset, t[1] = float(j) + offset, t[2] = 0, t[3] = 1;
    }
  GlTexture texture = create_texel_texture(GL_RGBA32F, canvas.width, canvas.height);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, canvas.width, canvas.height, GL_RGBA, GL_FLOAT, texels.data());
  return texture;
}

bool float_targets_available() {
  // Rendering to RGBA32F and filtering it are extensions in GLES 3.0 (llvmpipe has both).
  return context().has_gl_extension("GL_EXT_color_buffer_float") &&
         context().has_gl_extension("GL_OES_texture_float_linear");
}

TEST(LensWarpPass, EveryPixelSamplesTheCanvasWhereTheMapPoints) {
  context().make_current();
  if (!float_targets_available()) GTEST_SKIP() << "no float render targets / float filtering";
  const LensWarpMap& map = *strong_map();
  LensWarpPass pass(GL_RGBA32F);
  pass.set_map(strong_map());
  GlTexture first = coordinate_canvas(map.canvas(), 0.0f);
  GlTexture second = coordinate_canvas(map.canvas(), 1000.0f);
  pass.run(first.get(), PixelRect::full(kWidth, kHeight));
  const PixelRect rect{37, 411, 250, 69};  // reaching the bottom-left corner
  pass.run(second.get(), rect);
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  double worst = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const float* p = out.data() + (size_t(y) * kWidth + x) * 4;
      const double offset = rect.contains(x, y) ? 1000.0 : 0.0;
      const Vec2 expected = map.at(x, y);
      const double error = std::hypot(p[0] - offset - expected[0], p[1] - offset - expected[1]);
      worst = std::max(worst, error);
      // 0.01 canvas px: GL's bilinear weights carry at least 8 fractional bits (llvmpipe: 8),
      // so interpolating a linear ramp errs by under 1/256 texel; a half-texel slip is 0.5.
      ASSERT_LT(error, 0.01) << "pixel (" << x << ", " << y << ") = (" << p[0] << ", " << p[1] << "), map ("
                             << expected[0] << ", " << expected[1] << ")";
      ASSERT_EQ(p[3], 1.0f);
    }
  std::cout << "warp vs map: max " << worst << " canvas px\n";
}

TEST(LensWarpPass, CostPerFrameAt640x480) {
  context().make_current();
  const LensWarpMap& map = *strong_map();
  // The virtual layer's own format where the context renders half floats (VirtualLayer).
  const GLenum format = context().has_gl_extension("GL_EXT_color_buffer_half_float") ||
                                context().has_gl_extension("GL_EXT_color_buffer_float")
                            ? GL_RGBA16F
                            : GL_SRGB8_ALPHA8;
  GlTexture canvas = create_texel_texture(format, map.canvas().width, map.canvas().height);
  LensWarpPass pass(format);
  pass.set_map(strong_map());
  std::vector<double> ms;
  for (int run = 0; run < 25; ++run) {
    const auto start = std::chrono::steady_clock::now();
    pass.run(canvas.get(), PixelRect::full(kWidth, kHeight));
    glFinish();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  ms.erase(ms.begin(), ms.begin() + 5);  // the first runs compile the shader (llvmpipe JIT)
  std::sort(ms.begin(), ms.end());
  std::cout << "lens warp pass, whole 640x480 image, " << context().gl_renderer() << ": median " << ms[ms.size() / 2]
            << " ms, min " << ms.front() << " ms\n";
  RecordProperty("warp_pass_median_ms", std::to_string(ms[ms.size() / 2]));
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

}  // namespace
}  // namespace arpipe
