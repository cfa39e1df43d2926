// Tests of seed 000's composite pass against closed forms: translated copies average to the box
// blur of the bilinearly reconstructed intraframe, a cross-fade to its weighted mix, the identity
// to the input; outside the textures is transparent, outside rect untouched; the sample cap; cost.
#include "render/blur/intraframe_warp_blur_pass.h"

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
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

constexpr int kWidth = 160, kHeight = 120;
// One unit in the last place of the RGBA16F output: at most 2^-10 of the value (2^-11 absolute
// below 1). Not half an ulp: llvmpipe measured one whole ulp off where neighbouring texels
// differ. The cause: the texture coordinate of a texel centre, (p + 0.5) / size in float, comes
// back from the sampler a few float roundings (size * 2^-23 each, < 1e-4 texel here) off the
// centre, so a weight that small lands on the neighbour; kLeak bounds what it adds to a value
// (neighbours differ by at most 1 here), and is what makes a zero texel read a denormal.
constexpr double kHalfFloat = 1.0 / 1024;
constexpr double kLeak = 1e-4;

EglContext& context() {
  static EglContext instance(EglPlatformRequest::Auto);
  return instance;
}

bool half_float_targets() {
  return context().has_gl_extension("GL_EXT_color_buffer_half_float") ||
         context().has_gl_extension("GL_EXT_color_buffer_float");
}

using Rgba = std::array<float, 4>;

// An RGBA16F texture from float texels (row v = GL row v); the values used are exact in half floats.
GlTexture upload(const std::vector<float>& texels, int width, int height) {
  GlTexture texture = create_texel_texture(GL_RGBA16F, width, height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, texels.data());
  check_gl("uploading a test texture");
  return texture;
}

std::vector<float> image_of(int width, int height, Rgba (*texel)(int x, int y)) {
  std::vector<float> texels(size_t(width) * height * 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Rgba t = texel(x, y);
      std::copy(t.begin(), t.end(), texels.begin() + (ptrdiff_t(y) * width + x) * 4);
    }
  return texels;
}

const float* at(const std::vector<float>& pixels, int x, int y, int width = kWidth) {
  return pixels.data() + (size_t(y) * width + x) * 4;
}

IntraframeWarpSample sample(double weight_first, double weight_second, const Affine2& first_from_output,
                      const Affine2& second_from_output) {
  IntraframeWarpSample s;
  s.weight_first = weight_first, s.weight_second = weight_second;
  s.first_from_output = first_from_output, s.second_from_output = second_from_output;
  return s;
}

// The square of texels [kX0, kX1] x [kY0, kY1], opaque, its red varying by row (k/64, exact).
constexpr int kX0 = 50, kX1 = 99, kY0 = 40, kY1 = 79;
Rgba square_texel(int x, int y) {
  if (x < kX0 || x > kX1 || y < kY0 || y > kY1) return {0, 0, 0, 0};
  return {float(y - kY0) / 64.0f, 0.5f, 0.125f, 1.0f};
}
Rgba square_texel_second(int x, int y) {  // the same square, another colour: both textures are read
  const Rgba t = square_texel(x, y);
  return {t[0], t[1] * 0.5f, t[2] * 4.0f, t[3]};
}

// Integral of the unit tent (bilinear reconstruction of one texel) from -infinity to u.
double tent_cdf(double u) {
  if (u <= -1) return 0;
  if (u <= 0) return 0.5 * (u + 1) * (u + 1);
  if (u <= 1) return 1 - 0.5 * (1 - u) * (1 - u);
  return 1;
}

// Integral over [from, to] along a row of the bilinear reconstruction of texels 1 on [kX0, kX1].
double square_row_integral(double from, double to) {
  double sum = 0;
  for (int k = kX0; k <= kX1; ++k) sum += tent_cdf(to - k) - tent_cdf(from - k);
  return sum;
}

