// Tests of the velocity blur pass against the accumulation buffer's closed form: a solid square in
// uniform motion v, read as pixel squares, averages over the exposure to the fraction of the path
// X - v u (u in [-1/2, 1/2]) inside the square's pixel extent: ramps of length |v|. Also: no
// motion leaves the input, alpha is conserved, opposite motions, a nearer static surface hides
// what passes behind it, only rect is written; and the cost at 640x480.
#include "render/blur/velocity_blur_pass.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <vector>

#include "render/gl/egl_context.h"
#include "render/gl/gl_error.h"
#include "tests/render/gl_readback.h"

namespace arpipe {
namespace {

constexpr int kWidth = 160, kHeight = 120;
constexpr int kSamples = 16;
constexpr double kHalfFloat = 1.0 / 2048;  // relative rounding of the RGBA16F output

EglContext& context() {
  static EglContext instance(EglPlatformRequest::Auto);
  return instance;
}

bool half_float_targets() {
  return context().has_gl_extension("GL_EXT_color_buffer_half_float") ||
         context().has_gl_extension("GL_EXT_color_buffer_float");
}

using Rgba = std::array<float, 4>;

struct Square {
  int x0, x1, y0, y1;  // texels, inclusive
  Rgba color;          // premultiplied
  double vx, vy;       // motion over the exposure, px
  float depth = 1;     // m
};

GlTexture upload(const std::vector<float>& texels, int width, int height) {
  GlTexture texture = create_texel_texture(GL_RGBA16F, width, height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, texels.data());
  check_gl("uploading a test texture");
  return texture;
}

// The mid-exposure render and its velocity buffer (later squares drawn over earlier ones).
struct Layer {
  std::vector<float> color, velocity;
  GlTexture color_texture, velocity_texture;
};
Layer make_layer(const std::vector<Square>& squares, int width = kWidth, int height = kHeight) {
  Layer layer;
  layer.color.assign(size_t(width) * height * 4, 0);
  layer.velocity.assign(layer.color.size(), 0);
  for (const Square& s : squares)
    for (int y = s.y0; y <= s.y1; ++y)
      for (int x = s.x0; x <= s.x1; ++x) {
        const size_t i = (size_t(y) * width + x) * 4;
        std::copy(s.color.begin(), s.color.end(), layer.color.begin() + ptrdiff_t(i));
        layer.velocity[i] = float(s.vx), layer.velocity[i + 1] = float(s.vy);
        layer.velocity[i + 2] = s.depth, layer.velocity[i + 3] = 1;
      }
  layer.color_texture = upload(layer.color, width, height);
  layer.velocity_texture = upload(layer.velocity, width, height);
  return layer;
}

// The accumulation buffer's answer for one square: the part of u in [-1/2, 1/2] for which
// (x, y) - v u lies in [x0 - 1/2, x1 + 1/2] x [y0 - 1/2, y1 + 1/2] (slab clipping).
double covered_time(const Square& s, int x, int y) {
  double lo = -0.5, hi = 0.5;
  const double p[2] = {double(x), double(y)}, v[2] = {s.vx, s.vy};
  const double min[2] = {s.x0 - 0.5, s.y0 - 0.5}, max[2] = {s.x1 + 0.5, s.y1 + 0.5};
  for (int a = 0; a < 2; ++a) {
    if (v[a] == 0) {
      if (p[a] < min[a] || p[a] > max[a]) return 0;
      continue;
    }
    // p - v u in [min, max]  <=>  u in [(p - max) / v, (p - min) / v] (ordered)
    double u0 = (p[a] - max[a]) / v[a], u1 = (p[a] - min[a]) / v[a];
    if (u0 > u1) std::swap(u0, u1);
    lo = std::max(lo, u0), hi = std::min(hi, u1);
  }
  return std::max(0.0, hi - lo);
}

// The gather's error bound for one edge crossed along the line of motion (derivation in
// velocity_blur_pass.cpp's model): the taps read the bilinear reconstruction at segment midpoints
// (spacing h = (|v|/2 - 1/2) / (samples/2)); on a solid edge that reconstruction is linear with
// two kinks of slope jump 1, each costing at most h^2/8 of midpoint-rule integral, and it differs
// from the pixel squares' step only within half a pixel of the edge (integral 1/8 where one
// boundary of the integration cuts it). Divided by |v| (weight 1/|v| per unit of path); plus
// GL's 8-bit bilinear weights (1/512 of a step on the few taps near the edge) and the output's
// half floats.
double gather_bound(double motion_length, int samples = kSamples) {
  const double h = (motion_length / 2 - 0.5) / (samples / 2);
  return (h * h / 4 + 1.0 / 8) / motion_length + 1.0 / 512 + kHalfFloat;
}

class VelocityBlurPassTest : public ::testing::Test {
 protected:
  void SetUp() override {
    context().make_current();
    if (!half_float_targets()) GTEST_SKIP() << "no half-float render targets";
  }
};

// Compares every pixel with the sum of the squares' closed forms; returns the largest error.
double max_error(const std::vector<float>& out, const std::vector<Square>& squares, double tolerance) {
  double worst = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 4; ++c) {
        double expected = 0;
        for (const Square& s : squares) expected += covered_time(s, x, y) * s.color[size_t(c)];
        const double error = std::abs(out[(size_t(y) * kWidth + x) * 4 + size_t(c)] - expected);
        worst = std::max(worst, error);
        EXPECT_LT(error, tolerance) << "pixel (" << x << ", " << y << ") channel " << c << ": " << expected;
        if (error >= tolerance) return worst;
      }
  return worst;
}

double alpha_sum(const std::vector<float>& out) {
  double sum = 0;
  for (size_t i = 3; i < out.size(); i += 4) sum += out[i];
  return sum;
}

// |v| = 0 and 0.3: below half a pixel the input is kept exactly (the closed form agrees: below
// one pixel of motion no pixel centre changes side of a pixel-aligned edge); 8 and 20: the ramps.
TEST_F(VelocityBlurPassTest, UniformMotionAlongXGivesTheBoxBlur) {
  VelocityBlurPass pass(GL_RGBA16F);
  for (const double length : {0.0, 0.3, 8.0, 20.0}) {
    const Square square{60, 99, 40, 79, {0.5f, 0.25f, 0.75f, 1.0f}, length, 0};
    Layer layer = make_layer({square});
    pass.run(layer.color_texture.get(), layer.velocity_texture.get(), kWidth, kHeight,
             PixelRect::full(kWidth, kHeight), kSamples);
    const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
    if (length < 0.5) {
      for (size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], layer.color[i]) << "L " << length << " value " << i;
      continue;
    }
    const double bound = gather_bound(length);
    const double worst = max_error(out, {square}, bound);
    // Alpha: the time average conserves the covered area (40 x 40).
    const double mass = alpha_sum(out);
    std::cout << "velocity blur, L " << length << ": max error " << worst << " (bound " << bound
              << "), alpha sum " << mass << " of 1600\n";
    EXPECT_NEAR(mass, 1600, 16);
  }
}