class SeedBlurPassTest : public ::testing::Test {
 protected:
  void SetUp() override {
    context().make_current();
    if (!half_float_targets()) GTEST_SKIP() << "no half-float render targets";
  }
};

// n = L samples shifting the square by d_i = (i + 1/2) - L/2 (half-integers), the first half from
// the first intraframe, the rest from the second. Bilinear reads at half-integers are the
// midpoints of the reconstruction's linear pieces, so the mean equals exactly (1/L) times its
// integral over the window (square_row_integral): the box blur of length L, which away from the
// ramps' ends (1 px) is the linear ramp of length L.
// Tolerance: one half-float ulp (the 1/2 bilinear weight is exact in GL's 8-bit weights).
TEST_F(SeedBlurPassTest, TranslatedSamplesAverageToTheBoxBlur) {
  GlTexture first = upload(image_of(kWidth, kHeight, square_texel), kWidth, kHeight);
  GlTexture second = upload(image_of(kWidth, kHeight, square_texel_second), kWidth, kHeight);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  for (const int length : {8, 24, 50}) {
    IntraframeWarpPlan plan;
    for (int i = 0; i < length; ++i) {
      const Affine2 back = Affine2::translation({-(i + 0.5 - length / 2.0), 0});
      plan.samples.push_back(i < length / 2 ? sample(1, 0, back, Affine2::identity())
                                            : sample(0, 1, Affine2::identity(), back));
    }
    pass.run(first.get(), second.get(), kWidth, kHeight, plan, PixelRect::full(kWidth, kHeight));
    const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
    double worst = 0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        // Shifts d < 0 (first texture) read [x, x + L/2], d > 0 (second) read [x - L/2, x].
        const Rgba a = square_texel(kX0, y), b = square_texel_second(kX0, y);
        const double from_first = square_row_integral(x, x + length / 2.0) / length;
        const double from_second = square_row_integral(x - length / 2.0, x) / length;
        for (int c = 0; c < 4; ++c) {
          const double expected = from_first * a[size_t(c)] + from_second * b[size_t(c)];
          const double error = std::abs(at(out, x, y)[c] - expected);
          worst = std::max(worst, error);
          ASSERT_LT(error, kHalfFloat) << "L " << length << " pixel (" << x << ", " << y << ") channel " << c;
        }
      }
    std::cout << "seed blur, " << length << " translated samples: max error " << worst << "\n";
  }
}

TEST_F(SeedBlurPassTest, CrossFadeGivesTheWeightedMix) {
  const Rgba a{0.25f, 0.5f, 0.75f, 1.0f}, b{1.0f, 0.125f, 0.5f, 0.75f};
  std::vector<float> texels_a(size_t(kWidth) * kHeight * 4), texels_b(texels_a.size());
  for (size_t i = 0; i < texels_a.size(); ++i) texels_a[i] = a[i % 4], texels_b[i] = b[i % 4];
  GlTexture first = upload(texels_a, kWidth, kHeight);
  GlTexture second = upload(texels_b, kWidth, kHeight);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  IntraframeWarpPlan plan;
  plan.samples.push_back(sample(0.3, 0.7, Affine2::identity(), Affine2::identity()));
  pass.run(first.get(), second.get(), kWidth, kHeight, plan, PixelRect::full(kWidth, kHeight));
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 4; ++c)
        ASSERT_NEAR(at(out, x, y)[c], 0.3 * a[size_t(c)] + 0.7 * b[size_t(c)], kHalfFloat)
            << "pixel (" << x << ", " << y << ") channel " << c;
}

Rgba textured(int x, int y) {  // every texel different, k/1024: exact in half floats
  return {float((x * 7 + y * 3) % 1024) / 1024.0f, float((x * 13 + y * 29) % 512) / 1024.0f,
          float((x + y) % 64) / 64.0f, float(1 + (x * y) % 255) / 256.0f};
}