// Diagonal motion (12, 9), |v| = 15: the line crosses two edges near the corners, so twice the
// one-edge bound, with the transition half-pixel stretched along the line by 1/cos(37 deg) = 5/4.
TEST_F(VelocityBlurPassTest, DiagonalMotionGivesTheBoxBlur) {
  VelocityBlurPass pass(GL_RGBA16F);
  const Square square{60, 99, 40, 79, {0.25f, 0.5f, 0.125f, 1.0f}, 12, 9};
  Layer layer = make_layer({square});
  pass.run(layer.color_texture.get(), layer.velocity_texture.get(), kWidth, kHeight,
           PixelRect::full(kWidth, kHeight), kSamples);
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  const double h = (15.0 / 2 - 0.5) / (kSamples / 2);
  const double bound = 2 * (h * h / 4 + 1.25 / 8) / 15 + 1.0 / 512 + kHalfFloat;
  const double worst = max_error(out, {square}, bound);
  const double mass = alpha_sum(out);
  std::cout << "velocity blur, diagonal (12, 9): max error " << worst << " (bound " << bound << "), alpha sum "
            << mass << " of 1600\n";
  EXPECT_NEAR(mass, 1600, 16);
}

// Two squares moving apart, 12 px and 16 px, close enough to share tiles' neighbour maxima (the
// gather of the slower one runs along the faster one's motion, with the wider tap spacing).
TEST_F(VelocityBlurPassTest, OppositeMotionsBlurEachTheirOwnWay) {
  VelocityBlurPass pass(GL_RGBA16F);
  const Square left{30, 59, 40, 79, {0.5f, 0.0f, 0.0f, 1.0f}, -12, 0};
  const Square right{90, 119, 40, 79, {0.0f, 0.25f, 0.5f, 1.0f}, 16, 0};
  Layer layer = make_layer({left, right});
  pass.run(layer.color_texture.get(), layer.velocity_texture.get(), kWidth, kHeight,
           PixelRect::full(kWidth, kHeight), kSamples);
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  // The slower square's taps are spaced for 16 px but weighted by 1/12.
  const double h = (16.0 / 2 - 0.5) / (kSamples / 2);
  const double bound = (h * h / 4 + 1.0 / 8) / 12 + 1.0 / 512 + kHalfFloat;
  const double worst = max_error(out, {left, right}, bound);
  const double mass = alpha_sum(out);
  std::cout << "velocity blur, opposite motions: max error " << worst << " (bound " << bound << "), alpha sum "
            << mass << " of 2400\n";
  EXPECT_NEAR(mass, 2400, 24);
}