// The identity reads every texel at its centre: the input, up to half-float rounding.
TEST_F(SeedBlurPassTest, IdentityReproducesTheInput) {
  const std::vector<float> texels = image_of(kWidth, kHeight, textured);
  GlTexture first = upload(texels, kWidth, kHeight);
  GlTexture second = upload(std::vector<float>(texels.size(), 0), kWidth, kHeight);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  IntraframeWarpPlan plan;
  plan.samples.push_back(sample(1, 0, Affine2::identity(), Affine2::translation({3, 1})));
  pass.run(first.get(), second.get(), kWidth, kHeight, plan, PixelRect::full(kWidth, kHeight));
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  double worst = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    worst = std::max(worst, double(std::abs(out[i] - texels[i])));
    ASSERT_NEAR(out[i], texels[i], kHalfFloat * texels[i] + kLeak) << "value " << i;
  }
  std::cout << "seed blur identity: max error " << worst << "\n";
}

// Reads beyond the textures' edges (pixel coordinates past -0.5 or size - 0.5) are transparent.
TEST_F(SeedBlurPassTest, OutsideTheTexturesIsTransparent) {
  const Rgba solid{0.5f, 0.25f, 0.125f, 1.0f};
  std::vector<float> texels(size_t(kWidth) * kHeight * 4);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = solid[i % 4];
  GlTexture first = upload(texels, kWidth, kHeight);
  GlTexture second = upload(texels, kWidth, kHeight);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  IntraframeWarpPlan plan;
  plan.samples.push_back(sample(1, 0, Affine2::translation({30, 0}), Affine2::identity()));   // p reads p + 30
  plan.samples.push_back(sample(0, 1, Affine2::identity(), Affine2::translation({0, -1000})));  // all outside
  pass.run(first.get(), second.get(), kWidth, kHeight, plan, PixelRect::full(kWidth, kHeight));
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double inside = x + 30 <= kWidth - 1 ? 0.5 : 0.0;  // of the two samples, one at most
      for (int c = 0; c < 4; ++c)
        ASSERT_NEAR(at(out, x, y)[c], inside * solid[size_t(c)], kHalfFloat) << "pixel (" << x << ", " << y << ")";
    }
}

TEST_F(SeedBlurPassTest, OnlyRectIsWrittenAndAnEmptyPlanClearsIt) {
  const std::vector<float> texels = image_of(kWidth, kHeight, textured);
  GlTexture first = upload(texels, kWidth, kHeight);
  GlTexture second = upload(std::vector<float>(texels.size(), 0), kWidth, kHeight);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  IntraframeWarpPlan identity;
  identity.samples.push_back(sample(1, 0, Affine2::identity(), Affine2::identity()));
  IntraframeWarpPlan from_second;  // all zero
  from_second.samples.push_back(sample(0, 1, Affine2::identity(), Affine2::identity()));
  pass.run(first.get(), second.get(), kWidth, kHeight, identity, PixelRect::full(kWidth, kHeight));
  const PixelRect rect{20, 85, 50, 35}, cleared{100, 0, 60, 10};  // reaching the bottom and right edges
  pass.run(first.get(), second.get(), kWidth, kHeight, from_second, rect);
  pass.run(first.get(), second.get(), kWidth, kHeight, IntraframeWarpPlan{}, cleared);
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 4; ++c) {
        const float expected = rect.contains(x, y) || cleared.contains(x, y) ? 0.0f : at(texels, x, y)[c];
        ASSERT_NEAR(at(out, x, y)[c], expected, kHalfFloat * expected + kLeak) << "pixel (" << x << ", " << y << ")";
      }
}