// A static square in front (depth 1 m) beside one moving towards it behind (2 m): the moving one's
// trail passes behind the static one, which therefore keeps exactly its own colour.
TEST_F(VelocityBlurPassTest, NearerStaticSurfaceHidesWhatPassesBehind) {
  VelocityBlurPass pass(GL_RGBA16F);
  const Square moving{40, 79, 40, 79, {0.5f, 0.0f, 0.0f, 1.0f}, 20, 0, 2.0f};
  const Square front{80, 119, 40, 79, {0.0f, 0.25f, 0.5f, 1.0f}, 0, 0, 1.0f};
  Layer layer = make_layer({moving, front});
  pass.run(layer.color_texture.get(), layer.velocity_texture.get(), kWidth, kHeight,
           PixelRect::full(kWidth, kHeight), kSamples);
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (int y = front.y0; y <= front.y1; ++y)
    for (int x = front.x0; x <= front.x1; ++x)
      for (int c = 0; c < 4; ++c)
        ASSERT_NEAR(out[(size_t(y) * kWidth + x) * 4 + size_t(c)], front.color[size_t(c)],
                    kHalfFloat * front.color[size_t(c)])
            << "pixel (" << x << ", " << y << ")";
  // The moving square's trailing (left) ramp is the plain box blur.
  for (int x = 20; x < 60; ++x)
    EXPECT_NEAR(out[(size_t(60) * kWidth + x) * 4 + 3], covered_time(moving, x, 60), gather_bound(20)) << x;
}

TEST_F(VelocityBlurPassTest, OnlyRectIsWritten) {
  VelocityBlurPass pass(GL_RGBA16F);
  const Square still{60, 99, 40, 79, {0.5f, 0.25f, 0.75f, 1.0f}, 0, 0};
  Layer first = make_layer({still});
  pass.run(first.color_texture.get(), first.velocity_texture.get(), kWidth, kHeight,
           PixelRect::full(kWidth, kHeight), kSamples);
  const Square moving{60, 99, 40, 79, {0.5f, 0.25f, 0.75f, 1.0f}, 20, 0};
  Layer second = make_layer({moving});
  const PixelRect rect{45, 50, 40, 70};  // over the left ramp, down to the bottom edge
  pass.run(second.color_texture.get(), second.velocity_texture.get(), kWidth, kHeight, rect, kSamples);
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const float alpha = out[(size_t(y) * kWidth + x) * 4 + 3];
      if (rect.contains(x, y))
        ASSERT_NEAR(alpha, covered_time(moving, x, y), gather_bound(20)) << "pixel (" << x << ", " << y << ")";
      else
        ASSERT_EQ(alpha, first.color[(size_t(y) * kWidth + x) * 4 + 3]) << "pixel (" << x << ", " << y << ")";
    }
}

// Cost on a 640x480 image: a 150 x 150 square moving (24, 10) px, rect 200 x 200 around it.
TEST_F(VelocityBlurPassTest, CostAt640x480) {
  constexpr int width = 640, height = 480;
  const Square square{245, 394, 165, 314, {0.5f, 0.25f, 0.75f, 1.0f}, 24, 10};
  Layer layer = make_layer({square}, width, height);
  VelocityBlurPass pass(GL_RGBA16F);
  for (const int samples : {8, 24, 50}) {
    std::vector<double> ms;
    for (int run = 0; run < 25; ++run) {
      const auto start = std::chrono::steady_clock::now();
      pass.run(layer.color_texture.get(), layer.velocity_texture.get(), width, height, PixelRect{220, 140, 200, 200},
               samples);
      glFinish();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    ms.erase(ms.begin(), ms.begin() + 5);  // the first runs compile the shaders (llvmpipe JIT)
    std::sort(ms.begin(), ms.end());
    std::cout << "velocity blur pass, 640x480, rect 200x200, " << samples << " samples, " << context().gl_renderer()
              << ": median " << ms[ms.size() / 2] << " ms, min " << ms.front() << " ms\n";
    RecordProperty("velocity_blur_median_ms_" + std::to_string(samples), std::to_string(ms[ms.size() / 2]));
  }
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

}  // namespace
}  // namespace arpipe