TEST_F(SeedBlurPassTest, FiftySamplesRunFiftyOneThrow) {
  const std::vector<float> texels = image_of(kWidth, kHeight, textured);
  GlTexture first = upload(texels, kWidth, kHeight);
  GlTexture second = upload(texels, kWidth, kHeight);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  IntraframeWarpPlan plan;
  for (int i = 0; i < IntraframeWarpBlurPass::kMaxSamples; ++i)  // alternating textures: all 50 slots are read
    plan.samples.push_back(sample(i % 2, 1 - i % 2, Affine2::identity(), Affine2::identity()));
  pass.run(first.get(), second.get(), kWidth, kHeight, plan, PixelRect::full(kWidth, kHeight));
  const std::vector<float> out = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (size_t i = 0; i < out.size(); ++i)
    ASSERT_NEAR(out[i], texels[i], kHalfFloat * texels[i] + kLeak) << "value " << i;
  // 50 cross-fades, each weighted (1 - t, t) at t = (i + 0.5) / 50, read both textures: 100
  // lookups, the most a plan can hold. The first is read one pixel to the right and the second
  // holds the same texels one pixel to the left, so every lookup reads texel x + 1: a lookup that
  // took the other texture's warp, or a weight left out, shows.
  const std::vector<float> shifted = image_of(kWidth, kHeight, [](int x, int y) { return textured(x + 1, y); });
  GlTexture second_shifted = upload(shifted, kWidth, kHeight);
  IntraframeWarpPlan fades;
  for (int i = 0; i < IntraframeWarpBlurPass::kMaxSamples; ++i) {
    const double t = (i + 0.5) / IntraframeWarpBlurPass::kMaxSamples;
    fades.samples.push_back(sample(1 - t, t, Affine2::translation({1, 0}), Affine2::identity()));
  }
  pass.run(first.get(), second_shifted.get(), kWidth, kHeight, fades, PixelRect::full(kWidth, kHeight));
  const std::vector<float> faded = render_test::read_rgba_float(pass.texture(), kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x + 1 < kWidth; ++x)
      for (int c = 0; c < 4; ++c) {
        const double expected = at(texels, x + 1, y)[c];  // first at x + 1, second shifted by one: the same texel
        ASSERT_NEAR(at(faded, x, y)[c], expected, kHalfFloat * expected + kLeak) << x << "," << y << " channel " << c;
      }
  plan.samples.push_back(plan.samples.back());
  EXPECT_EQ(IntraframeWarpBlurPass::kMaxSamples, 50);
  EXPECT_THROW(pass.run(first.get(), second.get(), kWidth, kHeight, plan, PixelRect::full(kWidth, kHeight)),
               RenderError);
}

// Cost on a 640x480 image, 200 x 200 rect, samples cross-fading both intraframes (the most reads).
TEST_F(SeedBlurPassTest, CostAt640x480) {
  constexpr int width = 640, height = 480;
  GlTexture first = upload(std::vector<float>(size_t(width) * height * 4, 0.5f), width, height);
  GlTexture second = upload(std::vector<float>(size_t(width) * height * 4, 0.25f), width, height);
  IntraframeWarpBlurPass pass(GL_RGBA16F);
  for (const int count : {8, 24, 50}) {
    IntraframeWarpPlan plan;
    for (int i = 0; i < count; ++i) {
      const double t = (i + 0.5) / count;
      plan.samples.push_back(sample(1 - t, t, Affine2::translation({-20 * t, 3 * t}),
                                    Affine2::translation({20 * (1 - t), -3 * (1 - t)})));
    }
    std::vector<double> ms;
    for (int run = 0; run < 25; ++run) {
      const auto start = std::chrono::steady_clock::now();
      pass.run(first.get(), second.get(), width, height, plan, PixelRect{220, 140, 200, 200});
      glFinish();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    ms.erase(ms.begin(), ms.begin() + 5);  // the first runs compile the shader (llvmpipe JIT)
    std::sort(ms.begin(), ms.end());
    std::cout << "seed blur pass, 640x480, rect 200x200, " << count << " samples, " << context().gl_renderer()
              << ": median " << ms[ms.size() / 2] << " ms, min " << ms.front() << " ms\n";
    RecordProperty("intraframe_warp_blur_median_ms_" + std::to_string(count), std::to_string(ms[ms.size() / 2]));
  }
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

}  // namespace
}  // namespace arpipe
